#include "bench/core/bench_flags.hpp"

#include <benchmark/benchmark.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <string_view>

namespace bvhlab {

namespace {

void add_flag(CLI::App& app, const BenchFlag& flag) {
  const std::string name = std::string("--") + flag.name;
  std::visit(
      [&](auto* target) {
        using T = std::remove_pointer_t<decltype(target)>;
        if constexpr (std::is_same_v<T, bool>) {
          app.add_flag(name, *target, flag.help);
        } else {
          CLI::Option* option = app.add_option(name, *target, flag.help)->capture_default_str();
          if constexpr (std::is_same_v<T, std::vector<std::string>> || std::is_same_v<T, std::vector<double>>)
            option->delimiter(',');
        }
      },
      flag.target);
}

/// Robust timing unless the caller chose otherwise: kBenchRepetitions repetitions of each benchmark, run in a
/// random order across benchmarks (so a slow spell of the machine lands on different benchmarks), reported as
/// their mean, median, standard deviation and coefficient of variation. Read the median.
void add_robust_timing_defaults(std::vector<std::string>& args) {
  auto given = [&](std::string_view flag) {
    return std::any_of(args.begin(), args.end(), [&](const std::string& a) { return a.rfind(flag, 0) == 0; });
  };
  if (!given("--benchmark_repetitions"))
    args.push_back("--benchmark_repetitions=" + std::to_string(kBenchRepetitions));
  if (!given("--benchmark_enable_random_interleaving"))
    args.emplace_back("--benchmark_enable_random_interleaving=true");
  if (!given("--benchmark_report_aggregates_only") && !given("--benchmark_display_aggregates_only"))
    args.emplace_back("--benchmark_display_aggregates_only=true");
}

}  // namespace

std::optional<int> initialize_benchmark(const char* program, std::initializer_list<BenchFlag> flags, int argc,
                                        char** argv) {
  CLI::App app{std::string(program) + ": its own flags, then Google Benchmark's", program};
  app.allow_extras();
  for (const BenchFlag& flag : flags) add_flag(app, flag);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    app.exit(e);
    benchmark::PrintDefaultHelp();
    return 0;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s\n", program, e.what());
    return 2;
  }
  std::vector<std::string> rest = app.remaining();
  add_robust_timing_defaults(rest);
  // argv[0] itself, not a copy: Google Benchmark keeps the pointer as the executable's name for its JSON
  // context, which a local copy would leave dangling.
  std::vector<char*> rest_argv{argv[0]};
  for (std::string& arg : rest) rest_argv.push_back(arg.data());
  int rest_argc = static_cast<int>(rest_argv.size());
  benchmark::Initialize(&rest_argc, rest_argv.data());
  if (benchmark::ReportUnrecognizedArguments(rest_argc, rest_argv.data())) return 2;
  return std::nullopt;
}

}  // namespace bvhlab

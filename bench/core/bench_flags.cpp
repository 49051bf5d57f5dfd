#include "bench/core/bench_flags.hpp"

#include <benchmark/benchmark.h>
#include <CLI/CLI.hpp>

#include <cstdio>

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
  rest.insert(rest.begin(), argv[0]);
  std::vector<char*> rest_argv;
  for (std::string& arg : rest) rest_argv.push_back(arg.data());
  int rest_argc = static_cast<int>(rest_argv.size());
  benchmark::Initialize(&rest_argc, rest_argv.data());
  if (benchmark::ReportUnrecognizedArguments(rest_argc, rest_argv.data())) return 2;
  return std::nullopt;
}

}  // namespace bvhlab

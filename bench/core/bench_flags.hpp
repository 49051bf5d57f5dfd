// The benchmark programs' own flags (--meshes=a,b --steps=200), parsed by CLI11 in one compiled file, so the
// benchmarks do not each compile CLI11; the flags it does not know go on to Google Benchmark.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace bvhlab {

/// Where a flag's value goes; lists are comma-separated, a bool is a switch (`--crossover`).
using BenchFlagTarget = std::variant<bool*, int*, unsigned*, std::uint64_t*, double*, std::string*,
                                     std::vector<std::string>*, std::vector<double>*>;

struct BenchFlag {
  const char* name;  ///< without dashes: "meshes" is `--meshes=...`
  BenchFlagTarget target;
  const char* help;
};

/// Repetitions of each benchmark unless --benchmark_repetitions says otherwise (with random interleaving and
/// the aggregates displayed: the median is the figure to read).
inline constexpr int kBenchRepetitions = 5;

/// Parses the program's flags, then hands the rest to benchmark::Initialize. Returns std::nullopt to go on,
/// or the exit code: 0 after --help (these flags, then Google Benchmark's), 2 after a bad value or a flag
/// neither knows (named on stderr). A flag not given keeps its target's value: the default.
std::optional<int> initialize_benchmark(const char* program, std::initializer_list<BenchFlag> flags, int argc,
                                        char** argv);

}  // namespace bvhlab

// A density that exists only under tests/, to prove that the density axis takes a new policy through its
// header and one registry line (engine/registry.hpp, under BVHLAB_TEST_POLICIES): nothing else in adb/,
// traversal/ or bench/ names it, yet scenes, the CLI, saved trees, the runner, the report and the plot script
// run it (tests/bench/test_policies.cpp; the test CLI `bvhlab_test_policies`, tests/bench/CMakeLists.txt).
#pragma once

#include "adb/concept.hpp"
#include "adb/tree.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace bvhlab::testing {

/// Per node, the number of triangles below it, capped at `cap`; its estimate for a pair grows with the
/// overlap fraction and the smaller count. A ProbabilityDensity, so the ADB strategies run on it unchanged.
struct TriangleCountDensity {
  struct Params {
    int cap = 8;
    friend bool operator==(const Params&, const Params&) = default;
  };
  struct Storage {
    Params params;
    std::vector<std::uint8_t> counts;
  };

  static constexpr std::string_view name() { return "tricount"; }
  static constexpr std::uint32_t version() { return 1; }
  static std::span<const ParamSpec> parameters() {
    static constexpr ParamSpec specs[] = {{.name = "cap",
                                           .description = "largest count stored per node",
                                           .min = 1,
                                           .max = 255,
                                           .default_value = 8,
                                           .integer = true}};
    return specs;
  }
  static Params make_params(const ParamValues& values) {
    return {static_cast<int>(parameter(values, "cap"))};
  }

  template <TreeVolume BV>
  static Storage annotate(const Bvh<BV>& bvh, const Params& params, const AnnotationContext&,
                          AnnotateStats* stats) {
    Storage storage{params, {}};
    for (const auto& [begin, end] : node_triangle_ranges(bvh.nodes()))
      storage.counts.push_back(static_cast<std::uint8_t>(std::min<std::uint32_t>(params.cap, end - begin)));
    if (stats) *stats = AnnotateStats{.nodes = storage.counts.size()};
    return storage;
  }
  static std::string describe(const Storage& s) { return "tricount cap=" + std::to_string(s.params.cap); }
  static std::vector<std::byte> encode(const Storage& s) {
    std::vector<std::byte> out(1 + s.counts.size());
    out[0] = static_cast<std::byte>(s.params.cap);
    if (!s.counts.empty()) std::memcpy(out.data() + 1, s.counts.data(), s.counts.size());
    return out;
  }
  static Storage decode(std::span<const std::byte> bytes, std::size_t nodes) {
    if (bytes.size() != 1 + nodes) throw std::invalid_argument("tricount: one byte per node expected");
    Storage s{make_params({{"cap", std::to_integer<int>(bytes[0])}}), std::vector<std::uint8_t>(nodes)};
    if (s.params.cap < 1) throw std::invalid_argument("tricount: cap must be at least 1");
    if (nodes) std::memcpy(s.counts.data(), bytes.data() + 1, nodes);
    for (const std::uint8_t c : s.counts)
      if (c > s.params.cap) throw std::invalid_argument("tricount: a count exceeds the cap");
    return s;
  }
  static std::size_t memory_bytes(const Storage& s) { return s.counts.size(); }

  struct Estimator {
    const std::uint8_t *a, *b;
    double cap;
    double operator()(std::uint32_t i, const Box& box_a, std::uint32_t j, const Box& box_b,
                      double overlap) const {
      const double smaller = std::min(box_a.extent().prod(), box_b.extent().prod());
      const double fraction = smaller > 0 ? std::min(1.0, overlap / smaller) : (overlap > 0 ? 1.0 : 0.0);
      return fraction * std::min(a[i], b[j]) / cap;
    }
  };
  static Estimator estimator(const Storage& a, const Storage& b) {
    if (!(a.params == b.params))
      throw std::invalid_argument("tricount: the trees were annotated with other caps");
    return {a.counts.data(), b.counts.data(), double(a.params.cap)};
  }
};
static_assert(ProbabilityDensity<TriangleCountDensity>);

}  // namespace bvhlab::testing

// The BroadPhase concept: what finds the pairs of objects, among many, whose world boxes overlap, so the
// narrow phase (a strategy on the two objects' trees) runs on those pairs only.
//
// Concept `BroadPhase<B>` (in the manner of a CGAL concept page)
// ----------------------------------------------------------------
// A model tracks a fixed set of objects 0 .. n-1 across frames. Each frame the caller hands it every
// object's world axis-aligned box (traversal/broad_phase/world_box.hpp derives it from a tree and a pose);
// the model answers with the pairs whose boxes overlap. Models may keep any state between frames (sorted
// orders, trees, fattened boxes) to make coherent motion cheap, but the answer depends on the boxes of the
// current frame only.
//
// Types
//   ObjectPair                 Two object indices, a < b; ordered lexicographically.
//
// Operations (b: B; boxes: std::span<const Box>)
//   B::name()                  Short stable identifier ("sweep_and_prune", ...), used by the registry.
//   b.update(boxes)            boxes[i] is object i's world box this frame. The first call registers
//                              the objects (n = boxes.size(), possibly 0); every later call must pass
//                              the same count, else std::invalid_argument naming both counts. A box with
//                              a NaN or infinite coordinate, or an empty one (min > max on some axis), is
//                              refused with std::invalid_argument naming the object's index; a refused
//                              update leaves the previous frame's state and answer untouched.
//   b.pairs()                  const std::vector<ObjectPair>&: every pair whose *closed* boxes overlap
//                              (touching faces count), each once with a < b, sorted ascending. Exactly
//                              the pairs of the last accepted update, whatever the model's internal
//                              order, so all models give identical vectors for identical input.
//
// Models: BruteForce (brute_force.hpp, the reference), SweepAndPrune (sweep_and_prune.hpp),
// DynamicAabbTree (dynamic_aabb_tree.hpp). traversal/broad_phase/registry.hpp lists them by name.
#pragma once

#include "../../volumes/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <compare>
#include <concepts>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace bvhlab {

/// Two objects whose world boxes overlap: a < b.
struct ObjectPair {
  std::uint32_t a = 0;
  std::uint32_t b = 0;
  friend bool operator==(const ObjectPair&, const ObjectPair&) = default;
  friend auto operator<=>(const ObjectPair&, const ObjectPair&) = default;
};

template <class B>
concept BroadPhase = requires(B& b, const B& cb, std::span<const Box> boxes) {
  { B::name() } -> std::convertible_to<std::string_view>;
  b.update(boxes);
  { cb.pairs() } -> std::same_as<const std::vector<ObjectPair>&>;
};

namespace broad_phase_detail {

/// The input rules every model shares (see the concept). `registered` is the object count of the first
/// update, or -1 before it.
inline void check_update(std::string_view who, std::span<const Box> boxes, std::int64_t registered) {
  if (registered >= 0 && boxes.size() != static_cast<std::size_t>(registered))
    throw std::invalid_argument(std::string(who) + ": update got " + std::to_string(boxes.size()) +
                                " boxes, but " + std::to_string(registered) +
                                " objects are registered (the count is fixed by the first update)");
  if (boxes.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(boxes.size()) +
                                " objects do not fit 32-bit object indices");
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    const Box& box = boxes[i];
    // Empty first: the default Box (min = +inf, max = -inf) is an empty box, not an infinite one.
    bool empty = false, finite = true;
    for (int k = 0; k < 3; ++k) {
      empty = empty || box.min[k] > box.max[k];
      finite = finite && std::isfinite(box.min[k]) && std::isfinite(box.max[k]);
    }
    if (empty)
      throw std::invalid_argument(std::string(who) + ": object " + std::to_string(i) +
                                  "'s box is empty (min > max on some axis)");
    if (!finite)
      throw std::invalid_argument(std::string(who) + ": object " + std::to_string(i) +
                                  "'s box has a NaN or infinite coordinate");
  }
}

/// Whether every comparison holds, all of them evaluated and combined without branches: in a tree traversal
/// their outcomes are mixed, and the branches of `&&` mispredict at a cost above the comparisons' (a sixth
/// of the dynamic tree's pair search on 1,000 moving objects). Combined as integers: `&` of bools is what
/// clang warns about.
template <class... Holds>
inline bool all_hold(Holds... holds) {
  return (static_cast<unsigned>(holds) & ...) != 0;
}

/// Closed-box overlap on the three axes: six comparisons.
inline bool boxes_touch(const Box& a, const Box& b) {
  return all_hold(a.min.x() <= b.max.x(), b.min.x() <= a.max.x(), a.min.y() <= b.max.y(),
                  b.min.y() <= a.max.y(), a.min.z() <= b.max.z(), b.min.z() <= a.max.z());
}

inline ObjectPair ordered_pair(std::uint32_t i, std::uint32_t j) {
  return i < j ? ObjectPair{i, j} : ObjectPair{j, i};
}

/// Puts a frame's pairs in ascending order: bucketed by their first object (a counting sort, O(n + pairs)),
/// then each bucket, a handful of pairs, by the second. A comparison sort of the pairs took about a sixth of
/// the dynamic tree's frame in a dense world. Keeps its buffers between frames.
class PairSorter {
 public:
  void sort(std::vector<ObjectPair>& pairs, std::size_t objects) {
    bucket_end_.assign(objects + 1, 0);
    for (const ObjectPair& p : pairs) ++bucket_end_[p.a + 1];
    for (std::size_t i = 1; i <= objects; ++i) bucket_end_[i] += bucket_end_[i - 1];
    sorted_.resize(pairs.size());
    for (const ObjectPair& p : pairs) sorted_[bucket_end_[p.a]++] = p;
    // bucket_end_[a] is now where bucket a ends; it starts where bucket a - 1 ends.
    std::uint32_t begin = 0;
    for (std::size_t a = 0; a < objects; ++a) {
      const std::uint32_t end = bucket_end_[a];
      if (end - begin > 1)
        std::sort(sorted_.begin() + begin, sorted_.begin() + end,
                  [](const ObjectPair& x, const ObjectPair& y) { return x.b < y.b; });
      begin = end;
    }
    pairs.swap(sorted_);
  }

 private:
  std::vector<std::uint32_t> bucket_end_;
  std::vector<ObjectPair> sorted_;
};

}  // namespace broad_phase_detail

}  // namespace bvhlab

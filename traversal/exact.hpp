// Exact traversal: depth-first simultaneous descent (traversal/driver.hpp), generic over the bounding volume.
// Stops at the first intersecting triangle pair, or lists all of them.
#pragma once

#include "driver.hpp"

#include <stdexcept>

namespace bvhlab {

enum class ContactMode { First, All };

/// The exact strategy's hooks: a pair is queued iff its volumes overlap; leaf pairs run the triangle tests.
/// `Pair` may carry a key for other queue policies (set by a derived admit); exact depth-first needs none.
template <TreeVolume BV, class Pair_ = QueuedPair<BV>>
class ExactHooks {
 public:
  using Pair = Pair_;

  ExactHooks(const TreePair<BV>& trees, Result& result, ContactMode mode)
      : trees_(trees), result_(result), mode_(mode) {}

  [[gnu::always_inline]] bool evaluate(const Pair& p) { return trees_.overlap(p); }
  static Admission admit(Pair&, bool overlap) { return overlap ? Admission::Queue : Admission::Drop; }
  [[gnu::always_inline]] Step leaf_pair(const Pair& p) {
    const bool first_found = trees_.intersecting_triangles(p.a, p.b, [&](const TrianglePair& hit) {
      result_.collides = true;
      result_.probability = 1;
      if (!result_.witness) result_.witness = hit;
      if (mode_ == ContactMode::First) return true;
      result_.contacts.push_back(hit);
      return false;
    });
    return first_found ? Step::Decided : Step::Continue;
  }
  template <class Queue>
  static void finish(const Queue&, Ended) {}  // nothing left to shape: no contact, or all of them listed

 private:
  const TreePair<BV>& trees_;
  Result& result_;
  ContactMode mode_;
};

/// Exact first-contact (or all-contacts) query. `b_to_a` maps B's local frame into A's.
/// Const and thread-safe on shared trees: all traversal state lives on this call's stack.
template <TreeVolume BV>
Result query_exact(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                   ContactMode mode = ContactMode::First) {
  b_to_a.validate();
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  if (!a.has_polygons() || !b.has_polygons())
    throw std::invalid_argument("exact query: a tree was loaded without polygons; exact mode needs them");
  const auto context = VolumeWalker<BV>::make_context(b_to_a);
  const TreePair<BV> trees(a, b, b_to_a, context, result.counters);
  ExactHooks<BV> hooks(trees, result, mode);
  Unlimited limit;
  traverse<DepthFirst, SplitLarger>(trees, hooks, limit);
  return result;
}

}  // namespace bvhlab

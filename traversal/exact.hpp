// Exact traversal: depth-first simultaneous descent (traversal/driver.hpp), generic over the bounding volume.
// Stops at the first intersecting triangle pair, or lists all of them.
#pragma once

#include "driver.hpp"
#include "exact_options.hpp"

#include <optional>
#include <stdexcept>
#include <utility>

namespace bvhlab {

/// The exact strategy's hooks: a pair is queued iff its volumes overlap; leaf pairs run the leaf test (the
/// triangle tests, or Leaves' own). `Pair` may carry a key for other queue policies (set by a derived
/// admit); exact depth-first needs none.
template <TreeVolume BV, class Pair_ = QueuedPair<BV>, class Leaves = TriangleLeaves>
class ExactHooks {
 public:
  using Pair = Pair_;

  ExactHooks(const TreePair<BV, Leaves>& trees, Result& result, ContactMode mode)
      : trees_(trees), result_(result), mode_(mode) {}

  [[gnu::always_inline]] bool evaluate(const Pair& p) { return trees_.overlap(p); }
  static Admission admit(Pair&, bool overlap) { return overlap ? Admission::Queue : Admission::Drop; }
  [[gnu::always_inline]] Step leaf_pair(const Pair& p) {
    const bool first_found = trees_.leaf_contact(p.a, p.b, [&](const std::optional<TrianglePair>& hit) {
      result_.collides = true;
      result_.probability = 1;
      if (!result_.witness) result_.witness = hit;
      if (mode_ == ContactMode::First) return true;
      if (hit) result_.contacts.push_back(*hit);  // a leaf test without triangles is refused in All mode
      return false;
    });
    return first_found ? Step::Decided : Step::Continue;
  }
  template <class Queue>
  static void finish(const Queue&, Ended) {}  // nothing left to shape: no contact, or all of them listed

 private:
  const TreePair<BV, Leaves>& trees_;
  Result& result_;
  ContactMode mode_;
};

/// What every exact query checks first: a rigid pose (RigidTransform::validate), and a contact mode its
/// leaf test can serve. Throws std::invalid_argument.
template <class Leaves>
void check_exact_query(const RigidTransform& b_to_a, ContactMode mode) {
  b_to_a.validate();
  if constexpr (!Leaves::kTriangles)
    if (mode == ContactMode::All)
      throw std::invalid_argument("all contacts: point surfaces have no triangle pairs to list");
}

/// The exact strategy's traversal of `trees` (made for this query, counting into `result`) with hooks of
/// the caller's type (ExactHooks or one built on it); `done` is called with them when it ends.
template <class Hooks, TreeVolume BV, class Leaves, class Done>
void traverse_exact(const TreePair<BV, Leaves>& trees, Result& result, ContactMode mode, Done&& done) {
  Hooks hooks(trees, result, mode);
  Unlimited limit;
  traverse<DepthFirst, SplitLarger>(trees, hooks, limit);
  done(std::as_const(hooks));
}

/// query_exact after check_exact_query (for callers that made the checks already), with hooks of the
/// caller's type, as traverse_exact.
template <class Hooks, TreeVolume BV, class Leaves, class Done>
Result exact_traversal_with(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                            ContactMode mode, const Leaves& leaves, Done&& done) {
  Result result;
  result.exact = true;
  if (a.empty() || b.empty()) return result;
  if constexpr (Leaves::kTriangles) TriangleLeaves::require(a, b, "exact query");
  const auto context = VolumeWalker<BV>::make_context(b_to_a);
  const TreePair<BV, Leaves> trees(a, b, b_to_a, context, result.counters, leaves);
  traverse_exact<Hooks>(trees, result, mode, std::forward<Done>(done));
  return result;
}

/// The `done` of a traversal whose hooks have nothing more to say: a named type, so that query_exact and a
/// coherent query answering as the cold one (traversal/coherent.hpp) share one compiled traversal.
struct NothingToNote {
  template <class Hooks>
  void operator()(const Hooks&) const {}
};

/// Exact first-contact (or all-contacts) query. `b_to_a` maps B's local frame into A's. `leaves` is the
/// leaf test (TreePair's Leaves); the default tests triangles, and traversal/point_leaves.hpp passes the
/// surfaces of point clouds (query_exact_points). Const and thread-safe on shared trees: all traversal
/// state lives on this call's stack.
template <TreeVolume BV, class Leaves = TriangleLeaves>
Result query_exact(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                   ContactMode mode = ContactMode::First, const Leaves& leaves = kTriangleLeaves) {
  check_exact_query<Leaves>(b_to_a, mode);
  return exact_traversal_with<ExactHooks<BV, QueuedPair<BV>, Leaves>>(a, b, b_to_a, mode, leaves,
                                                                      NothingToNote{});
}

}  // namespace bvhlab

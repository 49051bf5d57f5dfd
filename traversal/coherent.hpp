// Coherent exact queries: one pair of trees asked again and again while B moves a little (a simulation step,
// a haptic loop, the protocol's turn) starts each query where the last one ended, in the manner of Ehmann and
// Lin's front tracking.
//
// The state (traversal/coherent_state.hpp) stores the traversal tree of the last query: every node pair it
// reached, in the exact strategy's order (depth first, the larger node split). Its front pairs (those not
// split: volumes disjoint, or a leaf pair without contact) are a cut: every triangle pair lies below exactly
// one of them. The next query
//   1. tests the remembered contact's leaf pair first (first contact only): if its triangles still intersect,
//      that is the answer;
//   2. otherwise walks the stored tree from its root without testing its inner pairs, and tests each front
//      pair again at the new pose: a pair still disjoint stays; one that overlaps now is descended as the
//      exact strategy would (it may find a contact); a leaf pair is tested by its triangles. The walk goes
//      first the way that led to the remembered contact, where a contact that moved is most likely found;
//   3. raises: an inner pair whose children are all disjoint again is tested itself, and if disjoint becomes
//      one front pair (so objects moving apart end up with their root pair alone). A parent that still
//      overlaps is not tested again for CoherenceOptions::raise_hold queries.
// While the stored tree is the root pair alone, step 2 is the root pair's test, made without the walk; a
// deeper stored tree without a contact is tested at its root pair first too, while that pays.
// The answer is exact whatever the state holds: "no contact" only when every front pair was found disjoint
// or without contact at the current pose, "contact" only with a triangle pair intersecting at it. The state
// starts from the root after a pose jump or when its tree grew past max_pairs; while the poses keep jumping,
// and at a new state's first query, the query is the cold one and stores no front (the root pair alone where
// the objects were apart).
#pragma once

#include "coherent_binding.hpp"
#include "coherent_state.hpp"
#include "exact.hpp"

#include <chrono>
#include <optional>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <vector>

namespace bvhlab {

namespace coherent_detail {

inline constexpr std::uint32_t kCold = ~std::uint32_t{0};
using LeafPair = std::pair<std::uint32_t, std::uint32_t>;

/// One walk over the stored traversal tree (`stored`, possibly empty: from the root), writing the new one
/// into `next`. Iterative: a stack of items, each a pair to visit or an inner pair to try to raise.
template <TreeVolume BV, class Leaves>
class FrontWalk {
 public:
  using Pair = QueuedPair<BV>;
  using Hooks = ExactHooks<BV, Pair, Leaves>;

  FrontWalk(const TreePair<BV, Leaves>& trees, const std::vector<FrontPair>& stored,
            std::vector<FrontPair>& next, Hooks& hooks, std::uint8_t raise_hold)
      : trees_(trees), stored_(stored), next_(next), hooks_(hooks), raise_hold_(raise_hold) {}

  /// The leaf pair of the first contact (the hooks stop there in first-contact mode), or nullopt once the
  /// whole tree was walked. overlapping_root: the root pair, when the caller took it and found it
  /// overlapping.
  std::optional<LeafPair> run(const Pair* overlapping_root = nullptr) {
    next_.clear();
    parents_.clear();
    write(FrontPair{}, 0);
    items_.clear();
    const std::uint32_t stored = stored_.empty() ? kCold : 0;
    if (!overlapping_root)
      items_.push_back({trees_.template root<Pair>(), 0, stored, false});
    else if (auto hit = descend({*overlapping_root, 0, stored, false})) {
      mark_path(0);
      return hit;
    }
    while (!items_.empty()) {
      const Item item = items_.back();
      items_.pop_back();
      if (item.raise) {
        try_raise(item);
        continue;
      }
      ++trees_.counters.nodes_visited;
      if (item.stored != kCold && stored_[item.stored].count > 0) {
        reuse(item);
        continue;
      }
      if (auto hit = test(item)) {
        mark_path(item.out);
        return hit;
      }
    }
    return std::nullopt;
  }

 private:
  struct Item {
    Pair pair;             ///< the nodes and their walkers' state at the current pose
    std::uint32_t out;     ///< its entry in next_
    std::uint32_t stored;  ///< its entry in stored_, or kCold below a pair that overlaps now
    bool raise;            ///< after its children: try to make it a front pair again
  };
  /// Collects the exact strategy's child pairs of one pair (SplitLarger: two, right then left).
  struct Children {
    std::optional<Pair> at[2];
    int count = 0;
    bool child(Pair&& p) {
      at[count++].emplace(p);
      return true;
    }
  };

  /// A front pair, or a pair below one that overlaps: tested as the exact strategy tests it.
  std::optional<LeafPair> test(const Item& item) {
    if (!trees_.overlap(item.pair)) {
      next_[item.out].separated = 1;
      return std::nullopt;
    }
    return descend(item);
  }

  /// A pair that overlaps: its leaf test, or its children to visit.
  std::optional<LeafPair> descend(const Item& item) {
    const Pair& p = item.pair;
    if (trees_.is_leaf_pair(p)) {
      if (hooks_.leaf_pair(p) == Step::Decided) return LeafPair{p.a, p.b};
      return std::nullopt;
    }
    Children children;
    SplitLarger::expand(trees_, p, children);
    const auto first = static_cast<std::uint32_t>(next_.size());
    next_[item.out].first = first;
    next_[item.out].count = static_cast<std::uint8_t>(children.count);
    for (int c = 0; c < children.count; ++c) {
      const Pair& child = *children.at[c];
      write(FrontPair{child.a, child.b}, item.out);
      items_.push_back({child, first + static_cast<std::uint32_t>(c), kCold, false});
    }
    return std::nullopt;
  }

  /// An inner pair of the stored tree: not tested; its children are visited, then raising is tried.
  void reuse(const Item& item) {
    const FrontPair& old = stored_[item.stored];
    const auto first = static_cast<std::uint32_t>(next_.size());
    FrontPair& pair = next_[item.out];
    pair.first = first;
    pair.count = old.count;
    pair.hold = old.hold > 0 ? static_cast<std::uint8_t>(old.hold - 1) : std::uint8_t{0};
    if (pair.hold == 0) items_.push_back({item.pair, item.out, item.stored, true});
    const auto visit = [&](std::uint32_t c) {
      const FrontPair& child = stored_[old.first + c];
      items_.push_back({child_pair(item.pair, child.a, child.b), first + c, old.first + c, false});
    };
    std::uint32_t towards_witness = kCold;
    for (std::uint32_t c = 0; c < old.count; ++c) {
      const FrontPair& child = stored_[old.first + c];
      write(FrontPair{child.a, child.b}, item.out);
      if (child.leads_to_witness)
        towards_witness = c;
      else
        visit(c);
    }
    // Pushed last, so visited first: a contact lost at the remembered leaf pair is most likely found near it
    // (on the pipes at every step, 2 to 4 times fewer BV tests a query; bench/RESULTS.md).
    if (towards_witness != kCold) visit(towards_witness);
  }

  /// Appends a pair to the tree being built, with the entry of its parent there (the root's own: 0).
  /// Forced inline: clang++ kept it as a call per pair, which made the walk 15% to 25% slower.
  [[gnu::always_inline]] void write(const FrontPair& pair, std::uint32_t parent) {
    next_.push_back(pair);
    parents_.push_back(parent);
  }

  /// Marks the pair at `out` in next_ and its ancestors as leading to the contact found there, up the
  /// parents the walk noted: a step per level. (A backward search of next_ for each parent took a step per
  /// pair written, and on the pipes at 2.9 degrees a step a fifth of the walk's mispredicted branches.)
  void mark_path(std::uint32_t out) {
    for (;;) {
      next_[out].leads_to_witness = 1;
      if (out == 0) return;
      out = parents_[out];
    }
  }

  /// The walkers' state of a stored child pair, derived from its parent's at the current pose.
  Pair child_pair(const Pair& p, std::uint32_t a, std::uint32_t b) const {
    using Walker = VolumeWalker<BV>;
    using Working = typename Walker::Working;
    const Working wa = a == p.a ? Working(p.wa) : Walker::child_a(trees_.a, p.wa, a, trees_.context);
    const Working wb = b == p.b ? Working(p.wb) : Walker::child_b(trees_.b, p.wb, b, trees_.context);
    return Pair{{}, a, b, wa, wb, {}};
  }

  /// After the children of an inner pair: if all are disjoint front pairs, the pair itself is tested, and
  /// becomes a front pair when disjoint too.
  void try_raise(const Item& item) {
    FrontPair& pair = next_[item.out];
    for (std::uint32_t c = 0; c < pair.count; ++c) {
      const FrontPair& child = next_[pair.first + c];
      if (child.count != 0 || !child.separated) return;
    }
    if (trees_.overlap(item.pair)) {
      pair.hold = raise_hold_;
      return;
    }
    pair.count = 0;
    pair.separated = 1;
  }

  const TreePair<BV, Leaves>& trees_;
  const std::vector<FrontPair>& stored_;
  std::vector<FrontPair>& next_;
  Hooks& hooks_;
  std::uint8_t raise_hold_;
  /// The stack, kept by the thread between queries: a walk is never re-entered, and a query that allocated
  /// its stack each time cost as much as a short front's tests.
  static std::vector<Item>& thread_stack() {
    thread_local std::vector<Item> items;
    return items;
  }
  std::vector<Item>& items_ = thread_stack();
  /// The entry in next_ of each written pair's parent (the root's: 0), kept by the thread as the stack is.
  static std::vector<std::uint32_t>& thread_parents() {
    thread_local std::vector<std::uint32_t> parents;
    return parents;
  }
  std::vector<std::uint32_t>& parents_ = thread_parents();
};

}  // namespace coherent_detail

namespace coherent_detail {

/// The exact query's hooks, noting the leaf pair of the first contact.
template <TreeVolume BV, class Leaves>
class ContactNotingHooks : public ExactHooks<BV, QueuedPair<BV>, Leaves> {
  using Base = ExactHooks<BV, QueuedPair<BV>, Leaves>;

 public:
  using Base::Base;
  [[gnu::always_inline]] Step leaf_pair(const typename Base::Pair& p) {
    const Step step = Base::leaf_pair(p);
    if (step == Step::Decided) contact = LeafPair{p.a, p.b};
    return step;
  }
  std::optional<LeafPair> contact;
};

/// query_exact_coherent past its checks and the stored root pair: the remembered contact, the jump test, the
/// walk. `result` holds what the query did so far and receives its answer; `overlapping_root`, when given,
/// is the stored root pair the caller tested and found overlapping (apart at the last query, not now);
/// `tested_with`, the pair of trees the caller made for that test (at this pose, counting into `result`).
template <TreeVolume BV, class Leaves>
void exact_from_state(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a, CoherentState& state,
                      ContactMode mode, const Leaves& leaves, Result& result,
                      const typename FrontWalk<BV, Leaves>::Pair* overlapping_root,
                      const std::type_identity_t<TreePair<BV, Leaves>>* tested_with) {
  // What the query costs decides where the next ones start (CoherenceOptions::judge): the clock is read only
  // when that cost is the time.
  using Clock = std::chrono::steady_clock;
  const bool timed = state.options().judge == CoherenceOptions::Judge::time;
  const Clock::time_point start = timed ? Clock::now() : Clock::time_point{};
  const auto seconds = [&] {
    return timed ? std::chrono::duration<double>(Clock::now() - start).count() : 0.0;
  };
  // The cold query's answer, after what this query spent before it, recorded as a query from the root: on
  // the pair of trees the query made already, if it did (a k-DOP's context costs about 5,100 instructions).
  // Objects it found apart at the root pair leave that pair as the stored tree: the next query tests it
  // alone (query_exact_coherent), as after a walk that found the same. In a cold turn its contact's leaf
  // pair is remembered, to be tried first by the next query; while the poses keep jumping it is not.
  const auto cold_answer = [&](const TreePair<BV, Leaves>* made, bool keep_contact) {
    const Counters spent = result.counters;
    std::optional<LeafPair> contact;
    const auto note = [&contact](const ContactNotingHooks<BV, Leaves>& hooks) { contact = hooks.contact; };
    if (made) {
      traverse_exact<ContactNotingHooks<BV, Leaves>>(*made, result, mode, note);
    } else if (!keep_contact) {
      // The cold query's own compiled traversal: while the poses keep jumping, this is every query, and
      // the same work in another copy of the loop ran up to a fifth slower (bench_coherence, stride 64).
      result = exact_traversal_with<ExactHooks<BV, QueuedPair<BV>, Leaves>>(a, b, b_to_a, mode, leaves,
                                                                            NothingToNote{});
      result.counters += spent;
    } else {
      result = exact_traversal_with<ContactNotingHooks<BV, Leaves>>(a, b, b_to_a, mode, leaves, note);
      result.counters += spent;
    }
    const Counters& now = result.counters;
    if (!result.collides && now.bv_tests == spent.bv_tests + 1 && now.triangle_tests == spent.triangle_tests)
      state.store_root_apart(b_to_a);
    state.witness = keep_contact ? contact : std::nullopt;
    state.record_cost(now, seconds(), CoherentState::Start::Root);
  };
  // In a cold turn (the front cost more than starting from the root) the front is not walked: the query is
  // the cold one, but for the turn's last, a walk from the root that leaves its front. The remembered
  // contact is still tried first (where contact persists, a fifth to a half of the cold turns' queries on
  // the pipes at 2.9 degrees a step; bench/RESULTS.md, "Contacts kept through cold turns").
  const bool cold = state.cold_turns_left() > 0;
  const bool cold_only = state.cold_turns_left() > 1;
  const bool try_contact = mode == ContactMode::First && state.witness.has_value();
  if (cold_only && !try_contact) {
    cold_answer(nullptr, true);
    return;
  }
  // With nothing stored (the poses jumped before, or the state is new) there is no remembered contact or root
  // pair to try first: the jump is judged before the traversal's set-up, so that while the poses keep
  // jumping the cold query answers at little more than its own cost. A new state's first query counts as one
  // of such a run (CoherentState::jumped): it is the cold one.
  std::optional<bool> jumped;
  if (!cold && !state.witness && state.pairs().empty()) {
    jumped = state.jumped(b_to_a);
    if (*jumped && state.jumping_on()) {
      state.forget_front(b_to_a);
      cold_answer(nullptr, false);
      return;
    }
  }
  if (a.empty() || b.empty()) return;
  if constexpr (Leaves::kTriangles) TriangleLeaves::require(a, b, "coherent exact query");
  // The volumes' context is made once a query: the caller's, where it tested the root pair (a k-DOP's costs
  // about 5,100 instructions, and most root pairs of a world's candidate pairs overlap).
  std::optional<typename VolumeWalker<BV>::Context> own_context;
  std::optional<TreePair<BV, Leaves>> own_trees;
  if (!tested_with) {
    own_context.emplace(VolumeWalker<BV>::make_context(b_to_a));
    own_trees.emplace(a, b, b_to_a, *own_context, result.counters, leaves);
  }
  const TreePair<BV, Leaves>& trees = tested_with ? *tested_with : *own_trees;
  using Walk = FrontWalk<BV, Leaves>;
  typename Walk::Hooks hooks(trees, result, mode);
  if (try_contact) {
    const auto [i, j] = *state.witness;
    if (hooks.leaf_pair(typename Walk::Pair{{}, i, j, {}, {}, {}}) == Step::Decided) {
      state.count_witness_hit();
      // A hit in a cold turn takes the turn's place: what it cost is neither a walk's nor a cold query's.
      if (cold)
        state.skip_cold_turn();
      else
        state.record_cost(result.counters, seconds(), CoherentState::Start::Front);
      return;
    }
  }
  if (cold_only) {
    cold_answer(&trees, true);  // after the remembered contact's test
    return;
  }
  // A pose that jumped from the last query's: no front of there pays here. After a query that did not
  // jump, the walk starts from the root and leaves a front for the steps that follow. While the poses keep
  // jumping, that walk would cost a cold query and more each time for a front never used (bench/RESULTS.md,
  // "How far a pose may jump"): the cold query answers and the state notes the pose alone.
  if (!jumped) jumped = !cold && state.jumped(b_to_a);
  if (*jumped && state.jumping_on()) {
    state.forget_front(b_to_a);
    cold_answer(&trees, false);  // after the remembered contact's or the root pair's test
    return;
  }
  const bool from_front = !cold && !*jumped && !state.pairs().empty();
  if (!from_front) state.pairs().clear();
  std::vector<FrontPair>& next = state.spare();
  Walk walk(trees, state.pairs(), next, hooks, state.options().raise_hold);
  state.witness = walk.run(overlapping_root);
  // A contact ends the walk early; the tree it built is still a cut of every pair (each pair not reached yet
  // is a front pair there, to be tested), so the next query starts from it rather than from the root.
  const std::size_t written = next.size();
  state.store(next, b_to_a);
  state.record_cost(result.counters, seconds(),
                    from_front ? CoherentState::Start::Front : CoherentState::Start::Root, written);
}

}  // namespace coherent_detail

/// Exact first-contact (or all-contacts) query that starts from `state`, the memory of the previous queries
/// on the same two trees (traversal/coherent_state.hpp), and leaves its own there. Answers, witnesses and
/// contacts are those of query_exact; the counters say what this query tested. Throws std::invalid_argument
/// for a non-rigid pose or a state made for other trees, std::logic_error for a state another query is
/// using. The trees are read only: any number of states may share them, one per caller.
template <TreeVolume BV, class Leaves = TriangleLeaves>
Result query_exact_coherent(const Bvh<BV>& a, const Bvh<BV>& b, const RigidTransform& b_to_a,
                            CoherentState& state, ContactMode mode = ContactMode::First,
                            const Leaves& leaves = kTriangleLeaves) {
  check_exact_query<Leaves>(b_to_a, mode);
  const CoherentState::InUse in_use(state);
  coherent_detail::attach(state, a, b);
  state.serve(CoherentState::Use::Exact);
  Result result;  // every path returns it: a Result moved costs about what the root pair's test does
  result.exact = true;
  // Objects apart at the last query (which remembers no contact then): walking the stored tree is testing
  // the root pair, so it is tested first, before the rest of the set-up, as the cold query would test it.
  // Apart still, that is the answer, at about the cold query's cost, and not recorded as the front's
  // (record_cost compares walks with queries from the root); overlapping now, it is walked from there.
  // A deeper stored tree without a contact is tested at its root pair first too, while that pays
  // (CoherentState::root_check_due): objects moving apart leave a front that rises back to the root pair
  // only level by level, each level held for raise_hold queries, and walking it cost up to 14 times the
  // root pair's test (bench/RESULTS.md, "The root pair before a stored front").
  const bool root_apart = state.root_apart();
  if (state.cold_turns_left() == 0 &&
      (root_apart || (!state.witness && !state.pairs().empty() && state.root_check_due()))) {
    const auto context = VolumeWalker<BV>::make_context(b_to_a);
    const TreePair<BV, Leaves> trees(a, b, b_to_a, context, result.counters, leaves);
    ++result.counters.nodes_visited;
    const auto root = trees.template root<typename coherent_detail::FrontWalk<BV, Leaves>::Pair>();
    const bool apart = !trees.overlap(root);
    if (!root_apart) state.root_checked(apart);
    if (apart) {
      // A cut of every triangle pair at this pose, as the cold query would leave it.
      if (root_apart)
        state.restamp(b_to_a);
      else
        state.store_root_apart(b_to_a);
      return result;
    }
    // Overlapping: from the root pair just tested where it was the stored tree, else the stored tree.
    coherent_detail::exact_from_state(a, b, b_to_a, state, mode, leaves, result, root_apart ? &root : nullptr,
                                      &trees);
    return result;
  }
  coherent_detail::exact_from_state(a, b, b_to_a, state, mode, leaves, result, nullptr, nullptr);
  return result;
}

}  // namespace bvhlab

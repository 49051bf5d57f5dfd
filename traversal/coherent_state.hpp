// What a coherent query keeps between the queries of one pair of trees (traversal/coherent.hpp): the front
// where the last traversal stopped, the colliding leaf pair it found, and the pose it was computed at.
// No templates: the same state serves every volume, so callers above the typed layer can hold one.
#pragma once

#include "../volumes/geometry.hpp"
#include "result.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace bvhlab {

/// When a coherent query starts from the root instead of the stored front.
struct CoherenceOptions {
  /// A stored traversal tree of more pairs than this is dropped after the query that made it; the next
  /// query starts from the root. 16 bytes a pair: the default holds 4 MiB.
  std::size_t max_pairs = std::size_t{1} << 18;
  /// The pose jumps when some point of B's root box moves (relative to A) by more than this many of the
  /// box's radii since the last query: the query starts from the root. While the poses keep jumping (two
  /// jumps in a row), it runs as the cold one and stores no front. 0.2: on the protocol, steps of up to
  /// about 3 degrees keep their front and steps of 11 run cold (bench/RESULTS.md, "The default max_jump").
  double max_jump = 0.2;
  /// A front pair whose parent pair was tested for raising and still overlapped waits this many queries
  /// before its parent is tested again (so pairs close to contact do not pay a useless test every query).
  std::uint8_t raise_hold = 8;
  /// Where the pose changes too much between queries for the front to pay, walking it costs more than a
  /// query from the root. When the front's recent walks cost more than the median of the last 8 queries from
  /// the root (CoherentState::record_cost), the next queries start from the root: 2 of them, twice as many
  /// each time the front loses again, at most this many. 0: always walk the front.
  std::uint32_t max_cold_run = 128;
  /// What "cost" means there. `work` (the default): node pairs, BV tests and triangle tests (four BV tests
  /// each), and five units per pair a walk stores (the cold query stores none), which repeat exactly from
  /// run to run, so the counters do too. `time`: each query's own
  /// seconds, what the caller pays: a walk's node pair costs 1.05 to 2.5 times a cold traversal's, by
  /// volume (bench/RESULTS.md), which the work does not see; the counters then vary from run to run.
  enum class Judge : std::uint8_t { work, time };
  Judge judge = Judge::work;

  /// Throws std::invalid_argument for nonsense values (max_pairs 0, a NaN or negative max_jump).
  void validate() const;
};
/// "work" or "time".
std::string_view to_string(CoherenceOptions::Judge judge);
/// Parses "work" or "time"; throws std::invalid_argument naming the bad value.
CoherenceOptions::Judge judge_from_string(std::string_view name);

/// One pair of the stored traversal tree: the node pairs the last query reached, each either a front pair
/// (count 0: tested again by the next query) or an inner pair whose `count` children follow at `first`.
struct FrontPair {
  std::uint32_t a = 0, b = 0;
  std::uint32_t first = 0;
  std::uint8_t count = 0;
  std::uint8_t separated = 0;         ///< a front pair whose volumes were disjoint when last tested
  std::uint8_t hold = 0;              ///< queries before raising this pair's children is tried again
  std::uint8_t leads_to_witness = 0;  ///< the pair or an ancestor of the remembered contact's leaf pair
};
static_assert(sizeof(FrontPair) == 16, "CoherenceOptions::max_pairs counts 16 bytes a pair");

/// The memory of one pair of trees across queries. Belongs to one caller: a state used by two queries at
/// once is refused (std::logic_error), and a state made for other trees too (std::invalid_argument).
/// Whatever it holds, an exact query stays exact: the front is a cut of every triangle pair, re-tested at the
/// current pose, and a remembered contact counts only if its triangles intersect at the current pose.
class CoherentState {
 public:
  explicit CoherentState(CoherenceOptions options = {});

  /// Forgets the stored front, the remembered contact and what the front's walks cost: the next query
  /// starts from the root. The trees it is bound to and its counters (jumps, witness hits, cold runs) stay.
  void reset();
  [[nodiscard]] const CoherenceOptions& options() const { return options_; }
  /// Front pairs of the stored traversal tree (0 before the first query).
  [[nodiscard]] std::size_t front_size() const;
  /// Pairs stored (front and inner).
  [[nodiscard]] std::size_t stored_pairs() const { return pairs_.size(); }
  /// Queries that started from the root although a front was stored (the pose jumped).
  [[nodiscard]] std::uint64_t jumps() const { return jumps_; }
  /// Queries answered by the remembered contact alone.
  [[nodiscard]] std::uint64_t witness_hits() const { return witness_hits_; }
  /// Queries that started from the root because walking the front had cost more (max_cold_run).
  [[nodiscard]] std::uint64_t cold_queries() const { return cold_queries_; }

  // ---- For the coherent queries (traversal/coherent.hpp) ----------------------------------------------
  /// What a state is bound to of one tree: its address, its identity (Bvh::identity: the topology the
  /// stored node pairs index) and its node count.
  struct TreeKey {
    const void* address = nullptr;
    std::uint64_t identity = 0;
    std::size_t nodes = 0;
    friend bool operator==(const TreeKey&, const TreeKey&) = default;
  };
  /// Binds the state to its trees and B's root box (its centre and radius in B's frame: what a pose jump is
  /// measured against).
  void bind(const TreeKey& a, const TreeKey& b, const Vec3& centre, double radius);
  [[nodiscard]] bool bound() const { return a_.address != nullptr; }
  /// Throws std::invalid_argument unless the state is unbound or bound to these trees: the same objects,
  /// with the topology they had (not rebuilt, not another tree made at the address of one that is gone).
  void check_trees(const TreeKey& a, const TreeKey& b) const {
    if (bound() && (a != a_ || b != b_)) refuse_other_trees();
  }
  /// Marks the state in use; throws std::logic_error when another thread's query holds it. Each coherent
  /// query holds it for itself; a loop of queries may hold it around them all (the engine's runs do), so
  /// that each query finds it held by its own thread and skips the atomic exchange, which cost about a
  /// sixth of a query decided at the root pair (bench/RESULTS.md, "The state held for a run").
  class InUse {
   public:
    explicit InUse(CoherentState& state) : state_(state) {
      if (held_here_ == &state) return;  // this thread holds it already: the loop around this query
      acquire();
    }
    ~InUse() {
      if (owner_) release();
    }
    InUse(const InUse&) = delete;
    InUse& operator=(const InUse&) = delete;

   private:
    void acquire();
    void release();
    CoherentState& state_;
    bool owner_ = false;                    ///< this guard took the state (not one around it)
    const CoherentState* outer_ = nullptr;  ///< what this thread held before
  };

  /// True when `pose` lies farther than max_jump from the pose of the last query that stored its front or
  /// noted its pose (store, restamp, forget_front); counts the jump. True, but not counted, while no query
  /// has: a new state's first query is answered cold (traversal/coherent.hpp).
  [[nodiscard]] bool jumped(const RigidTransform& pose);
  /// Whether the last two calls of jumped() were both true (or the first call, on a state that had seen no
  /// pose, was true): the poses keep jumping.
  [[nodiscard]] bool jumping_on() const { return jumping_on_; }
  std::vector<FrontPair>& pairs() { return pairs_; }
  /// Whether the stored tree is the root pair alone, disjoint when last tested: the objects were apart.
  [[nodiscard]] bool root_apart() const {
    return pairs_.size() == 1 && pairs_[0].count == 0 && pairs_[0].separated != 0;
  }
  std::vector<FrontPair>& spare() { return spare_; }
  /// Keeps `next` (built for `pose`) as the stored tree, or drops it when larger than max_pairs.
  void store(std::vector<FrontPair>& next, const RigidTransform& pose);
  /// The stored tree holds at `pose` as it is (a root pair found disjoint there again).
  void restamp(const RigidTransform& pose) {
    pose_ = pose;
    stamped_ = true;
  }
  /// Keeps the root pair alone, disjoint at `pose`: a query from the root found the objects apart there, and
  /// the next query tests that pair without a walk (root_apart), as after a walk that found the same.
  void store_root_apart(const RigidTransform& pose) {
    pairs_.assign(1, FrontPair{.separated = 1});
    restamp(pose);
  }
  /// Drops the stored tree and notes `pose` alone: a query after a pose jump, answered from the root.
  void forget_front(const RigidTransform& pose) {
    pairs_.clear();
    restamp(pose);
  }
  /// The node pair that decided the last answer, if one did: the exact queries' colliding leaf pair, the
  /// ADB queries' deciding pair (traversal/coherent_adb.hpp).
  std::optional<std::pair<std::uint32_t, std::uint32_t>> witness;
  /// What filled the state: an exact, ADB, guided exact, distance or tolerance query (their node pairs mean
  /// different things).
  enum class Use : std::uint8_t { None, Exact, Adb, Guided, Distance, Tolerance };
  /// Starts the state afresh (reset) when it was filled by another kind of query.
  void serve(Use use) {
    if (use_ == use) return;
    reset();
    use_ = use;
  }
  void count_witness_hit() { ++witness_hits_; }
  /// Whether a query with a stored tree deeper than the root pair, and no remembered contact, tests the root
  /// pair first (traversal/coherent.hpp): yes, unless that test found the root pair overlapping lately.
  /// Each such test waits twice as many queries as the last (1, 2, 4, up to 64) until one finds it apart,
  /// so where the objects' root volumes keep overlapping it costs at most a test in 64 queries.
  [[nodiscard]] bool root_check_due() {
    if (root_wait_ == 0) return true;
    --root_wait_;
    return false;
  }
  /// What the root pair's test of root_check_due found.
  void root_checked(bool apart) {
    root_backoff_ = apart ? 0 : std::min<std::uint8_t>(64, root_backoff_ == 0 ? 1 : 2 * root_backoff_);
    root_wait_ = root_backoff_;
  }
  /// While the front lost its last comparison with queries from the root: the queries of that run still to
  /// go (this one included). They start from the root; the last one builds the front the next walk starts
  /// from.
  [[nodiscard]] std::uint32_t cold_turns_left() const { return cold_left_; }
  /// A query of a cold turn answered otherwise (by the remembered contact): one turn fewer to go, but for
  /// the turn's last, which builds the front and waits for a query that needs it.
  void skip_cold_turn() {
    if (cold_left_ > 1) --cold_left_;
  }
  /// How a query started, for record_cost.
  enum class Start : std::uint8_t { Front, Root };
  /// Records one query's cost (its seconds or its work: CoherenceOptions::judge) and decides whether the
  /// next queries walk the front or start from the root.
  /// `pairs_written`: the pairs of the tree a walk stored.
  void record_cost(const Counters& counters, double seconds, Start start, std::size_t pairs_written = 0);

 private:
  [[nodiscard]] bool moved_too_far(const RigidTransform& pose) const;
  [[noreturn]] static void refuse_other_trees();

  CoherenceOptions options_;
  TreeKey a_, b_;
  Vec3 b_centre_ = Vec3::Zero();
  double b_radius_ = 0;
  std::vector<FrontPair> pairs_;  ///< the stored traversal tree; pairs_[0] is the root pair
  std::vector<FrontPair> spare_;  ///< the next tree is built here, then swapped in (no allocation per query)
  RigidTransform pose_;           ///< the pose pairs_ was computed at, or the last query's after a jump
  bool stamped_ = false;          ///< pose_ is a query's (not the state's initial value)
  bool last_jumped_ = false, jumping_on_ = false;  ///< the last two answers of jumped()
  std::uint64_t jumps_ = 0, witness_hits_ = 0, cold_queries_ = 0;
  Use use_ = Use::None;
  // The comparison of the front's walks with queries from the root (record_cost); cost < 0: none yet.
  double front_cost_ = -1;
  /// The last queries from the root, their costs: record_cost compares the front with their median, so
  /// that one pose far costlier than the rest (a new state's first query, say) does not stand for all.
  std::array<double, 8> root_costs_{};
  std::uint8_t root_count_ = 0, root_next_ = 0;
  double root_cost_ = -1;  ///< their median, kept as each comes in; < 0: none yet
  void add_root_cost(double cost);
  std::uint32_t cold_left_ = 0;  ///< queries from the root still to run before the front is tried again
  std::uint32_t cold_run_ = 2;   ///< the length of the next such run
  std::uint8_t root_backoff_ = 0, root_wait_ = 0;  ///< root_check_due: the current wait, the queries left
  /// The state this thread holds (InUse), if any.
  static inline thread_local const CoherentState* held_here_ = nullptr;
  /// Set while a query uses the state; a copy of the state is not in use.
  struct BusyFlag {
    std::atomic<bool> busy{false};
    BusyFlag() = default;
    BusyFlag(const BusyFlag&) {}
    BusyFlag& operator=(const BusyFlag&) { return *this; }
  } busy_;
};

}  // namespace bvhlab

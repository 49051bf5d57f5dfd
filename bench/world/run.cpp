#include "bench/world/world.hpp"

#include "bench/pairs/advice.hpp"
#include "bench/pairs/plan.hpp"
#include "bench/pairs/prepare.hpp"
#include "bench/report_tables.hpp"
#include "bench/world/motion.hpp"
#include "engine/policies.hpp"
#include "traversal/broad_phase/registry.hpp"
#include "traversal/coherent_state.hpp"
#include "traversal/frame_budget.hpp"

#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_model.hpp"
#endif

#include <algorithm>
#include <array>
#include <fstream>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>

namespace bvhlab {

namespace {

constexpr int kScalingFrames = 10;

std::vector<std::string> instance_objects(const Scene& scene) {
  std::vector<std::string> objects;
  for (const WorldInstance& instance : scene.world->instances) objects.push_back(instance.object);
  return objects;
}

/// `count` copies of the scene's objects (cyclically) at the scene's density: the region grows with the
/// count, the walk keeps its steps; kScalingFrames frames of it. What every broad phase's scaling row runs
/// on.
struct ScalingWorld {
  std::vector<std::string> objects;
  std::vector<std::vector<RigidTransform>> frames;
};

ScalingWorld scaling_world(const Scene& scene, int count) {
  const WorldSpec& w = *scene.world;
  const std::vector<std::string> names = instance_objects(scene);
  ScalingWorld out;
  for (int i = 0; i < count; ++i) out.objects.push_back(names[static_cast<std::size_t>(i) % names.size()]);
  const double grow = std::cbrt(double(count) / double(names.size()));
  const Box region{w.region.center() - 0.5 * grow * w.region.extent(),
                   w.region.center() + 0.5 * grow * w.region.extent()};
  const std::vector<std::optional<RigidTransform>> random(out.objects.size());
  out.frames = random_walk(random, region, w.seed + 1, kScalingFrames, w.step, w.turn_deg);
  return out;
}

/// The coherent states of a world's instance pairs: a pair that is a candidate again starts where its last
/// query ended (a pose that moved too far since starts from the root: CoherenceOptions::max_jump).
using PairStates = std::map<ObjectPair, CoherentState>;

/// A candidate pair of one frame: the instances, the prepared trees of their objects and B's pose in A's.
struct Candidate {
  ObjectPair instances;
  const PreparedHierarchy* trees = nullptr;
  RigidTransform b_to_a;
  bool truth = false;
};

/// The objects, trees and broad phases of one hierarchy, made once and used in every frame.
class WorldHierarchy {
 public:
  WorldHierarchy(const Scene& scene, const PlannedHierarchy& planned, Preparation& preparation)
      : scene_(scene), planned_(planned), preparation_(preparation) {
    for (const std::string& name : scene.world->broad_phases) broad_phases_.push_back(make_broad_phase(name));
  }

  [[nodiscard]] const PlannedHierarchy& planned() const { return planned_; }
  /// The frame schedules' memories of the previous frame, by series (run_frame_budgets).
  std::map<std::string, FrameMemory>& memories() { return memories_; }
  /// A coherent variant's state of each instance pair, carried from frame to frame (by series).
  PairStates& coherent_states(const std::string& series) { return coherent_states_[series]; }

  /// The prepared trees of two objects (by name), made on first use.
  const PreparedHierarchy& trees(const std::string& a, const std::string& b) {
    auto& slot = pairs_[{a, b}];
    if (!slot)
      slot = preparation_.hierarchy(planned_, preparation_.object(*scene_.object(a)),
                                    preparation_.object(*scene_.object(b)));
    return *slot;
  }

  /// Each object's own prepared trees (the source of its world box), looked up before any timing.
  std::vector<const PreparedHierarchy*> own_trees(std::span<const std::string> objects) {
    std::vector<const PreparedHierarchy*> out;
    for (const std::string& o : objects) out.push_back(&trees(o, o));
    return out;
  }

  /// The world box of every instance: own[i]'s tree placed by poses[i].
  static std::vector<Box> world_boxes(std::span<const PreparedHierarchy* const> own,
                                      std::span<const RigidTransform> poses) {
    std::vector<Box> boxes;
    boxes.reserve(own.size());
    for (std::size_t i = 0; i < own.size(); ++i) boxes.push_back(own[i]->world_box(poses[i]));
    return boxes;
  }

  /// Every broad phase on the frame's world boxes (timed, rows into `out`); their common answer.
  std::vector<ObjectPair> candidates(int frame, std::span<const RigidTransform> poses,
                                     std::vector<BroadPhaseRow>& out) {
    if (instance_trees_.empty()) instance_trees_ = own_trees(instance_objects(scene_));
    const auto start = Clock::now();
    const std::vector<Box> boxes = world_boxes(instance_trees_, poses);
    const double boxes_micros = micros_since(start);
    std::vector<ObjectPair> first;
    for (const auto& broad_phase : broad_phases_) {
      const auto begin = Clock::now();
      broad_phase->update(boxes);
      const std::vector<ObjectPair>& pairs = broad_phase->pairs();
      const double update_micros = micros_since(begin);
      out.push_back({frame, planned_.hierarchy->name, std::string(broad_phase->name()), boxes.size(),
                     pairs.size(), boxes_micros, update_micros});
      if (&broad_phase == &broad_phases_.front())
        first = pairs;
      else if (pairs != first)
        throw std::logic_error("broad phases " + std::string(broad_phases_.front()->name()) + " and " +
                               std::string(broad_phase->name()) + " disagree in frame " +
                               std::to_string(frame));
    }
    return first;
  }

  /// Each broad phase alone on scaling_world(count); medians over its frames.
  std::vector<ScalingRow> scaling(int count) {
    const ScalingWorld world = scaling_world(scene_, count);
    const std::vector<const PreparedHierarchy*> own = own_trees(world.objects);
    std::vector<ScalingRow> rows;
    for (const std::string& name : scene_.world->broad_phases) {
      std::unique_ptr<AnyBroadPhase> broad_phase = make_broad_phase(name);
      std::vector<double> boxes_micros, update_micros, candidates;
      for (const auto& poses : world.frames) {
        const auto start = Clock::now();
        const std::vector<Box> boxes = world_boxes(own, poses);
        boxes_micros.push_back(micros_since(start));
        const auto begin = Clock::now();
        broad_phase->update(boxes);
        candidates.push_back(double(broad_phase->pairs().size()));
        update_micros.push_back(micros_since(begin));
      }
      rows.push_back({planned_.hierarchy->name, name, world.objects.size(),
                      static_cast<std::size_t>(report_tables::median(candidates)),
                      report_tables::median(boxes_micros), report_tables::median(update_micros)});
    }
    return rows;
  }

 private:
  const Scene& scene_;
  const PlannedHierarchy& planned_;
  Preparation& preparation_;
  std::vector<std::unique_ptr<AnyBroadPhase>> broad_phases_;
  std::vector<const PreparedHierarchy*> instance_trees_;
  std::map<std::pair<std::string, std::string>, std::unique_ptr<PreparedHierarchy>> pairs_;
  std::map<std::string, FrameMemory> memories_;
  std::map<std::string, PairStates> coherent_states_;
};

/// The pair rows a run keeps (RunOptions::per_pose): every answer, or only the wrong ones, each of the frame
/// and hierarchy being run.
struct PairRows {
  PerPose mode = PerPose::none;
  const std::vector<WorldInstance>* instances = nullptr;
  int frame = 0;
  std::string hierarchy;
  std::vector<WorldPairRow> rows;

  void add(const std::string& series, const Candidate& c, bool collides, bool flagged, double probability,
           double micros, std::uint64_t bv_tests) {
    if (mode == PerPose::none || (mode == PerPose::wrong && collides == c.truth)) return;
    rows.push_back({frame, hierarchy, series, (*instances)[c.instances.a].name,
                    (*instances)[c.instances.b].name, c.truth, collides, flagged, probability, micros,
                    bv_tests});
  }
};

/// Counts one series' answers against the truth.
void count(WorldSeriesRow& row, const std::vector<Candidate>& candidates, const std::vector<char>& answers,
           const std::vector<char>& flagged) {
  row.candidates = candidates.size();
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    row.colliding += candidates[k].truth;
    row.answered += answers[k];
    row.missed += candidates[k].truth && !answers[k];
    row.false_pairs += !candidates[k].truth && answers[k];
    row.flagged += flagged[k];
  }
}

/// A per-pair strategy on every candidate pair, each query timed alone (as the pair runner times them); a
/// coherent variant continues each pair's state in `states`.
WorldSeriesRow run_variant(const StrategyVariant& variant, const std::vector<Candidate>& candidates,
                           int warmup, PairStates& states, PairRows& pair_rows) {
  WorldSeriesRow row;
  row.series = variant.label();
  row.exact_strategy = strategy_info(variant.strategy).exact;
  std::vector<char> answers(candidates.size()), flagged(candidates.size());
  std::vector<QueryRecord> records;
  for (std::size_t k = 0; k < candidates.size(); ++k) {
    records.clear();
    const auto pose = std::span(&candidates[k].b_to_a, 1);
    if (variant.coherent)
      candidates[k].trees->run(variant, pose, warmup, records, states[candidates[k].instances]);
    else
      candidates[k].trees->run(variant, pose, warmup, records);
    row.micros += records.front().micros;
    row.bv_tests += records.front().counters.bv_tests;
    answers[k] = records.front().collides;
    flagged[k] = records.front().budget_exhausted;
    pair_rows.add(row.series, candidates[k], answers[k], flagged[k], records.front().probability,
                  records.front().micros, records.front().counters.bv_tests);
  }
  count(row, candidates, answers, flagged);
  return row;
}

/// One frame budget on every candidate pair at once, through the trees' own type (schedule_frame), with
/// the schedule's memory of the previous frame when it keeps one (each pair named by its two instances).
std::vector<PairOutcome> schedule(const PlannedHierarchy& planned, const std::vector<Candidate>& candidates,
                                  const FrameOptions& options, FrameMemory* memory, double& micros) {
  std::vector<FramePairRef> pairs;
  pairs.reserve(candidates.size());
  for (const Candidate& c : candidates) {
    const auto [a, b] = c.trees->trees();
    if (!a)
      throw std::invalid_argument("frame budgets run on bvhlab trees; hierarchy " + planned.hierarchy->name +
                                  " has none");
    pairs.push_back({a, b, c.b_to_a, std::uint64_t{c.instances.a} << 32 | c.instances.b});
  }
  const auto start = Clock::now();
  std::vector<PairOutcome> out = AnyTree::schedule_frame(pairs, options, memory);
  micros = micros_since(start);
  return out;
}

/// Each schedule runs once untimed first when `warmup` > 0, as each per-pair query does (run_variant): the
/// series of a frame then find the trees equally warm, whichever runs first. A schedule with memory keeps
/// one FrameMemory over the frames in `memories` (by series); its warm-up runs on a copy, so the timed run
/// recalls the previous frame, not the warm-up's answers for this one.
std::vector<WorldSeriesRow> run_frame_budgets(const Scene& scene, const PlannedHierarchy& planned,
                                              const std::vector<Candidate>& candidates, int warmup,
                                              std::map<std::string, FrameMemory>& memories,
                                              PairRows& pair_rows) {
  std::vector<WorldSeriesRow> rows;
  for (const FrameBudgetSpec& spec : scene.world->frame_budgets) {
    if (!spec.applies_to(*planned.hierarchy)) continue;
    for (const std::string& policy : spec.schedules)
      for (const Budget& budget : spec.budgets) {
        FrameOptions options;
        options.policy = policy;
        options.p_min = spec.p_min;
        options.adb.confirm_levels = static_cast<std::uint8_t>(spec.confirm_levels);
        options.order = frame_order(spec.order);
        options.budget = budget;
        WorldSeriesRow row;
        // A confirming schedule is a line of its own in the figures, beside the same policy without it.
        row.schedule = policy;
        if (options.order != FrameOrder::best_first) row.schedule += " " + spec.order;
        if (spec.confirm_levels > 0) row.schedule += " confirm_levels=" + std::to_string(spec.confirm_levels);
        if (spec.memory) row.schedule += " memory";
        row.budget = budget_label(budget);
        row.budget_bv_tests = budget.max_bv_tests;
        row.budget_deadline_us = budget.deadline_us;
        row.series = "frame " + row.schedule + " " + row.budget + " p_min=" + parameter_text(spec.p_min);
        FrameMemory* memory = spec.memory ? &memories[row.series] : nullptr;
        if (warmup > 0) {
          std::optional<FrameMemory> scratch;
          if (memory) scratch = *memory;
          schedule(planned, candidates, options, scratch ? &*scratch : nullptr, row.micros);
        }
        const std::vector<PairOutcome> outcomes = schedule(planned, candidates, options, memory, row.micros);
        std::vector<char> answers(candidates.size()), flagged(candidates.size());
        for (std::size_t k = 0; k < outcomes.size(); ++k) {
          answers[k] = outcomes[k].collides;
          flagged[k] = outcomes[k].budget_exhausted;
          if (outcomes[k].counters.bv_tests == 0) {
            ++row.untested;
            row.untested_colliding += candidates[k].truth;
          }
          row.bv_tests += outcomes[k].counters.bv_tests;
          pair_rows.add(row.series, candidates[k], answers[k], flagged[k], outcomes[k].probability, -1,
                        outcomes[k].counters.bv_tests);
        }
        count(row, candidates, answers, flagged);
        rows.push_back(std::move(row));
      }
  }
  return rows;
}

/// A frame-budget series summed over the run's frames, with what picks its comparison: its schedule and the
/// size of its budget in its own kind (tests, or microseconds; a budget of both kinds counts by tests).
struct BudgetTotals {
  RootRoundShortfall shortfall;
  std::string schedule;
  double budget = 0;
};

/// Each frame-budget series summed over the run's frames, in first-seen order.
std::vector<BudgetTotals> frame_budget_totals(const std::vector<WorldSeriesRow>& rows) {
  std::vector<BudgetTotals> out;
  std::map<std::pair<std::string, std::string>, std::size_t> index;
  for (const WorldSeriesRow& row : rows) {
    if (row.schedule.empty()) continue;
    auto [it, fresh] = index.try_emplace({row.hierarchy, row.series}, out.size());
    if (fresh) {
      BudgetTotals& t = out.emplace_back();
      t.shortfall.series = row.series;
      t.shortfall.hierarchy = row.hierarchy;
      t.shortfall.counts_tests = row.budget_bv_tests > 0;
      t.schedule = row.schedule;
      t.budget = t.shortfall.counts_tests ? double(row.budget_bv_tests) : row.budget_deadline_us;
    }
    RootRoundShortfall& s = out[it->second].shortfall;
    ++s.frames;
    s.frames_short += row.untested > 0;
    s.candidates += row.candidates;
    s.most_candidates = std::max(s.most_candidates, row.candidates);
    s.untested += row.untested;
    s.untested_colliding += row.untested_colliding;
    s.colliding += row.colliding;
    s.missed += row.missed;
  }
  return out;
}

/// "The right tool" for every frame-budget series that left a pair without its root test in some frame,
/// with the same schedule's smallest budget of the same kind that covered every round, when the run has one.
std::vector<std::string> root_round_advice(const std::vector<WorldSeriesRow>& rows) {
  const std::vector<BudgetTotals> totals = frame_budget_totals(rows);
  std::vector<std::string> advice;
  for (const BudgetTotals& short_one : totals) {
    RootRoundShortfall s = short_one.shortfall;
    if (s.untested == 0) continue;
    double smallest = std::numeric_limits<double>::infinity();
    for (const BudgetTotals& other : totals) {
      const RootRoundShortfall& o = other.shortfall;
      if (o.untested > 0 || o.hierarchy != s.hierarchy || o.counts_tests != s.counts_tests ||
          other.schedule != short_one.schedule || !(other.budget < smallest))
        continue;
      smallest = other.budget;
      s.covered_series = o.series;
      s.covered_colliding = o.colliding;
      s.covered_missed = o.missed;
    }
    advice.push_back(root_round_advice(s));
  }
  return advice;
}

/// The candidate pairs of a frame with their exact answers (memoised per frame across hierarchies: any
/// exact traversal gives the same answer).
std::vector<Candidate> with_truth(WorldHierarchy& h, const Scene& scene, std::span<const ObjectPair> pairs,
                                  std::span<const RigidTransform> poses,
                                  std::map<std::pair<std::uint32_t, std::uint32_t>, bool>& truth) {
  const auto& instances = scene.world->instances;
  std::vector<Candidate> out;
  for (const ObjectPair& p : pairs) {
    Candidate c{p, &h.trees(instances[p.a].object, instances[p.b].object), poses[p.a].inverse() * poses[p.b]};
    auto [it, fresh] = truth.try_emplace({p.a, p.b}, false);
    if (fresh) it->second = c.trees->exact_collides(c.b_to_a);
    c.truth = it->second;
    out.push_back(c);
  }
  return out;
}

#ifdef BVHLAB_HAVE_FCL
/// FCL's side of a world, once per frame (its models are not one of the scene's hierarchies): its managers
/// on its own world boxes, timed as bvhlab's broad phases are (boxes, then update plus pair finding), and
/// its narrow phase on the dynamic tree's pairs, each pair timed alone as run_variant times bvhlab's. Rows
/// under the hierarchy kFclWorldHierarchy.
class FclSide {
 public:
  FclSide(const Scene& scene, Preparation& preparation)
      : scene_(scene), preparation_(preparation), world_(models(instance_objects(scene))) {}

  /// FCL's managers alone on scaling_world(count), timed as the hierarchies' scaling rows are (its boxes:
  /// setTransform and computeAABB; then registration in the first frame, update after, and the pairs).
  std::vector<ScalingRow> scaling(int count) {
    const ScalingWorld scaled = scaling_world(scene_, count);
    std::vector<ScalingRow> rows;
    for (std::size_t k = 0; k < FclWorld::kManagers.size(); ++k) {
      FclWorld world(models(scaled.objects));
      std::vector<double> boxes_micros, update_micros, candidates;
      for (const auto& poses : scaled.frames) {
        const auto start = Clock::now();
        world.place(poses);
        boxes_micros.push_back(micros_since(start));
        const auto begin = Clock::now();
        candidates.push_back(double(world.pairs(k).size()));
        update_micros.push_back(micros_since(begin));
      }
      rows.push_back({std::string(kFclWorldHierarchy), FclWorld::kManagers[k], world.size(),
                      static_cast<std::size_t>(report_tables::median(candidates)),
                      report_tables::median(boxes_micros), report_tables::median(update_micros)});
    }
    return rows;
  }

  void frame(int frame, std::span<const RigidTransform> poses,
             const std::map<std::pair<std::uint32_t, std::uint32_t>, bool>& truth, int warmup,
             WorldOutput& output) {
    const auto start = Clock::now();
    world_.place(poses);
    const double boxes_micros = micros_since(start);
    std::array<std::vector<ObjectPair>, FclWorld::kManagers.size()> pairs;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const auto begin = Clock::now();
      const std::vector<ObjectPair>& found = world_.pairs(k);
      const double update_micros = micros_since(begin);
      pairs[k] = found;
      std::sort(pairs[k].begin(), pairs[k].end());
      output.broad.push_back({frame, std::string(kFclWorldHierarchy), FclWorld::kManagers[k], world_.size(),
                              pairs[k].size(), boxes_micros, update_micros});
    }
    output.series.push_back(narrow_phase(frame, pairs[0], truth, warmup));
    check(frame, pairs, truth);
  }

 private:
  /// One model per object (FCL's OBBRSS, as the pair runner's fcl_obbrss), shared by its instances.
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> models(const std::vector<std::string>& objects) {
    std::vector<std::shared_ptr<fcl::CollisionGeometryd>> out;
    for (const std::string& object : objects) {
      auto& model = models_[object];
      if (!model) model = make_fcl_model<fcl::OBBRSSd>(preparation_.object(*scene_.object(object)).mesh);
      out.push_back(model);
    }
    return out;
  }

  static bool truth_of(const std::map<std::pair<std::uint32_t, std::uint32_t>, bool>& truth, ObjectPair p) {
    const auto it = truth.find({p.a, p.b});
    return it != truth.end() && it->second;  // not a candidate of bvhlab's: boxes apart
  }

  WorldSeriesRow narrow_phase(int frame, const std::vector<ObjectPair>& pairs,
                              const std::map<std::pair<std::uint32_t, std::uint32_t>, bool>& truth,
                              int warmup) {
    WorldSeriesRow row;
    row.frame = frame;
    row.hierarchy = kFclWorldHierarchy;
    row.series = "exact";
    row.exact_strategy = true;
    row.candidates = pairs.size();
    colliding_.clear();
    bool sink = false;
    for (const ObjectPair& p : pairs) {
      if (warmup > 0) sink ^= world_.collides(p);
      const auto start = Clock::now();
      const bool answer = world_.collides(p);
      row.micros += micros_since(start);
      const bool real = truth_of(truth, p);
      row.colliding += real;
      row.answered += answer;
      row.missed += real && !answer;
      row.false_pairs += !real && answer;
      if (answer) colliding_.push_back(p);
    }
    if (sink && pairs.empty()) std::cerr << ' ';  // keeps the warm-up
    return row;
  }

  /// FCL's colliding pairs (narrow phase on its dynamic tree's pairs) must be bvhlab's exact ones, and FCL's
  /// SaP must have found each of them too.
  void check(int frame, const std::array<std::vector<ObjectPair>, FclWorld::kManagers.size()>& pairs,
             const std::map<std::pair<std::uint32_t, std::uint32_t>, bool>& truth) const {
    std::vector<ObjectPair> ours;
    for (const auto& [key, collides] : truth)
      if (collides) ours.push_back({key.first, key.second});
    std::vector<ObjectPair> only_fcl, only_ours;
    std::set_difference(colliding_.begin(), colliding_.end(), ours.begin(), ours.end(),
                        std::back_inserter(only_fcl));
    std::set_difference(ours.begin(), ours.end(), colliding_.begin(), colliding_.end(),
                        std::back_inserter(only_ours));
    if (!only_fcl.empty())
      fail(frame, only_fcl.front(), "FCL answers colliding, bvhlab's exact answer apart");
    if (!only_ours.empty()) fail(frame, only_ours.front(), "bvhlab's exact answer is colliding, FCL's apart");
    for (const ObjectPair& p : ours)
      if (!std::binary_search(pairs[1].begin(), pairs[1].end(), p))
        fail(frame, p, "colliding, but not a pair of FCL's SaP manager");
  }

  [[noreturn]] void fail(int frame, ObjectPair p, const std::string& what) const {
    const auto& instances = scene_.world->instances;
    throw std::runtime_error("world " + scene_.name + ", frame " + std::to_string(frame) + ": instances " +
                             instances[p.a].name + " and " + instances[p.b].name + ": " + what);
  }

  const Scene& scene_;
  Preparation& preparation_;
  std::map<std::string, std::shared_ptr<fcl::CollisionGeometryd>> models_;  // by object; before world_
  FclWorld world_;
  std::vector<ObjectPair> colliding_;  ///< FCL's colliding pairs of the frame, sorted
};
#endif

}  // namespace

WorldOutput run_world(const Scene& scene, const RunOptions& options) {
  if (!scene.world) throw std::invalid_argument("scene " + scene.name + " has no \"world\"");
  WorldOutput output;
  output.scene = scene.name;
  output.instances = scene.world->instances.size();
  output.frames = scene.world->frames;
  const auto wall = Clock::now();
  LogFn log = options.log ? options.log : [](const std::string& m) { std::cerr << m << '\n'; };
  const RunPlan plan = plan_run(scene);
  Preparation preparation(options.cache_dir, output.stats, log, options.threads ? options.threads : 1);
  std::vector<std::unique_ptr<WorldHierarchy>> hierarchies;
  for (const PlannedHierarchy& planned : plan.hierarchies)
    hierarchies.push_back(std::make_unique<WorldHierarchy>(scene, planned, preparation));
#ifdef BVHLAB_HAVE_FCL
  FclSide fcl(scene, preparation);
#endif
  PairRows pair_rows{options.per_pose, &scene.world->instances, 0, {}, {}};
  output.per_pose = options.per_pose;
  for (int frame = 0; frame < scene.world->frames; ++frame) {
    const auto& poses = scene.world->poses[static_cast<std::size_t>(frame)];
    std::map<std::pair<std::uint32_t, std::uint32_t>, bool> truth;
    for (auto& h : hierarchies) {
      const std::vector<ObjectPair> pairs = h->candidates(frame, poses, output.broad);
      const std::vector<Candidate> candidates = with_truth(*h, scene, pairs, poses, truth);
      pair_rows.frame = frame;
      pair_rows.hierarchy = h->planned().hierarchy->name;
      std::vector<WorldSeriesRow> rows;
      for (const StrategyVariant& variant : h->planned().variants)
        rows.push_back(run_variant(variant, candidates, options.warmup_queries,
                                   h->coherent_states(variant.label()), pair_rows));
      for (WorldSeriesRow& row : run_frame_budgets(scene, h->planned(), candidates, options.warmup_queries,
                                                   h->memories(), pair_rows))
        rows.push_back(row);
      for (WorldSeriesRow& row : rows) {
        row.frame = frame;
        row.hierarchy = h->planned().hierarchy->name;
        output.series.push_back(std::move(row));
      }
    }
#ifdef BVHLAB_HAVE_FCL
    fcl.frame(frame, poses, truth, options.warmup_queries, output);
#endif
  }
  for (int count : scene.world->scaling) {
    log("broad phases alone at " + std::to_string(count) + " objects");
    for (auto& row : hierarchies.front()->scaling(count)) output.scaling.push_back(row);
#ifdef BVHLAB_HAVE_FCL
    for (auto& row : fcl.scaling(count)) output.scaling.push_back(row);
#endif
  }
  output.pairs = std::move(pair_rows.rows);
  output.advice = root_round_advice(output.series);
  for (const std::string& advice : output.advice) log("note: " + advice);
  output.models = preparation.models();
  output.stats.wall_seconds = std::chrono::duration<double>(Clock::now() - wall).count();
  return output;
}

}  // namespace bvhlab

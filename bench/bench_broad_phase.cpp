// The broad phase for many objects: bvhlab's sweep_and_prune and dynamic_aabb_tree against FCL 0.7's
// DynamicAABBTreeCollisionManager and SaPCollisionManager, in one process, on the same objects and motions.
//
//   bench_broad_phase [--frames=50] [--motion=fcl|local] [benchmark flags]
//
// Environments (bench/core/broad_phase_env.hpp, FCL's broad-phase test environment): fcl_n100 and fcl_n1000
// (FCL's n = 100 and 1000: 3n objects), and scale_100, scale_1000, scale_10000 (that many objects). Every
// environment's frames are computed once, before timing; a benchmark plays them forwards and backwards, so
// consecutive frames always differ by one step of the motion.
//
// Timed per frame (frame/<env>/<impl>):
//   bvhlab_sap, bvhlab_dat   world boxes of the objects' trees under the frame's poses (world_box.hpp),
//                            update(), pairs() (sorted, exactly the overlapping boxes)
//   fcl_dat, fcl_sap         setTransform + computeAABB per object, manager update(), collide() with a
//                            callback collecting the pairs it is called with (FCL's box-overlap candidates)
// register/<env>/<impl> times the first frame: registration plus the first pair query.
//
// Before timing, each environment is checked on its first frames: bvhlab's two broad phases must give
// identical pairs; FCL's candidates (boxes around FCL's bounding sphere of the mesh, looser under rotation)
// must contain bvhlab's, and the count of extra FCL candidates is printed; the exact narrow phase (bvhlab's
// `exact` strategy on bvhlab's pairs, fcl::collide on FCL's candidates) must find the same colliding pairs.
// A failed check ends the program with status 1. After the run, the medians (of --benchmark_repetitions)
// and the ratios bvhlab / FCL per environment are printed.
#include "bench/core/bench_flags.hpp"
#include "bench/core/broad_phase_env.hpp"
#include "traversal/broad_phase/dynamic_aabb_tree.hpp"
#include "traversal/broad_phase/sweep_and_prune.hpp"
#include "traversal/broad_phase/world_box.hpp"
#include "traversal/exact.hpp"
#include "volumes/aabb.hpp"

#include <benchmark/benchmark.h>
#ifdef BVHLAB_HAVE_FCL
#include "bench/core/fcl_model.hpp"

#include <fcl/broadphase/broadphase_SaP.h>
#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/narrowphase/collision.h>
#endif

#include <algorithm>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace bvhlab {
namespace {

using broad_phase_env::Environment;
using broad_phase_env::Motion;

struct Scene {
  std::string label;
  Environment env;
  std::vector<std::vector<RigidTransform>> frames;
  std::vector<Bvh<Aabb>> trees;    // one per shape
  std::vector<RootBounds> bounds;  // one per shape
#ifdef BVHLAB_HAVE_FCL
  std::vector<std::vector<fcl::Transform3d>> fcl_frames;
  std::vector<std::shared_ptr<fcl::CollisionGeometryd>> models;  // one per shape
#endif
};

// Frame k of a benchmark: forwards through the frames, then backwards, and so on.
std::size_t ping_pong(std::size_t k, std::size_t frames) {
  if (frames < 2) return 0;
  const std::size_t period = 2 * frames - 2, f = k % period;
  return f < frames ? f : period - f;
}

Scene make_scene(const std::string& label, std::size_t objects, std::size_t frames, Motion motion) {
  Scene s;
  s.label = label;
  s.env = broad_phase_env::make_environment(objects);
  s.frames = broad_phase_env::make_frames(s.env, frames, motion);
  for (const Mesh& mesh : s.env.shapes) {
    s.trees.push_back(Bvh<Aabb>::build(mesh));
    s.bounds.push_back(root_bounds(s.trees.back()));
  }
#ifdef BVHLAB_HAVE_FCL
  for (const auto& poses : s.frames) {
    std::vector<fcl::Transform3d> tfs;
    for (const RigidTransform& p : poses) {
      fcl::Transform3d tf = fcl::Transform3d::Identity();
      tf.linear() = p.rotation;
      tf.translation() = p.translation;
      tfs.push_back(tf);
    }
    s.fcl_frames.push_back(std::move(tfs));
  }
  for (const Mesh& mesh : s.env.shapes) {
    s.models.push_back(make_fcl_model<fcl::OBBRSSd>(mesh));
  }
#endif
  return s;
}

// --- bvhlab ---------------------------------------------------------------------------------------------

void world_boxes(const Scene& s, std::size_t frame, std::vector<Box>& boxes) {
  const auto& poses = s.frames[frame];
  boxes.resize(poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const std::uint32_t shape = s.env.shape_of[i];
    boxes[i] = world_box(s.trees[shape], poses[i], s.bounds[shape]);
  }
}

template <class Phase>
void bvhlab_frame(const Scene& s, std::size_t frame, Phase& phase, std::vector<Box>& boxes) {
  world_boxes(s, frame, boxes);
  phase.update(boxes);
}

std::set<ObjectPair> bvhlab_colliding(const Scene& s, std::size_t frame,
                                      const std::vector<ObjectPair>& pairs) {
  std::set<ObjectPair> out;
  const auto& poses = s.frames[frame];
  for (const ObjectPair& p : pairs) {
    const RigidTransform b_to_a = poses[p.a].inverse() * poses[p.b];
    if (query_exact(s.trees[s.env.shape_of[p.a]], s.trees[s.env.shape_of[p.b]], b_to_a).collides)
      out.insert(p);
  }
  return out;
}

// --- FCL ------------------------------------------------------------------------------------------------

#ifdef BVHLAB_HAVE_FCL
struct FclWorld {
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<fcl::CollisionObjectd*> pointers;
  std::unique_ptr<fcl::BroadPhaseCollisionManagerd> manager;
  std::vector<std::uintptr_t> ids;  // user data: the object's index
  std::vector<ObjectPair> candidates;
};

std::unique_ptr<FclWorld> fcl_world(const Scene& s, bool tree) {
  auto w = std::make_unique<FclWorld>();
  const auto& tfs = s.fcl_frames[0];
  for (std::size_t i = 0; i < tfs.size(); ++i) {
    w->objects.push_back(std::make_unique<fcl::CollisionObjectd>(s.models[s.env.shape_of[i]], tfs[i]));
    w->objects.back()->setUserData(reinterpret_cast<void*>(static_cast<std::uintptr_t>(i)));
    w->pointers.push_back(w->objects.back().get());
  }
  if (tree)
    w->manager = std::make_unique<fcl::DynamicAABBTreeCollisionManagerd>();
  else
    w->manager = std::make_unique<fcl::SaPCollisionManagerd>();
  return w;
}

std::uint32_t index_of(const fcl::CollisionObjectd* o) {
  return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(o->getUserData()));
}

bool collect(fcl::CollisionObjectd* a, fcl::CollisionObjectd* b, void* data) {
  static_cast<std::vector<ObjectPair>*>(data)->push_back(
      broad_phase_detail::ordered_pair(index_of(a), index_of(b)));
  return false;  // keep going
}

void fcl_move(const Scene& s, std::size_t frame, FclWorld& w) {
  const auto& tfs = s.fcl_frames[frame];
  for (std::size_t i = 0; i < tfs.size(); ++i) {
    w.objects[i]->setTransform(tfs[i]);
    w.objects[i]->computeAABB();
  }
}

void fcl_register(const Scene& s, FclWorld& w) {
  fcl_move(s, 0, w);
  w.manager->registerObjects(w.pointers);
  w.manager->setup();
  w.candidates.clear();
  w.manager->collide(&w.candidates, collect);
}

void fcl_frame(const Scene& s, std::size_t frame, FclWorld& w) {
  fcl_move(s, frame, w);
  w.manager->update();
  w.candidates.clear();
  w.manager->collide(&w.candidates, collect);
}

std::set<ObjectPair> fcl_colliding(const FclWorld& w, const std::vector<ObjectPair>& candidates) {
  std::set<ObjectPair> out;
  const fcl::CollisionRequestd request(1, false);
  for (const ObjectPair& p : candidates) {
    fcl::CollisionResultd result;
    fcl::collide(w.objects[p.a].get(), w.objects[p.b].get(), request, result);
    if (result.isCollision()) out.insert(p);
  }
  return out;
}
#endif

// --- the check before timing ----------------------------------------------------------------------------

std::size_t missing_from(const std::set<ObjectPair>& a, const std::set<ObjectPair>& b) {
  std::size_t n = 0;
  for (const ObjectPair& p : a) n += !b.count(p);
  return n;
}

// Runs the first frames through all four, prints what differs, returns false on a real disagreement.
bool check(const Scene& s, std::size_t frames) {
  SweepAndPrune sap;
  DynamicAabbTree dat;
  std::vector<Box> boxes;
  bool ok = true;
  std::size_t pairs = 0, colliding = 0;
#ifdef BVHLAB_HAVE_FCL
  auto fcl_tree = fcl_world(s, true), fcl_sap = fcl_world(s, false);
  std::size_t fcl_tree_pairs = 0, fcl_sap_pairs = 0, tree_vs_sap = 0, fcl_extra = 0;
#endif
  for (std::size_t f = 0; f < frames; ++f) {
    bvhlab_frame(s, f, sap, boxes);
    bvhlab_frame(s, f, dat, boxes);
    if (sap.pairs() != dat.pairs()) {
      std::printf("check %s frame %zu: sweep_and_prune and dynamic_aabb_tree disagree\n", s.label.c_str(), f);
      ok = false;
    }
    pairs += sap.pairs().size();
    const std::set<ObjectPair> ours(sap.pairs().begin(), sap.pairs().end());
    const std::set<ObjectPair> ours_colliding = bvhlab_colliding(s, f, sap.pairs());
    colliding += ours_colliding.size();
#ifdef BVHLAB_HAVE_FCL
    if (f == 0) {
      fcl_register(s, *fcl_tree);
      fcl_register(s, *fcl_sap);
    } else {
      fcl_frame(s, f, *fcl_tree);
      fcl_frame(s, f, *fcl_sap);
    }
    const std::set<ObjectPair> tree_set(fcl_tree->candidates.begin(), fcl_tree->candidates.end());
    const std::set<ObjectPair> sap_set(fcl_sap->candidates.begin(), fcl_sap->candidates.end());
    fcl_tree_pairs += tree_set.size();
    fcl_sap_pairs += sap_set.size();
    tree_vs_sap += missing_from(tree_set, sap_set) + missing_from(sap_set, tree_set);
    fcl_extra += missing_from(sap_set, ours);
    const std::size_t lost = missing_from(ours, sap_set) + missing_from(ours, tree_set);
    if (lost) {
      std::printf("check %s frame %zu: %zu of bvhlab's pairs are not FCL candidates\n", s.label.c_str(), f,
                  lost);
      ok = false;
    }
    for (const FclWorld* w : {fcl_tree.get(), fcl_sap.get()}) {
      const std::set<ObjectPair> theirs = fcl_colliding(*w, w->candidates);
      if (theirs == ours_colliding) continue;
      std::printf("check %s frame %zu: exact colliding pairs differ: %zu only bvhlab, %zu only FCL\n",
                  s.label.c_str(), f, missing_from(ours_colliding, theirs),
                  missing_from(theirs, ours_colliding));
      ok = false;
    }
#endif
  }
  std::printf(
      "check %-12s %zu objects, %zu frames: bvhlab %zu box pairs (both broad phases equal), %zu colliding",
      s.label.c_str(), s.env.poses.size(), frames, pairs, colliding);
#ifdef BVHLAB_HAVE_FCL
  std::printf(
      "; FCL candidates: dynamic tree %zu, SaP %zu (%zu differ between them), %zu beyond bvhlab's "
      "(FCL's looser boxes); exact colliding pairs %s",
      fcl_tree_pairs, fcl_sap_pairs, tree_vs_sap, fcl_extra, ok ? "equal" : "DIFFER");
#endif
  std::printf("\n");
  return ok;
}

// --- benchmarks -----------------------------------------------------------------------------------------

template <class Phase>
void register_bvhlab(const Scene& s, const std::string& impl) {
  benchmark::RegisterBenchmark(("frame/" + s.label + "/" + impl).c_str(), [&s](benchmark::State& state) {
    Phase phase;
    std::vector<Box> boxes;
    bvhlab_frame(s, 0, phase, boxes);
    std::size_t k = 0, pairs = 0;
    for (auto _ : state) {
      bvhlab_frame(s, ping_pong(++k, s.frames.size()), phase, boxes);
      pairs += phase.pairs().size();
    }
    state.counters["pairs"] = benchmark::Counter(double(pairs), benchmark::Counter::kAvgIterations);
  })->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(("register/" + s.label + "/" + impl).c_str(), [&s](benchmark::State& state) {
    std::vector<Box> boxes;
    for (auto _ : state) {
      Phase phase;
      bvhlab_frame(s, 0, phase, boxes);
      benchmark::DoNotOptimize(phase.pairs().data());
    }
  })->Unit(benchmark::kMicrosecond);
}

#ifdef BVHLAB_HAVE_FCL
void register_fcl(const Scene& s, const std::string& impl, bool tree) {
  benchmark::RegisterBenchmark(("frame/" + s.label + "/" + impl).c_str(), [&s,
                                                                           tree](benchmark::State& state) {
    auto w = fcl_world(s, tree);
    fcl_register(s, *w);
    std::size_t k = 0, pairs = 0;
    for (auto _ : state) {
      fcl_frame(s, ping_pong(++k, s.frames.size()), *w);
      pairs += w->candidates.size();
    }
    state.counters["pairs"] = benchmark::Counter(double(pairs), benchmark::Counter::kAvgIterations);
  })->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark(("register/" + s.label + "/" + impl).c_str(), [&s,
                                                                              tree](benchmark::State& state) {
    for (auto _ : state) {
      state.PauseTiming();
      auto w = fcl_world(s, tree);
      state.ResumeTiming();
      fcl_register(s, *w);
      benchmark::DoNotOptimize(w->candidates.data());
      state.PauseTiming();
      w.reset();
      state.ResumeTiming();
    }
  })->Unit(benchmark::kMicrosecond);
}
#endif

// Console output as usual, plus the medians (or the single runs) kept for the ratio table.
class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      const bool median = r.run_type == Run::RT_Aggregate && r.aggregate_name == "median";
      if (median || (r.run_type == Run::RT_Iteration && r.repetitions <= 1))
        times_[r.run_name.function_name] = r.GetAdjustedCPUTime();
    }
  }

  void print_ratios() const {
    std::map<std::string, std::map<std::string, double>> by_env;  // "frame/env" -> impl -> time
    for (const auto& [name, t] : times_) {
      const auto slash = name.rfind('/');
      by_env[name.substr(0, slash)][name.substr(slash + 1)] = t;
    }
    std::printf("\nMedian CPU time (us) and ratios bvhlab / FCL:\n");
    std::printf("%-26s %11s %11s %11s %11s %9s %9s %9s %9s\n", "", "bvhlab_sap", "bvhlab_dat", "fcl_dat",
                "fcl_sap", "sap/fdat", "dat/fdat", "sap/fsap", "dat/fsap");
    for (const auto& [env, impl_times] : by_env) {
      // A named reference: clang 14 cannot capture a structured binding.
      const std::map<std::string, double>& t = impl_times;
      auto get = [&](const char* k) { return t.count(k) ? t.at(k) : 0.0; };
      auto ratio = [](double a, double b) { return a > 0 && b > 0 ? a / b : 0.0; };
      const double bs = get("bvhlab_sap"), bd = get("bvhlab_dat"), fd = get("fcl_dat"), fs = get("fcl_sap");
      std::printf("%-26s %11.1f %11.1f %11.1f %11.1f %9.3f %9.3f %9.3f %9.3f\n", env.c_str(), bs, bd, fd, fs,
                  ratio(bs, fd), ratio(bd, fd), ratio(bs, fs), ratio(bd, fs));
    }
  }

 private:
  std::map<std::string, double> times_;
};

}  // namespace
}  // namespace bvhlab

int main(int argc, char** argv) {
  using namespace bvhlab;
  std::size_t frames = 50;
  std::string motion_name = "fcl";
  if (auto exit = initialize_benchmark(
          "bench_broad_phase",
          {{"frames", &frames, "frames per environment"},
           {"motion", &motion_name, "fcl (FCL's update motion) or local (turning in place)"}},
          argc, argv))
    return *exit;
  if (motion_name != "fcl" && motion_name != "local") {
    std::fprintf(stderr, "bench_broad_phase: --motion must be fcl or local, not '%s'\n", motion_name.c_str());
    return 2;
  }
  const Motion motion = motion_name == "fcl" ? Motion::Fcl : Motion::Local;
  if (frames < 2) {
    std::fprintf(stderr, "bench_broad_phase: --frames must be at least 2\n");
    return 2;
  }
  struct Spec {
    const char* label;
    std::size_t objects;
  };
  const Spec specs[] = {{"fcl_n100", 300},
                        {"fcl_n1000", 3000},
                        {"scale_100", 100},
                        {"scale_1000", 1000},
                        {"scale_10000", 10000}};
  static std::vector<Scene> scenes;  // benchmarks hold references: never resized after this
  scenes.reserve(std::size(specs));
  bool ok = true;
  for (const Spec& spec : specs) {
    scenes.push_back(make_scene(spec.label, spec.objects, frames, motion));
    ok = check(scenes.back(), std::min<std::size_t>(frames, 5)) && ok;
  }
  if (!ok) {
    std::fprintf(stderr, "bench_broad_phase: a check failed (see above); not timing\n");
    return 1;
  }
  for (const Scene& s : scenes) {
    register_bvhlab<SweepAndPrune>(s, "bvhlab_sap");
    register_bvhlab<DynamicAabbTree>(s, "bvhlab_dat");
#ifdef BVHLAB_HAVE_FCL
    register_fcl(s, "fcl_dat", true);
    register_fcl(s, "fcl_sap", false);
#endif
  }
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  reporter.print_ratios();
  benchmark::Shutdown();
  return 0;
}

#include "bench/pairs/measure.hpp"

#include "bench/core/ground_truth.hpp"
#include "engine/policies.hpp"
#include "engine/tree_cache.hpp"
#include "traversal/coherent_state.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <numeric>
#include <thread>

namespace bvhlab {
namespace {

/// Poses per block of the interleaved timing loop (see Measurement::time_group).
constexpr std::size_t kPoseBlock = 50;

/// Reads a ground-truth file's fields in order; throws on a short file.
struct Reader {
  std::span<const std::byte> bytes;
  std::size_t position = 0;
  std::string_view take(std::size_t n) {
    if (bytes.size() - position < n) throw std::runtime_error("truncated");
    std::string_view out(reinterpret_cast<const char*>(bytes.data()) + position, n);
    position += n;
    return out;
  }
  std::uint64_t u64() {
    const std::string_view raw = take(8);
    std::uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(raw[static_cast<std::size_t>(i)]);
    return v;
  }
};

/// Context switches forced on this thread so far (another process took its core).
long involuntary_switches() {
  rusage usage{};
  getrusage(RUSAGE_THREAD, &usage);
  return usage.ru_nivcsw;
}

Truth exact_truth(const WorkloadSpec& workload, const PreparedHierarchy& exact, unsigned threads) {
  Truth truth(workload.groups.size());
  for (std::size_t g = 0; g < workload.groups.size(); ++g) {
    const auto& poses = workload.groups[g].poses;
    truth[g].assign(poses.size(), 0);
    const unsigned workers =
        std::max(1u, std::min<unsigned>(threads, static_cast<unsigned>(poses.size() / 64 + 1)));
    std::vector<std::thread> pool;
    for (unsigned w = 0; w < workers; ++w)
      pool.emplace_back([&, w] {
        for (std::size_t i = w; i < poses.size(); i += workers) truth[g][i] = exact.exact_collides(poses[i]);
      });
    for (auto& t : pool) t.join();
  }
  return truth;
}

}  // namespace

std::vector<PoseAnswer> answer_prepared(const PreparedQuery& query, std::span<const RigidTransform> poses,
                                        int repeat) {
  const double overhead = repeat > 0 ? clock_overhead_us() : 0;
  CoherentState state;  // a coherent query's first answers: each pose starts where the previous one ended
  const auto first = [&](const RigidTransform& pose) {
    Result result;
    const ResultSink sink = [&](std::size_t, const Result& r) { result = r; };
    if (query.coherent())
      query.run(std::span(&pose, 1), sink, state);
    else
      query.run(std::span(&pose, 1), sink);
    return result;
  };
  return answer_poses(poses, repeat, overhead, first,
                      [&](std::span<const RigidTransform> all, std::vector<QueryRecord>& records) {
                        query.time(all, 0, records);
                      });
}

double clock_overhead_us() {
  std::vector<double> samples(20001);
  for (double& sample : samples) {
    const auto start = Clock::now();
    const auto stop = Clock::now();
    sample = std::chrono::duration<double, std::micro>(stop - start).count();
  }
  std::nth_element(samples.begin(), samples.begin() + samples.size() / 2, samples.end());
  return samples[samples.size() / 2];
}

// ---------------------------------------------------------------------------------------------------------
// Ground truth on disk.

std::vector<std::byte> KeyedFileCache::read(const std::filesystem::path& file, const std::string& key) {
  std::vector<std::byte> bytes = tree_cache_detail::read_file_bytes(file);
  Reader in{bytes};
  if (in.u64() != ContentHash().update(key).digest()) throw std::runtime_error("stale: made for another key");
  return bytes;
}

void KeyedFileCache::store(const std::string& key, std::span<const std::byte> payload,
                           const LogFn& log) const {
  if (dir_.empty()) return;
  std::vector<std::byte> out;
  const std::uint64_t digest = ContentHash().update(key).digest();
  for (std::size_t i = 0; i < kKeyBytes; ++i)
    out.push_back(static_cast<std::byte>((digest >> (8 * i)) & 0xff));
  out.insert(out.end(), payload.begin(), payload.end());
  try {
    tree_cache_detail::write_file_bytes(file_of(key), out);
  } catch (const std::exception& e) {
    log(what_ + " cache: could not store (" + e.what() + ")");
  }
}

std::filesystem::path KeyedFileCache::file_of(const std::string& key) const {
  return dir_ / (ContentHash().update(key).hex() + extension_);
}

namespace {

// Ground truth payload: "BVHLGT02", the group count, per group its pose count and one bit per pose, then a
// checksum of all before it.
std::vector<std::byte> encode_truth(const Truth& truth) {
  std::string out = "BVHLGT02";
  auto put = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xff));
  };
  put(truth.size());
  for (const auto& group : truth) {
    put(group.size());
    std::string bits((group.size() + 7) / 8, '\0');
    for (std::size_t i = 0; i < group.size(); ++i)
      if (group[i]) bits[i / 8] = static_cast<char>(bits[i / 8] | (1 << (i % 8)));
    out += bits;
  }
  put(hash_bytes(std::as_bytes(std::span(out.data(), out.size()))));
  const auto bytes = std::as_bytes(std::span(out.data(), out.size()));
  return {bytes.begin(), bytes.end()};
}

// Throws naming what is wrong: not a truth payload, made for another workload, corrupt.
Truth decode_truth(std::span<const std::byte> bytes, const WorkloadSpec& workload) {
  Reader in{bytes};
  if (in.take(8) != std::string_view("BVHLGT02")) throw std::runtime_error("not a ground-truth file");
  const std::uint64_t groups = in.u64();
  if (groups != workload.groups.size()) throw std::runtime_error("stale: wrong number of pose groups");
  Truth truth(groups);
  for (std::size_t g = 0; g < groups; ++g) {
    const std::uint64_t n = in.u64();
    if (n != workload.groups[g].poses.size()) throw std::runtime_error("stale: wrong number of poses");
    const std::string_view bits = in.take((n + 7) / 8);
    truth[g].resize(n);
    for (std::size_t i = 0; i < n; ++i)
      truth[g][i] = (static_cast<unsigned char>(bits[i / 8]) >> (i % 8)) & 1;
  }
  const std::size_t body = in.position;
  if (in.u64() != hash_bytes(bytes.first(body))) throw std::runtime_error("checksum mismatch");
  if (in.position != bytes.size()) throw std::runtime_error("trailing bytes");
  return truth;
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------
// Progress.

Progress::Progress(bool enabled, std::size_t total)
    : enabled_(enabled && total > 0), total_(total), tty_(isatty(2)) {}

void Progress::advance(std::size_t done, const std::string& label) {
  if (!enabled_) return;
  done_ += done;
  const double fraction = std::min(1.0, double(done_) / double(total_));
  if (tty_) {
    const auto now = Clock::now();
    if (done_ < total_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const int width = 30, filled = static_cast<int>(fraction * width);
    std::fprintf(stderr, "\r[%s%s] %3d%%  %-48.48s", std::string(filled, '#').c_str(),
                 std::string(width - filled, '.').c_str(), static_cast<int>(fraction * 100), label.c_str());
    if (done_ >= total_) std::fputc('\n', stderr);
  } else {
    const int tenth = static_cast<int>(fraction * 10);
    if (tenth > printed_tenth_) {
      printed_tenth_ = tenth;
      std::fprintf(stderr, "  %3d%% of the queries done (%s)\n", tenth * 10, label.c_str());
    }
  }
  std::fflush(stderr);
}

// ---------------------------------------------------------------------------------------------------------
// The stage.

Measurement::Measurement(const Scene& scene, const RunPlan& plan, const RunOptions& options, RunStats& stats,
                         LogFn log, unsigned threads)
    : scene_(scene),
      plan_(plan),
      stats_(stats),
      log_(std::move(log)),
      threads_(threads),
      warmup_(options.warmup_queries),
      truth_cache_(options.cache_dir.empty() ? options.cache_dir : options.cache_dir / "truth", ".truth",
                   "truth"),
      calibration_cache_(options.cache_dir.empty() ? options.cache_dir : options.cache_dir / "calibration",
                         ".calib", "calibration"),
      progress_(options.progress,
                plan.total_queries * static_cast<std::size_t>(std::max(1, scene.timing.repeats))) {
  stats_.timing_repeats = scene.timing.repeats;
  stats_.timing_statistic = statistic_name(scene.timing.statistic);
}

Truth Measurement::ground_truth(const PreparedPair& pair, Preparation& preparation) {
  const auto truth_start = Clock::now();
  Truth truth = cached_truth(pair, preparation, scene_.workload);
  cross_check(pair, truth);
  stats_.truth_seconds += seconds_since(truth_start);
  return truth;
}

Truth Measurement::cached_truth(const PreparedPair& pair, Preparation& preparation,
                                const WorkloadSpec& workload) {
  const std::string truth_key = "truth v1|A=" + pair.a->key + "|B=" + pair.b->key + "|" + workload.identity;
  std::string why;
  std::optional<Truth> truth = truth_cache_.load(
      truth_key, &why, [&](std::span<const std::byte> payload) { return decode_truth(payload, workload); });
  if (truth) {
    ++stats_.truth_cache_hits;
    return std::move(*truth);
  }
  if (!why.empty()) {
    ++stats_.truth_cache_rejected;
    log_("truth cache: rejected " + why + "; recomputing");
  }
  truth = compute_truth(pair, preparation, workload);
  ++stats_.truth_computed;
  truth_cache_.store(truth_key, encode_truth(*truth), log_);
  return std::move(*truth);
}

Truth Measurement::compute_truth(const PreparedPair& pair, Preparation& preparation,
                                 const WorkloadSpec& workload) {
  const PreparedHierarchy* exact = nullptr;
  for (std::size_t i = 0; i < plan_.hierarchies.size() && !exact; ++i)
    if (!plan_.hierarchies[i].hierarchy->is_fcl()) exact = pair.hierarchies[i].get();
  std::unique_ptr<PreparedHierarchy> fallback;
  if (!exact) {  // an FCL-only scene: the truth still comes from bvhlab's exact traversal
    fallback = preparation.plain_aabb(*pair.a, *pair.b);
    exact = fallback.get();
  }
  log_("computing the ground truth of " + pair.label +
       (&workload == &scene_.workload ? "" : "'s training poses") + " (exact traversal)");
  return exact_truth(workload, *exact, threads_);
}

// Against CGAL on poses spread evenly over the whole workload.
void Measurement::cross_check(const PreparedPair& pair, const Truth& truth) {
  const WorkloadSpec& workload = scene_.workload;
  std::size_t total_poses = 0;
  for (const auto& group : workload.groups) total_poses += group.poses.size();
  const std::size_t sample =
      std::min<std::size_t>(static_cast<std::size_t>(scene_.report.cgal_sample), total_poses);
  if (sample == 0) return;
  const CgalGroundTruth cgal(pair.a->mesh, pair.b->mesh);
  for (std::size_t k = 0; k < sample; ++k) {
    std::size_t index = (2 * k + 1) * total_poses / (2 * sample);
    std::size_t g = 0;
    while (index >= workload.groups[g].poses.size()) index -= workload.groups[g++].poses.size();
    const bool expected = truth[g][index];
    if (cgal.collides(workload.groups[g].poses[index]) != expected) {
      ++stats_.cgal_mismatches;
      log_("ground truth: CGAL disagrees on " + pair.label + " at distance " +
           g17(workload.groups[g].distance) + ", pose " + std::to_string(index) + " (truth says " +
           (expected ? "collision" : "none") + ")");
    }
    ++stats_.cgal_checked;
  }
}

// Every hierarchy and strategy on the same poses, in `repeats` passes over the whole workload. Within a
// pass the poses run in blocks, each block through every series in turn (in a new order each block), so a
// slow spell of a shared machine (another process, frequency changes) spreads over all series
// instead of landing on one, and within a block the caches stay warm. A pose comes back only a whole pass
// later: its samples are far apart in time, so a slow spell shorter than a pass spoils at most one of them,
// and the branch predictor cannot learn the pose. Each (series, pose) keeps the query of its representative
// sample (the median or the minimum of its passes): its time and its answer come from the same query.
std::vector<PairRecords> Measurement::time_workload(const std::vector<PreparedPair>& pairs) {
  const std::size_t repeats = static_cast<std::size_t>(std::max(1, scene_.timing.repeats));
  const std::size_t groups = scene_.workload.groups.size();
  // passes[pair][group][series][pass]: the group's records of one series in one pass.
  std::vector<std::vector<std::vector<std::vector<std::vector<QueryRecord>>>>> passes(pairs.size());
  const long switches_before = involuntary_switches();
  for (std::size_t pass = 0; pass < repeats; ++pass)
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      passes[p].resize(groups);
      for (std::size_t g = 0; g < groups; ++g) {
        std::vector<std::vector<QueryRecord>> series;
        time_pass(pairs[p], g, series);
        passes[p][g].resize(series.size());
        for (std::size_t s = 0; s < series.size(); ++s) passes[p][g][s].push_back(std::move(series[s]));
      }
    }
  stats_.involuntary_switches += involuntary_switches() - switches_before;
  std::vector<PairRecords> out(pairs.size(), PairRecords(groups));
  for (std::size_t p = 0; p < pairs.size(); ++p)
    for (std::size_t g = 0; g < groups; ++g) {
      std::size_t s = 0;
      out[p][g].resize(plan_.hierarchies.size());
      for (std::size_t i = 0; i < plan_.hierarchies.size(); ++i)
        for (std::size_t v = 0; v < plan_.hierarchies[i].variants.size(); ++v, ++s)
          out[p][g][i].push_back(representatives(passes[p][g][s]));
      passes[p][g].clear();
    }
  stats_.timed_samples = disturbance_.samples;
  stats_.stalled_samples = disturbance_.stalled;
  stats_.sampled_seconds = disturbance_.timed_us * 1e-6;
  stats_.stall_lost_seconds = disturbance_.lost_us * 1e-6;
  return out;
}

void Measurement::time_pass(const PreparedPair& pair, std::size_t g,
                            std::vector<std::vector<QueryRecord>>& series) {
  const PoseGroup& group = scene_.workload.groups[g];
  const auto& planned = plan_.hierarchies;
  std::vector<std::pair<std::size_t, std::size_t>> flat;  // (hierarchy, variant) by flat series index
  for (std::size_t i = 0; i < planned.size(); ++i)
    for (std::size_t v = 0; v < planned[i].variants.size(); ++v) flat.emplace_back(i, v);
  series.resize(flat.size());
  std::vector<std::size_t> order(flat.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const std::span<const RigidTransform> poses(group.poses);
  std::vector<QueryRecord> block_records;
  for (std::size_t begin = 0; begin < poses.size(); begin += kPoseBlock) {
    const auto block = poses.subspan(begin, std::min(kPoseBlock, poses.size() - begin));
    // Each block runs the series in a new order (seeded: a run repeats its orders), so no series always
    // follows the same one and finds the caches as that neighbour left them.
    std::shuffle(order.begin(), order.end(), block_order_);
    for (const std::size_t s : order) {
      const auto [i, v] = flat[s];
      pair.hierarchies[i]->run(planned[i].variants[v], block, warmup_, block_records);
      series[s].insert(series[s].end(), block_records.begin(), block_records.end());
    }
    char distance[16];
    std::snprintf(distance, sizeof distance, "%g", group.distance);
    progress_.advance(flat.size() * block.size(), pair.label + " d=" + distance);
  }
}

std::vector<QueryRecord> Measurement::representatives(const std::vector<std::vector<QueryRecord>>& passes) {
  std::vector<QueryRecord> out;
  std::vector<double> samples(passes.size());
  for (std::size_t k = 0; k < passes.front().size(); ++k) {
    for (std::size_t pass = 0; pass < passes.size(); ++pass) samples[pass] = passes[pass][k].micros;
    out.push_back(passes[representative_sample(samples, scene_.timing.statistic)][k]);
    disturbance_.add(samples);
  }
  return out;
}

SeriesMaps Measurement::calibration_maps(const PreparedPair& pair, Preparation& preparation) {
  const auto& planned = plan_.hierarchies;
  SeriesMaps maps(planned.size());
  for (std::size_t i = 0; i < planned.size(); ++i) maps[i].resize(planned[i].variants.size());
  if (!scene_.calibration) return maps;
  const WorkloadSpec& training = scene_.calibration->training;
  std::optional<Truth> truth;  // computed only when some map is not cached
  std::vector<QueryRecord> records;
  for (std::size_t i = 0; i < planned.size(); ++i) {
    const HierarchySpec& h = *planned[i].hierarchy;
    for (std::size_t v = 0; v < planned[i].variants.size(); ++v) {
      const StrategyVariant& variant = planned[i].variants[v];
      if (strategy_info(variant.strategy).exact) continue;
      const std::string key = "calibration v1|A=" + pair.a->key + "|B=" + pair.b->key +
                              "|hierarchy=" + h.name + "|bv=" + h.bv +
                              "|split=" + std::string(to_string(h.build.split)) +
                              "|leaf=" + std::to_string(h.build.max_leaf_triangles) +
                              "|annotation=" + pair.hierarchies[i]->model.annotation +
                              "|series=" + variant.label() + "|" + training.identity;
      std::string why;
      if ((maps[i][v] = calibration_cache_.load(key, &why, [](std::span<const std::byte> payload) {
            return CalibrationMap::decode(payload, "map");
          }))) {
        ++stats_.calibration_cache_hits;
        continue;
      }
      if (!why.empty()) log_("calibration cache: rejected " + why + "; fitting again");
      if (!truth) truth = cached_truth(pair, preparation, training);
      std::vector<CalibrationSample> samples;
      for (std::size_t g = 0; g < training.groups.size(); ++g) {
        pair.hierarchies[i]->run(variant, training.groups[g].poses, 0, records);
        for (std::size_t k = 0; k < records.size(); ++k)
          samples.push_back({std::clamp(records[k].probability, 0.0, 1.0), (*truth)[g][k] != 0});
      }
      maps[i][v] = CalibrationMap::fit(samples);
      ++stats_.calibration_fitted;
      calibration_cache_.store(key, maps[i][v]->encode(), log_);
    }
  }
  return maps;
}

}  // namespace bvhlab

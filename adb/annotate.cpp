// ADB density annotation, the counting: per node, per cell, over threads, with the run's statistics. The
// areas come from annotate_area.cpp, the exact decisions of ties from annotate_exact.cpp. See
// adb/annotate.hpp for the definitions and the exactness argument.
#include "adb/annotate.hpp"
#include "adb/annotate_internal.hpp"
#include "adb/pair_geometry.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <string>
#include <thread>

namespace bvhlab {
namespace {

using namespace annotate_detail;

constexpr double kUnitRoundoff = std::numeric_limits<double>::epsilon() / 2;

struct CellSum {
  double lo = 0;
  double hi = 0;
  std::uint32_t terms = 0;
};

/// Certified bounds of a sum of nonnegative terms accumulated in round-to-nearest: |fl(S) - S| <= gamma S
/// with gamma = (n - 1) u / (1 - (n - 1) u) <= 2 n u; widened generously, then one more ulp for the product.
Bounds certified(const CellSum& s) {
  const double gamma = 4.0 * (static_cast<double>(s.terms) + 1.0) * kUnitRoundoff;
  const double lo = std::nextafter(std::nextafter(s.lo * (1.0 - gamma), 0.0), 0.0);
  const double hi = std::nextafter(std::nextafter(s.hi * (1.0 + gamma), INFINITY), INFINITY);
  return {std::max(0.0, lo), hi};
}

struct ThreadStats {
  std::size_t fast = 0, clipped = 0, clip_calls = 0, skipped_clips = 0, derived_areas = 0, degenerate = 0,
              exact_cells = 0;
};

struct Worker {
  ThreadStats stats;
  std::vector<std::uint32_t> pending;  ///< scratch: the current node's triangles that need clipping
  std::vector<TrianglePoints> local;   ///< scratch: the current node's triangles in its own frame
  std::vector<TriangleInfo> infos;     ///< scratch: their infos
};

struct Job {
  std::span<const Box> boxes;
  std::span<const std::pair<std::uint32_t, std::uint32_t>> ranges;
  std::span<const TrianglePoints> triangles;
  std::span<const TriangleInfo> infos;
  int g = 2;
  double tau = kDefaultAdbTau;
};

struct FrameJob {
  std::span<const OrientedBox> frames;
  std::span<const std::pair<std::uint32_t, std::uint32_t>> ranges;
  std::span<const TrianglePoints> triangles;
  int g = 2;
  double tau = kDefaultAdbTau;
};

template <class F>
void for_each_candidate_cell(const Placement& p, F&& f) {
  for (int i = p.candidate[0].first; i <= p.candidate[0].last; ++i)
    for (int j = p.candidate[1].first; j <= p.candidate[1].last; ++j)
      for (int k = p.candidate[2].first; k <= p.candidate[2].last; ++k) f(std::array<int, 3>{i, j, k});
}

/// What is known about one cell of the node being counted.
struct CellState {
  enum class Decision : std::uint8_t { Open, Counts, DoesNotCount };
  CellSum known;             ///< areas of fast-path triangles and of clipped pieces so far
  double pending = 0;        ///< sum of the area upper bounds of candidate triangles not clipped yet
  double pending_total = 0;  ///< that sum before any was clipped (scales its rounding error)
  std::uint32_t pending_count = 0;
  std::uint32_t pending_ops = 0;  ///< additions and subtractions applied to `pending`
  Decision decision = Decision::Open;

  /// Decides the cell when the bounds allow: counted once its certain area reaches the threshold, not
  /// counted once even the largest possible area (known + every pending triangle in full) stays below it.
  void decide(const Bounds& threshold) {
    const Bounds area = certified(known);
    if (area.lo > 0 && area.lo >= threshold.hi) {
      decision = Decision::Counts;
      return;
    }
    double upper = area.hi;
    if (pending_count > 0) {
      // `pending` went through pending_ops roundings of magnitude at most u * pending_total each.
      const double slack = 4.0 * (pending_ops + 2.0) * kUnitRoundoff * pending_total;
      upper = std::nextafter(upper + std::max(0.0, pending) + slack, INFINITY);
    }
    if (upper <= 0 || upper < threshold.lo) decision = Decision::DoesNotCount;
  }
};

void check_grid_box(const Box& box, std::uint32_t node) {
  if (box.empty() || !box.min.allFinite() || !box.max.allFinite() || !(box.max - box.min).allFinite())
    throw std::invalid_argument("annotate: node " + std::to_string(node) +
                                " has an empty or non-finite bounding box but holds triangles");
}

/// The cells of the node being counted, by grid coordinates.
struct NodeCells {
  int g;
  std::array<CellState, kMaxGrid * kMaxGrid * kMaxGrid> cells{};

  CellState& operator[](const std::array<int, 3>& c) { return cells[(c[0] * g + c[1]) * g + c[2]]; }
  const CellState& operator[](const std::array<int, 3>& c) const {
    return cells[(c[0] * g + c[1]) * g + c[2]];
  }
};

/// The area a cell needs to count, tau times a cell's mean face area, as certified bounds.
Bounds count_threshold(const Box& box, int g, double tau) {
  CGAL::Protect_FPU_rounding<true> guard;
  Interval a[3];
  for (int k = 0; k < 3; ++k) a[k] = (Interval(box.max[k]) - Interval(box.min[k])) / Interval(g);
  const Interval t = Interval(tau) * (a[0] * a[1] + a[1] * a[2] + a[2] * a[0]) / Interval(3);
  return to_bounds(t);
}

/// The first pass over the node's triangles: a fast-path triangle (inside one cell per axis) adds its area
/// to its cells; any other is queued in worker.pending and adds its area bound to its cells' pending sums.
/// Then every cell with a candidate is decided where the bounds already allow.
void place_triangles(const Grid& grid, std::span<const TriangleInfo> infos, const Bounds& threshold,
                     NodeCells& cells, Worker& worker) {
  ThreadStats& stats = worker.stats;
  std::vector<std::uint32_t>& pending = worker.pending;
  pending.clear();
  const std::uint32_t end = static_cast<std::uint32_t>(infos.size());
  for (std::uint32_t t = 0; t < end; ++t) {
    const TriangleInfo& info = infos[t];
    if (info.degenerate) {
      ++stats.degenerate;
      continue;
    }
    const Placement p = place(grid, info);
    if (p.outside) continue;
    if (p.inside_cell) {
      ++stats.fast;
      for_each_candidate_cell(p, [&](const std::array<int, 3>& c) {
        CellSum& s = cells[c].known;
        s.lo += info.area.lo;
        s.hi += info.area.hi;
        ++s.terms;
      });
    } else {
      ++stats.clipped;
      pending.push_back(t);
      for_each_candidate_cell(p, [&](const std::array<int, 3>& c) {
        CellState& cell = cells[c];
        cell.pending += info.area.hi;
        ++cell.pending_count;
        ++cell.pending_ops;
      });
    }
  }
  for (CellState& cell : cells.cells) {
    cell.pending_total = cell.pending;
    if (cell.known.terms + cell.pending_count > 0) cell.decide(threshold);
  }
}

/// The second pass: clips each queued triangle against its candidate cells that are still open.
///
/// The candidate cells of a clipped triangle partition it (they overlap in cell planes only, which a
/// triangle spanning a positive extent across them meets in segments), unless an axis has two containing
/// cells (the triangle lies in their shared plane). So when every candidate is still open, the last one's
/// area is the triangle's minus the others': one clip fewer per triangle.
void clip_pending(const Grid& grid, std::span<const TrianglePoints> triangles,
                  std::span<const TriangleInfo> infos, const Bounds& threshold, NodeCells& cells,
                  Worker& worker) {
  ThreadStats& stats = worker.stats;
  std::vector<std::array<int, 3>> candidates;
  for (const std::uint32_t t : worker.pending) {
    const TriangleInfo& info = infos[t];
    const Placement p = place(grid, info);
    candidates.clear();
    bool all_open = true;
    for_each_candidate_cell(p, [&](const std::array<int, 3>& c) {
      candidates.push_back(c);
      all_open = all_open && cells[c].decision == CellState::Decision::Open;
    });
    bool partition = all_open && candidates.size() >= 2;
    for (int a = 0; a < 3; ++a)
      partition = partition && (!p.contained[a] || p.candidate[a].first == p.candidate[a].last);
    std::array<ClipBox, kMaxGrid * kMaxGrid * kMaxGrid> boxes;
    std::array<bool, kMaxGrid * kMaxGrid * kMaxGrid> has_area{};
    std::size_t derived = candidates.size();  // the candidate whose area is derived, if any
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      has_area[k] = make_clip_box(grid, info, p, candidates[k], boxes[k]);
      if (partition && has_area[k]) derived = k;
    }
    Interval rest(info.area.lo, info.area.hi);
    auto add = [&](CellState& cell, const Bounds& area) {
      if (area.hi > 0) {
        cell.known.lo += area.lo;
        cell.known.hi += area.hi;
        ++cell.known.terms;
      }
      cell.pending -= info.area.hi;
      --cell.pending_count;
      ++cell.pending_ops;
      cell.decide(threshold);
    };
    for (std::size_t k = 0; k < candidates.size(); ++k) {
      CellState& cell = cells[candidates[k]];
      if (cell.decision != CellState::Decision::Open) {
        ++stats.skipped_clips;
        continue;
      }
      if (k == derived) continue;
      Bounds area;
      if (has_area[k]) {
        ++stats.clip_calls;
        area = clipped_area_bounds(triangles[t], boxes[k]);
        if (derived < candidates.size()) {
          CGAL::Protect_FPU_rounding<true> guard;
          rest -= Interval(area.lo, area.hi);
        }
      }
      add(cell, area);
    }
    if (derived < candidates.size()) {
      ++stats.derived_areas;
      add(cells[candidates[derived]], to_bounds(rest));
    }
  }
}

/// pc: the cells that count; a cell the bounds left open is decided exactly.
int tally_cells(const Grid& grid, const Box& box, double tau, std::span<const TrianglePoints> triangles,
                std::span<const TriangleInfo> infos, const NodeCells& cells, ThreadStats& stats) {
  const int g = cells.g;
  int count = 0;
  for (int i = 0; i < g; ++i)
    for (int j = 0; j < g; ++j)
      for (int k = 0; k < g; ++k) {
        const std::array<int, 3> c{i, j, k};
        const CellState& cell = cells[c];
        if (cell.known.terms + cell.pending_count == 0) continue;
        switch (cell.decision) {
          case CellState::Decision::Counts:
            ++count;
            break;
          case CellState::Decision::DoesNotCount:
            break;
          case CellState::Decision::Open:  // a tie or a near-tie: decide exactly
            ++stats.exact_cells;
            if (cell_counts_exactly(grid, c, box, tau, triangles, infos)) ++count;
            break;
        }
      }
  return count;
}

/// pc of one node: its grid box and its triangles with their infos. Fast-path triangles first; then a
/// clipped triangle is clipped only against candidate cells the bounds have not decided yet (most cells of a
/// large node are decided by their fast-path area).
std::uint8_t count_cells(const Box& box, std::span<const TrianglePoints> triangles,
                         std::span<const TriangleInfo> infos, int g, double tau, Worker& worker) {
  const Grid grid(box, g);
  const Bounds threshold = count_threshold(box, g, tau);
  NodeCells cells{g};
  place_triangles(grid, infos, threshold, cells, worker);
  clip_pending(grid, triangles, infos, threshold, cells, worker);
  return static_cast<std::uint8_t>(tally_cells(grid, box, tau, triangles, infos, cells, worker.stats));
}

/// pc of node `node` on its bounding box (the triangles and infos shared by all nodes).
std::uint8_t count_node(const Job& job, std::uint32_t node, Worker& worker) {
  const auto [begin, end] = job.ranges[node];
  if (begin == end) return 0;
  check_grid_box(job.boxes[node], node);
  return count_cells(job.boxes[node], job.triangles.subspan(begin, end - begin),
                     job.infos.subspan(begin, end - begin), job.g, job.tau, worker);
}

/// pc of node `node` in its own frame: its triangles mapped into the frame (rounded to doubles), counted on
/// the frame's box grown to hold them; an axis thinner than kMinRelativeThickness of the longest is
/// flattened to the plane 0, the flat box the query thickens (adb/pair_geometry.hpp).
std::uint8_t count_node_in_frame(const FrameJob& job, std::uint32_t node, Worker& worker) {
  const auto [begin, end] = job.ranges[node];
  if (begin == end) return 0;
  const OrientedBox& frame = job.frames[node];
  Box box;
  if (!frame.empty()) box = {-frame.half, frame.half};
  worker.local.clear();
  for (std::uint32_t t = begin; t < end; ++t) {
    const TrianglePoints& world = job.triangles[t];
    TrianglePoints local;
    for (int k = 0; k < 3; ++k) {
      local[k] = frame.local(world[k]);
      if (!local[k].allFinite())  // a corrupt frame; Box::extend would skip a NaN silently
        throw std::invalid_argument("annotate: node " + std::to_string(node) +
                                    " has a non-finite frame but holds triangles");
      box.extend(local[k]);
    }
    worker.local.push_back(local);
  }
  check_grid_box(box, node);
  flatten_thin_axes(box, [&](auto&& set) {
    for (TrianglePoints& t : worker.local)
      for (Vec3& v : t) set(v);
  });
  worker.infos.clear();
  for (const TrianglePoints& t : worker.local) worker.infos.push_back(make_info(t));
  return count_cells(box, worker.local, worker.infos, job.g, job.tau, worker);
}

}  // namespace

namespace {

/// Checks the arguments every node shares; returns the number of (triangle, node) pairs.
std::size_t check_arguments(std::size_t node_count,
                            std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                            std::span<const TrianglePoints> triangles, int grid,
                            const AnnotateOptions& options) {
  if (grid < 1 || grid > kMaxGrid)
    throw std::invalid_argument("annotate: grid must be 1..6 cells per axis, got " + std::to_string(grid));
  if (!std::isfinite(options.tau) || !(options.tau >= 0))  // tau = 0: every cell with some area counts
    throw std::invalid_argument("annotate: tau must be finite and >= 0, got " + std::to_string(options.tau));
  if (node_count != node_ranges.size())
    throw std::invalid_argument("annotate: " + std::to_string(node_count) + " node boxes but " +
                                std::to_string(node_ranges.size()) + " node ranges");
  std::size_t total_pairs = 0;
  for (std::size_t i = 0; i < node_ranges.size(); ++i) {
    const auto [b, e] = node_ranges[i];
    if (b > e || e > triangles.size())
      throw std::invalid_argument("annotate: node " + std::to_string(i) + " has triangle range [" +
                                  std::to_string(b) + ", " + std::to_string(e) + ") outside the " +
                                  std::to_string(triangles.size()) + " triangles");
    total_pairs += e - b;
  }
  for (std::size_t t = 0; t < triangles.size(); ++t)
    for (const auto& v : triangles[t])
      if (!v.allFinite())
        throw std::invalid_argument("annotate: triangle " + std::to_string(t) + " has a non-finite vertex");
  return total_pairs;
}

/// Runs body(thread id, first, last) over [0, items) in chunks of `chunk`, on `threads` threads (the
/// calling one among them). The first exception stops the others from taking more chunks and is rethrown.
template <class Body>
void run_parallel(unsigned threads, std::size_t items, std::size_t chunk, Body&& body) {
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex mutex;  // guards `error`
  auto worker = [&](unsigned id) {
    try {
      for (;;) {
        if (failed) return;
        const std::size_t first = next.fetch_add(chunk);
        if (first >= items) return;
        body(id, first, std::min(items, first + chunk));
      }
    } catch (...) {
      std::lock_guard lock(mutex);
      if (!error) error = std::current_exception();
      failed = true;
    }
  };
  std::vector<std::thread> pool;
  for (unsigned id = 1; id < threads; ++id) pool.emplace_back(worker, id);
  worker(0);
  for (auto& th : pool) th.join();
  if (error) std::rethrow_exception(error);
}

/// The run's statistics: the workers' counters summed.
AnnotateStats sum_stats(const std::vector<Worker>& workers) {
  AnnotateStats s;
  for (const Worker& w : workers) {
    const ThreadStats& t = w.stats;
    s.fast_path_triangles += t.fast;
    s.clipped_triangles += t.clipped;
    s.clip_calls += t.clip_calls;
    s.skipped_clips += t.skipped_clips;
    s.derived_areas += t.derived_areas;
    s.degenerate_triangles += t.degenerate;
    s.exact_cells += t.exact_cells;
  }
  return s;
}

/// Checks the shared arguments, then counts every node with count(worker, node) over the threads, with
/// progress and statistics. `shared_infos`: the triangles' infos are computed first (for count_node).
template <class CountNode>
CellCounts count_all(std::size_t node_count,
                     std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                     std::span<const TrianglePoints> triangles, int grid, const AnnotateOptions& options,
                     std::vector<TriangleInfo>* shared_infos, CountNode&& count) {
  const auto start = std::chrono::steady_clock::now();
  const std::size_t total_pairs = check_arguments(node_count, node_ranges, triangles, grid, options);

  unsigned threads = options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<std::size_t>(threads, std::max<std::size_t>(1, node_count / 64)));

  std::vector<std::uint8_t> counts(node_count, 0);
  std::vector<Worker> workers(threads);

  if (shared_infos) {
    shared_infos->resize(triangles.size());
    run_parallel(threads, triangles.size(), 4096, [&](unsigned, std::size_t first, std::size_t last) {
      for (std::size_t t = first; t < last; ++t) (*shared_infos)[t] = make_info(triangles[t]);
    });
  }

  std::atomic<std::size_t> done_pairs{0};
  std::atomic<std::size_t> reported{0};
  std::mutex progress_mutex;  // one progress callback at a time, never moving backwards
  const std::size_t report_step = std::max<std::size_t>(1, total_pairs / 200);
  run_parallel(threads, node_count, 16, [&](unsigned id, std::size_t first, std::size_t last) {
    std::size_t pairs = 0;
    for (std::size_t n = first; n < last; ++n) {
      counts[n] = count(workers[id], static_cast<std::uint32_t>(n));
      pairs += node_ranges[n].second - node_ranges[n].first;
    }
    const std::size_t done = done_pairs.fetch_add(pairs) + pairs;
    if (options.progress && done >= reported.load() + report_step) {
      std::lock_guard lock(progress_mutex);
      if (done > reported.load()) {
        reported = done;
        options.progress(done, total_pairs);
      }
    }
  });
  if (options.progress) options.progress(total_pairs, total_pairs);

  CellCounts out;
  out.counts = std::move(counts);
  out.stats = sum_stats(workers);
  AnnotateStats& s = out.stats;
  s.threads = threads;
  s.nodes = node_count;
  s.triangle_node_pairs = total_pairs;
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace

CellCounts annotate_counts(std::span<const Box> node_boxes,
                           std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                           std::span<const TrianglePoints> triangles, int grid,
                           const AnnotateOptions& options) {
  std::vector<TriangleInfo> infos;  // filled by count_all before any node is counted
  return count_all(node_boxes.size(), node_ranges, triangles, grid, options, &infos,
                   [&](Worker& worker, std::uint32_t node) {
                     const Job job{node_boxes, node_ranges, triangles, infos, grid, options.tau};
                     return count_node(job, node, worker);
                   });
}

CellCounts annotate_counts_in_frames(std::span<const OrientedBox> node_frames,
                                     std::span<const std::pair<std::uint32_t, std::uint32_t>> node_ranges,
                                     std::span<const TrianglePoints> triangles, int grid,
                                     const AnnotateOptions& options) {
  const FrameJob job{node_frames, node_ranges, triangles, grid, options.tau};
  return count_all(
      node_frames.size(), node_ranges, triangles, grid, options, nullptr,
      [&](Worker& worker, std::uint32_t node) { return count_node_in_frame(job, node, worker); });
}

}  // namespace bvhlab

#include "bvh/topology.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <future>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace bvhlab {

std::string_view to_string(SplitMethod m) {
  return m == SplitMethod::Median ? "median" : "sah";
}

SplitMethod split_method_from_string(std::string_view s) {
  if (s == "median") return SplitMethod::Median;
  if (s == "sah") return SplitMethod::Sah;
  throw std::invalid_argument("unknown split method '" + std::string(s) + "' (expected median or sah)");
}

namespace {

constexpr int kBins = 16;
// Below this many triangles a subtree is not worth a thread of its own.
constexpr std::size_t kParallelThreshold = 50'000;

Scalar half_area(const Box& b) {
  if (b.empty()) return 0;
  const Vec3 e = b.extent();
  return e.x() * e.y() + e.y() * e.z() + e.z() * e.x();
}

class Builder {
 public:
  /// One primitive per centroid, with its box (a point's box is the point).
  Builder(std::vector<Vec3> centroids, std::vector<Box> boxes, std::uint32_t max_leaf,
          std::span<const Vec3> directions, const BuildOptions& options)
      : directions_(directions),
        options_(options),
        max_leaf_(max_leaf),
        centroids_(std::move(centroids)),
        boxes_(std::move(boxes)) {}

  Topology run(unsigned threads) {
    const std::size_t n = centroids_.size();
    Topology out;
    out.triangle_order.resize(n);
    for (std::size_t i = 0; i < n; ++i) out.triangle_order[i] = static_cast<std::uint32_t>(i);
    order_ = out.triangle_order.data();

    if (threads < 2 || n < 2 * kParallelThreshold || n <= max_leaf_) {
      Local whole = build_range(0, n);
      out.nodes = std::move(whole.nodes);
      out.depth = whole.depth;
      out.leaves = whole.leaves;
    } else {
      // Split the root here, build both halves concurrently, then splice them under the root.
      const std::size_t mid = split(0, n);
      auto left_future = std::async(std::launch::async, [&] { return build_range(0, mid); });
      Local right = build_range(mid, n);
      Local left = left_future.get();
      splice(out, left, right);
    }
    report_progress(0, true);
    return out;
  }

 private:
  struct Local {
    std::vector<TreeNode> nodes;
    std::uint32_t depth = 0;
    std::uint32_t leaves = 0;
  };

  // Builds [begin, end) of order_ depth-first with an explicit stack (no recursion-depth limit).
  Local build_range(std::size_t begin, std::size_t end) {
    Local local;
    struct Work {
      std::uint32_t node;
      std::size_t begin, end;
      std::uint32_t depth;
    };
    local.nodes.emplace_back();
    std::vector<Work> stack{{0, begin, end, 0}};
    while (!stack.empty()) {
      const Work w = stack.back();
      stack.pop_back();
      local.depth = std::max(local.depth, w.depth);
      const std::size_t count = w.end - w.begin;
      if (count <= max_leaf_) {
        local.nodes[w.node] = {static_cast<std::uint32_t>(w.begin), static_cast<std::uint32_t>(count)};
        ++local.leaves;
        report_progress(count, false);
        continue;
      }
      const std::size_t mid = split(w.begin, w.end);
      const auto left = static_cast<std::uint32_t>(local.nodes.size());
      local.nodes[w.node] = {left, 0};
      local.nodes.emplace_back();
      local.nodes.emplace_back();
      stack.push_back({left + 1, mid, w.end, w.depth + 1});
      stack.push_back({left, w.begin, mid, w.depth + 1});
    }
    return local;
  }

  // Partitions order_[begin, end) and returns the split point; both sides are non-empty.
  std::size_t split(std::size_t begin, std::size_t end) {
    std::uint32_t* first = order_ + begin;
    std::uint32_t* last = order_ + end;
    const std::size_t count = end - begin;

    // Centroid spread along every direction.
    std::size_t best_dir = 0;
    Scalar best_spread = -1;
    std::vector<std::pair<Scalar, Scalar>> ranges(directions_.size());
    for (std::size_t d = 0; d < directions_.size(); ++d) {
      Scalar lo = std::numeric_limits<Scalar>::infinity(), hi = -lo;
      for (auto* it = first; it != last; ++it) {
        const Scalar k = directions_[d].dot(centroids_[*it]);
        lo = std::min(lo, k);
        hi = std::max(hi, k);
      }
      ranges[d] = {lo, hi};
      if (hi - lo > best_spread) best_spread = hi - lo, best_dir = d;
    }
    if (!(best_spread > 0)) return begin + count / 2;  // all centroids coincide: split the list in half

    if (options_.split == SplitMethod::Sah) {
      Scalar best_cost = std::numeric_limits<Scalar>::infinity();
      std::size_t sah_dir = 0;
      int sah_bin = -1;
      for (std::size_t d = 0; d < directions_.size(); ++d) {
        const auto [lo, hi] = ranges[d];
        if (!(hi > lo)) continue;
        std::array<Box, kBins> bin_box;
        std::array<std::size_t, kBins> bin_count{};
        const Scalar scale = kBins / (hi - lo);
        for (auto* it = first; it != last; ++it) {
          const int b = bin_of(directions_[d].dot(centroids_[*it]), lo, scale);
          bin_box[b].extend(boxes_[*it]);
          ++bin_count[b];
        }
        std::array<Scalar, kBins> right_cost{};
        Box acc;
        std::size_t acc_n = 0;
        for (int b = kBins - 1; b > 0; --b) {
          acc.extend(bin_box[b]);
          acc_n += bin_count[b];
          right_cost[b] = half_area(acc) * static_cast<Scalar>(acc_n);
        }
        acc = Box{};
        acc_n = 0;
        for (int b = 0; b < kBins - 1; ++b) {
          acc.extend(bin_box[b]);
          acc_n += bin_count[b];
          if (acc_n == 0 || acc_n == count) continue;
          const Scalar cost = half_area(acc) * static_cast<Scalar>(acc_n) + right_cost[b + 1];
          if (cost < best_cost) best_cost = cost, sah_dir = d, sah_bin = b;
        }
      }
      if (sah_bin >= 0) {
        // Plain copies, not a structured binding: clang 14 (the sanitizer presets) cannot capture those.
        const Scalar lo = ranges[sah_dir].first;
        const Scalar scale = kBins / (ranges[sah_dir].second - lo);
        const Vec3 dir = directions_[sah_dir];
        auto* mid = std::partition(first, last, [&](std::uint32_t t) {
          return bin_of(dir.dot(centroids_[t]), lo, scale) <= sah_bin;
        });
        if (mid != first && mid != last) return begin + static_cast<std::size_t>(mid - first);
      }
    }
    // Object median along the direction of widest spread.
    const Vec3 dir = directions_[best_dir];
    std::uint32_t* mid = first + count / 2;
    std::nth_element(first, mid, last, [&](std::uint32_t a, std::uint32_t b) {
      return dir.dot(centroids_[a]) < dir.dot(centroids_[b]);
    });
    return begin + count / 2;
  }

  static int bin_of(Scalar key, Scalar lo, Scalar scale) {
    const int b = static_cast<int>((key - lo) * scale);
    return std::clamp(b, 0, kBins - 1);
  }

  void splice(Topology& out, const Local& left, const Local& right) {
    const auto l = static_cast<std::uint32_t>(left.nodes.size());
    auto map_left = [](std::uint32_t k) { return k == 0 ? 1u : k + 2; };
    auto map_right = [l](std::uint32_t k) { return k == 0 ? 2u : l + k + 1; };
    out.nodes.resize(1 + left.nodes.size() + right.nodes.size());
    out.nodes[0] = {1, 0};
    for (std::uint32_t k = 0; k < left.nodes.size(); ++k) {
      TreeNode n = left.nodes[k];
      if (!n.is_leaf()) n.first = map_left(n.first);
      out.nodes[map_left(k)] = n;
    }
    for (std::uint32_t k = 0; k < right.nodes.size(); ++k) {
      TreeNode n = right.nodes[k];
      if (!n.is_leaf()) n.first = map_right(n.first);
      out.nodes[map_right(k)] = n;
    }
    out.depth = 1 + std::max(left.depth, right.depth);
    out.leaves = left.leaves + right.leaves;
  }

  void report_progress(std::size_t placed, bool final_call) {
    if (!options_.progress) return;
    const std::size_t total = centroids_.size();
    const std::size_t before = placed_.fetch_add(placed);
    constexpr std::size_t kStep = 1 << 16;
    if (final_call || before / kStep != (before + placed) / kStep) {
      std::lock_guard lock(progress_mutex_);
      options_.progress(std::min(before + placed, total), total);
    }
  }

  std::span<const Vec3> directions_;
  const BuildOptions& options_;
  std::uint32_t max_leaf_;
  std::vector<Vec3> centroids_;
  std::vector<Box> boxes_;
  std::uint32_t* order_ = nullptr;
  std::atomic<std::size_t> placed_{0};
  std::mutex progress_mutex_;
};

unsigned thread_count(const BuildOptions& options) {
  return options.threads ? options.threads : std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace

std::vector<std::pair<std::uint32_t, std::uint32_t>> node_triangle_ranges(std::span<const TreeNode> nodes) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(nodes.size());
  // Children are stored after their parent, so a reverse sweep sees children first.
  for (std::size_t k = nodes.size(); k-- > 0;) {
    const TreeNode& n = nodes[k];
    if (n.is_leaf()) {
      ranges[k] = {n.first, n.first + n.count};
    } else {
      if (n.first <= k || std::size_t{n.first} + 1 >= nodes.size())
        throw std::invalid_argument("tree: node " + std::to_string(k) + " has a child index out of order");
      ranges[k] = {ranges[n.left()].first, ranges[n.right()].second};
    }
  }
  return ranges;
}

Topology build_topology(const Mesh& mesh, std::span<const Vec3> split_directions,
                        const BuildOptions& options) {
  if (mesh.triangles.empty()) throw std::invalid_argument("build: mesh '" + mesh.name + "' has no triangles");
  if (options.max_leaf_triangles == 0)
    throw std::invalid_argument("build: max_leaf_triangles must be at least 1");
  if (split_directions.empty()) throw std::invalid_argument("build: no split directions");
  if (mesh.triangles.size() >= std::numeric_limits<std::uint32_t>::max() / 2)
    throw std::invalid_argument("build: mesh '" + mesh.name +
                                "' has too many triangles for 32-bit node indices");
  const std::size_t n = mesh.triangle_count();
  std::vector<Vec3> centroids(n);
  std::vector<Box> boxes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto t = mesh.triangle(i);
    for (const auto& v : t) boxes[i].extend(v);
    centroids[i] = (t[0] + t[1] + t[2]) / Scalar(3);
  }
  Builder builder(std::move(centroids), std::move(boxes), options.max_leaf_triangles, split_directions,
                  options);
  return builder.run(thread_count(options));
}

Topology build_topology(std::span<const Vec3> points, std::span<const Vec3> split_directions,
                        const BuildOptions& options) {
  if (points.empty()) throw std::invalid_argument("build: the point cloud has no points");
  if (options.max_leaf_points == 0) throw std::invalid_argument("build: max_leaf_points must be at least 1");
  if (split_directions.empty()) throw std::invalid_argument("build: no split directions");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max() / 2)
    throw std::invalid_argument("build: too many points for 32-bit node indices");
  std::vector<Box> boxes(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite())
      throw std::invalid_argument("build: point " + std::to_string(i) + " is not finite");
    boxes[i].extend(points[i]);
  }
  Builder builder(std::vector<Vec3>(points.begin(), points.end()), std::move(boxes), options.max_leaf_points,
                  split_directions, options);
  return builder.run(thread_count(options));
}

}  // namespace bvhlab

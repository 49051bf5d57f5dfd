#include "adb/update_samples.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <thread>

namespace bvhlab {

namespace {

constexpr ParamSpec kSamplesParameters[] = {
    {.name = "per_triangle",
     .description = "surface samples per triangle on average, spread in proportion to triangle area",
     .min = 0,
     .max = 256,
     .default_value = 4,
     .exclusive_min = true},
    {.name = "seed",
     .description = "seed of the samples' random positions",
     .min = 0,
     .max = 4294967295.0,
     .default_value = 1,
     .integer = true},
    {.name = "from_rest",
     .description = "1: the rest shape's exact count plus the change the samples see; 0: the samples alone",
     .min = 0,
     .max = 1,
     .default_value = 1,
     .integer = true},
};

double area(const TrianglePoints& t) {
  return 0.5 * (t[1] - t[0]).cross(t[2] - t[0]).norm();
}

/// Samples at their triangles' current positions, each with its share of its triangle's current area.
struct MovedSamples {
  std::vector<Vec3> points;
  std::vector<double> weights;
};

MovedSamples move_samples(const SampledUpdate::State& state, std::span<const TrianglePoints> triangles) {
  MovedSamples out;
  out.points.resize(state.barycentric.size());
  out.weights.resize(state.barycentric.size());
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const std::uint32_t first = state.first_sample[t], last = state.first_sample[t + 1];
    if (first == last) continue;
    const TrianglePoints& tri = triangles[t];
    const Vec3 e1 = tri[1] - tri[0], e2 = tri[2] - tri[0];
    const double weight = area(tri) / (last - first);
    for (std::uint32_t s = first; s < last; ++s) {
      out.points[s] = tri[0] + state.barycentric[s][0] * e1 + state.barycentric[s][1] * e2;
      out.weights[s] = weight;
    }
  }
  return out;
}

/// pc of one node from the samples of its triangles.
std::uint8_t count_node(const Box& box, std::uint32_t first, std::uint32_t last, const MovedSamples& samples,
                        const AdbParams& adb) {
  if (first == last) return 0;
  const int g = adb.grid;
  const Vec3 extent = box.extent();
  const Vec3 cell = extent / g;
  const double threshold = adb.tau * (cell.x() * cell.y() + cell.y() * cell.z() + cell.z() * cell.x()) / 3;
  std::array<double, 64> sums{};  // g <= 4
  for (std::uint32_t s = first; s < last; ++s) {
    std::array<int, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      if (extent[a] > 0) {
        const double x = (samples.points[s][a] - box.min[a]) / extent[a] * g;
        lo[a] = hi[a] = std::clamp(static_cast<int>(std::floor(x)), 0, g - 1);
      } else {  // a flat box: the exact annotation counts its area in every layer
        lo[a] = 0;
        hi[a] = g - 1;
      }
    }
    for (int i = lo[0]; i <= hi[0]; ++i)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int k = lo[2]; k <= hi[2]; ++k) sums[(i * g + j) * g + k] += samples.weights[s];
  }
  int count = 0;
  for (int c = 0; c < g * g * g; ++c) count += sums[c] > 0 && sums[c] >= threshold;
  return static_cast<std::uint8_t>(count);
}

}  // namespace

std::span<const ParamSpec> SampledUpdate::parameters() {
  return kSamplesParameters;
}

SampledUpdate::Params SampledUpdate::make_params(const ParamValues& values) {
  return {parameter(values, "per_triangle"), static_cast<std::uint32_t>(parameter(values, "seed")),
          parameter(values, "from_rest") != 0};
}

SampledUpdate::State SampledUpdate::draw(std::span<const TrianglePoints> triangles, const Params& params) {
  State state;
  state.params = params;
  double total = 0;
  for (const TrianglePoints& t : triangles) total += area(t);
  const double wanted =
      std::max(1.0, std::round(params.per_triangle * static_cast<double>(triangles.size())));
  std::mt19937_64 rng(params.seed);
  std::uniform_real_distribution<double> unit(0, 1);
  // Systematic sampling along the cumulative area: triangle t gets the sample points k * step + offset
  // falling in its stretch of it.
  const double step = total / wanted, offset = unit(rng);
  state.first_sample.assign(triangles.size() + 1, 0);
  double cumulative = 0;
  std::uint32_t drawn = 0;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    state.first_sample[t] = drawn;
    if (step > 0) {
      const double before = std::floor(cumulative / step + offset);
      cumulative += area(triangles[t]);
      drawn += static_cast<std::uint32_t>(std::floor(cumulative / step + offset) - before);
    }
  }
  state.first_sample[triangles.size()] = drawn;
  state.barycentric.resize(drawn);
  for (auto& b : state.barycentric) {
    const double root = std::sqrt(unit(rng)), r = unit(rng);  // uniform over the triangle
    b = {root * (1 - r), root * r};
  }
  return state;
}

std::vector<std::uint8_t> SampledUpdate::sampled_counts(const State& state, std::span<const Box> boxes,
                                                        std::span<const TrianglePoints> triangles,
                                                        const AdbParams& adb, unsigned threads) {
  if (adb.grid > 4) throw std::invalid_argument("density update 'samples': grid must be at most 4");
  const MovedSamples samples = move_samples(state, triangles);
  std::vector<std::uint8_t> counts(boxes.size(), 0);
  std::atomic<std::size_t> next{0};
  constexpr std::size_t kChunk = 256;
  auto work = [&] {
    for (std::size_t first; (first = next.fetch_add(kChunk)) < boxes.size();)
      for (std::size_t i = first; i < std::min(boxes.size(), first + kChunk); ++i) {
        const auto [b, e] = state.ranges[i];
        counts[i] = count_node(boxes[i], state.first_sample[b], state.first_sample[e], samples, adb);
      }
  };
  unsigned n = threads ? threads : std::max(1u, std::thread::hardware_concurrency());
  n = static_cast<unsigned>(std::min<std::size_t>(n, std::max<std::size_t>(1, boxes.size() / (4 * kChunk))));
  std::vector<std::thread> pool;
  for (unsigned k = 1; k < n; ++k) pool.emplace_back(work);
  work();
  for (auto& th : pool) th.join();
  return counts;
}

std::vector<std::uint8_t> SampledUpdate::combine(const State& state, std::vector<std::uint8_t> sampled,
                                                 int grid) {
  if (!state.params.from_rest) return sampled;
  const int cells = grid * grid * grid;
  for (std::size_t i = 0; i < sampled.size(); ++i)
    sampled[i] = static_cast<std::uint8_t>(
        std::clamp(int(state.rest_exact[i]) + int(sampled[i]) - int(state.rest_sampled[i]), 0, cells));
  return sampled;
}

}  // namespace bvhlab

#include "adb/calibration.hpp"

#include "adb/saved_tree.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <string>

namespace bvhlab {
namespace {

constexpr std::string_view kMagic = "BVHLCAL1";
constexpr std::size_t kHeaderBytes = 16, kKnotBytes = 16, kChecksumBytes = 8;

/// A pooled run of samples: its weight and collisions, and the range of probabilities it covers.
struct Block {
  double weight = 0, y_sum = 0, x_low = 0, x_high = 0;
  [[nodiscard]] double y() const { return y_sum / weight; }
};

std::vector<Block> tied_blocks(std::span<const CalibrationSample> samples) {
  std::vector<CalibrationSample> sorted(samples.begin(), samples.end());
  std::sort(sorted.begin(), sorted.end(),
            [](const auto& a, const auto& b) { return a.probability < b.probability; });
  std::vector<Block> blocks;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    const double p = sorted[i].probability;
    if (i == 0 || p != sorted[i - 1].probability) blocks.push_back({0, 0, p, p});
    blocks.back().weight += 1;
    blocks.back().y_sum += sorted[i].collided ? 1 : 0;
  }
  return blocks;
}

/// Pool adjacent violators: a stack of blocks whose frequencies never decrease.
std::vector<Block> pool_adjacent_violators(const std::vector<Block>& blocks) {
  std::vector<Block> stack;
  for (const Block& b : blocks) {
    stack.push_back(b);
    while (stack.size() > 1 && stack[stack.size() - 2].y() >= stack.back().y()) {
      const Block top = stack.back();
      stack.pop_back();
      stack.back().weight += top.weight;
      stack.back().y_sum += top.y_sum;
      stack.back().x_high = top.x_high;
    }
  }
  return stack;
}

void put_u64(std::vector<std::byte>& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<std::byte>((v >> (8 * i)) & 0xff));
}
std::uint64_t get_u64(std::span<const std::byte> in, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | std::to_integer<std::uint64_t>(in[at + std::size_t(i)]);
  return v;
}

/// Why `knots` cannot be a map, or "" when they can.
std::string knot_problem(const std::vector<CalibrationMap::Knot>& knots) {
  for (std::size_t i = 0; i < knots.size(); ++i) {
    const auto& k = knots[i];
    const std::string at = "knot " + std::to_string(i) + ": ";
    if (!std::isfinite(k.x) || !std::isfinite(k.y)) return at + "not a finite number";
    if (k.x < 0 || k.x > 1 || k.y < 0 || k.y > 1) return at + "outside [0, 1]";
    if (i > 0 && !(k.x > knots[i - 1].x)) return at + "reported probabilities not strictly increasing";
    if (i > 0 && k.y < knots[i - 1].y) return at + "not monotone (the calibrated probability decreases)";
  }
  return "";
}

double lerp_between(const CalibrationMap::Knot& a, const CalibrationMap::Knot& b, double p) {
  if (b.x <= a.x) return b.y;
  return a.y + (b.y - a.y) * (p - a.x) / (b.x - a.x);
}

}  // namespace

CalibrationMap::CalibrationMap(std::vector<Knot> knots) : knots_(std::move(knots)) {
  if (const std::string why = knot_problem(knots_); !why.empty())
    throw CalibrationError("calibration map: " + why);
}

CalibrationMap CalibrationMap::fit(std::span<const CalibrationSample> samples) {
  for (const CalibrationSample& s : samples)
    if (!(s.probability >= 0 && s.probability <= 1))
      throw CalibrationError("calibration fit: probability " + std::to_string(s.probability) +
                             " is not a number in [0, 1]");
  // A knot at each end of each block: every training probability maps to its block's frequency, as the
  // fit says. (Knots at the block means alone would move answers far from their block's mean towards the
  // neighbouring blocks, and ADB reports few distinct values, so a block's mass often sits at one end.)
  std::vector<Knot> knots;
  for (const Block& b : pool_adjacent_violators(tied_blocks(samples))) {
    const double y = std::clamp(b.y(), 0.0, 1.0);
    knots.push_back({b.x_low, y});
    if (b.x_high > b.x_low) knots.push_back({b.x_high, y});
  }
  return CalibrationMap(std::move(knots));
}

double CalibrationMap::operator()(double probability) const {
  if (std::isnan(probability)) return probability;
  const double p = std::clamp(probability, 0.0, 1.0);
  if (knots_.empty()) return p;
  if (p <= knots_.front().x) return lerp_between({0, 0}, knots_.front(), p);
  if (p >= knots_.back().x) return lerp_between(knots_.back(), {1, 1}, p);
  const auto upper =
      std::upper_bound(knots_.begin(), knots_.end(), p, [](double v, const Knot& k) { return v < k.x; });
  return std::clamp(lerp_between(*(upper - 1), *upper, p), 0.0, 1.0);
}

std::vector<std::byte> CalibrationMap::encode() const {
  std::vector<std::byte> out;
  for (char c : kMagic) out.push_back(static_cast<std::byte>(c));
  put_u64(out, knots_.size());  // count (u32) and the reserved zero (u32), little-endian
  for (const Knot& k : knots_) {
    put_u64(out, std::bit_cast<std::uint64_t>(k.x));
    put_u64(out, std::bit_cast<std::uint64_t>(k.y));
  }
  put_u64(out, saved_tree_detail::fnv1a64(out));
  return out;
}

CalibrationMap CalibrationMap::decode(std::span<const std::byte> bytes, std::string_view source) {
  const std::string where = std::string(source) + ": ";
  if (bytes.size() < kHeaderBytes + kChecksumBytes)
    throw CalibrationError(where + "too short for a calibration map");
  if (std::string_view(reinterpret_cast<const char*>(bytes.data()), kMagic.size()) != kMagic)
    throw CalibrationError(where + "not a calibration map (wrong magic)");
  const std::uint64_t head = get_u64(bytes, kMagic.size());
  const std::uint64_t count = head & 0xffffffffu;
  if (head >> 32) throw CalibrationError(where + "reserved field is not 0");
  if ((bytes.size() - kHeaderBytes - kChecksumBytes) / kKnotBytes != count ||
      (bytes.size() - kHeaderBytes - kChecksumBytes) % kKnotBytes != 0)
    throw CalibrationError(where + "size does not match its " + std::to_string(count) + " knots");
  const std::size_t body = bytes.size() - kChecksumBytes;
  if (get_u64(bytes, body) != saved_tree_detail::fnv1a64(bytes.first(body)))
    throw CalibrationError(where + "checksum mismatch");
  std::vector<Knot> knots(count);
  for (std::size_t i = 0; i < count; ++i) {
    knots[i].x = std::bit_cast<double>(get_u64(bytes, kHeaderBytes + i * kKnotBytes));
    knots[i].y = std::bit_cast<double>(get_u64(bytes, kHeaderBytes + i * kKnotBytes + 8));
  }
  if (const std::string why = knot_problem(knots); !why.empty()) throw CalibrationError(where + why);
  return CalibrationMap(std::move(knots));
}

}  // namespace bvhlab

// The isotonic calibration map: PAV against the min-max formula of isotonic regression, monotonicity, the
// identity fallback, encode/decode, and that a fitted map repairs a miscalibrated series on held-out samples.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "adb/calibration.hpp"
#include "adb/saved_tree.hpp"

namespace bvhlab {
namespace {

using Knot = CalibrationMap::Knot;

/// Isotonic regression by its closed form: the value at distinct probability i is
/// max over j <= i of min over k >= i of the mean frequency of distinct probabilities j..k (weighted by
/// their sample counts); a run of equal values becomes knots at its lowest and highest probability.
std::vector<Knot> reference_knots(std::vector<CalibrationSample> samples) {
  std::sort(samples.begin(), samples.end(),
            [](const auto& a, const auto& b) { return a.probability < b.probability; });
  std::vector<double> xs, weight, hits;
  for (const auto& s : samples) {
    if (xs.empty() || xs.back() != s.probability) {
      xs.push_back(s.probability);
      weight.push_back(0);
      hits.push_back(0);
    }
    weight.back() += 1;
    hits.back() += s.collided;
  }
  const std::size_t n = xs.size();
  std::vector<double> value(n);
  for (std::size_t i = 0; i < n; ++i) {
    double best = -1;
    for (std::size_t j = 0; j <= i; ++j) {
      double worst = 2;
      for (std::size_t k = i; k < n; ++k) {
        double w = 0, h = 0;
        for (std::size_t m = j; m <= k; ++m) w += weight[m], h += hits[m];
        worst = std::min(worst, h / w);
      }
      best = std::max(best, worst);
    }
    value[i] = best;
  }
  std::vector<Knot> knots;
  for (std::size_t i = 0; i < n;) {
    std::size_t end = i;
    while (end < n && std::abs(value[end] - value[i]) < 1e-12) ++end;
    knots.push_back({xs[i], value[i]});
    if (end - 1 > i) knots.push_back({xs[end - 1], value[i]});
    i = end;
  }
  return knots;
}

TEST(Calibration, PavMatchesTheMinMaxFormulaOnSmallInputs) {
  std::mt19937 rng(12);
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<CalibrationSample> samples(1 + rng() % 12);
    for (auto& s : samples) s = {double(rng() % 6) / 5, rng() % 3 == 0};  // few values: many ties
    const std::vector<Knot> expected = reference_knots(samples);
    const std::vector<Knot> got = CalibrationMap::fit(samples).knots();
    ASSERT_EQ(got.size(), expected.size()) << "trial " << trial;
    for (std::size_t i = 0; i < got.size(); ++i) {
      EXPECT_NEAR(got[i].x, expected[i].x, 1e-12) << "trial " << trial << " knot " << i;
      EXPECT_NEAR(got[i].y, expected[i].y, 1e-12) << "trial " << trial << " knot " << i;
    }
  }
}

TEST(Calibration, OutputIsMonotoneAndWithinTheUnitInterval) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<CalibrationSample> samples(2000);
  for (auto& s : samples) {
    s.probability = unit(rng);
    s.collided = unit(rng) < 0.5 + 0.4 * std::sin(12 * s.probability);  // far from monotone
  }
  const CalibrationMap map = CalibrationMap::fit(samples);
  double previous = -1;
  for (int i = -10; i <= 1010; ++i) {
    const double y = map(i / 1000.0);
    ASSERT_GE(y, previous) << "at " << i / 1000.0;
    ASSERT_GE(y, 0.0);
    ASSERT_LE(y, 1.0);
    previous = y;
  }
}

TEST(Calibration, IdentityWithoutSamplesAndNearlyIdentityWhenCalibrated) {
  const CalibrationMap none = CalibrationMap::fit({});
  EXPECT_TRUE(none.identity());
  for (double p : {0.0, 0.3, 1.0}) EXPECT_EQ(none(p), p);
  EXPECT_EQ(none(1.5), 1.0);  // clamped

  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0, 1);
  std::vector<CalibrationSample> samples(100000);
  for (auto& s : samples) {
    s.probability = unit(rng);
    s.collided = unit(rng) < s.probability;
  }
  const CalibrationMap map = CalibrationMap::fit(samples);
  for (double p = 0.05; p < 1; p += 0.05) EXPECT_NEAR(map(p), p, 0.03) << "at " << p;
}

TEST(Calibration, FallsBackTowardsTheIdentityOutsideTheSamples) {
  const CalibrationMap map({{0.4, 0.2}, {0.6, 0.3}});
  EXPECT_DOUBLE_EQ(map(0.2), 0.1);   // halfway from (0, 0) to the first knot
  EXPECT_DOUBLE_EQ(map(0.5), 0.25);  // between the knots
  EXPECT_DOUBLE_EQ(map(0.8), 0.65);  // halfway from the last knot to (1, 1)
}

TEST(Calibration, EncodeDecodeRoundTrips) {
  std::vector<CalibrationSample> samples;
  for (int i = 0; i < 50; ++i) samples.push_back({i / 49.0, i % 3 != 0 && i > 10});
  const CalibrationMap map = CalibrationMap::fit(samples);
  ASSERT_FALSE(map.identity());
  const CalibrationMap back = CalibrationMap::decode(map.encode(), "test");
  EXPECT_EQ(back.knots(), map.knots());
  EXPECT_TRUE(CalibrationMap::decode(CalibrationMap().encode(), "test").identity());
}

void expect_refused(std::vector<std::byte> bytes, const std::string& why) {
  try {
    (void)CalibrationMap::decode(bytes, "maps/x.calib");
    ADD_FAILURE() << "accepted; expected: " << why;
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("maps/x.calib: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
  }
}

TEST(Calibration, CorruptBytesAreRefusedByName) {
  const std::vector<std::byte> good = CalibrationMap({{0.2, 0.1}, {0.7, 0.8}}).encode();
  expect_refused({good.begin(), good.begin() + 10}, "too short");
  auto bad_magic = good;
  bad_magic[0] = std::byte{'X'};
  expect_refused(bad_magic, "wrong magic");
  auto longer = good;
  longer.push_back(std::byte{0});
  expect_refused(longer, "size does not match");
  auto flipped = good;
  flipped[20] ^= std::byte{1};
  expect_refused(flipped, "checksum mismatch");
  // A decreasing map with a valid checksum: refused for what it is, never applied.
  auto decreasing = good;
  std::swap_ranges(decreasing.begin() + 24, decreasing.begin() + 32, decreasing.begin() + 40);  // swap the y
  const std::uint64_t sum = saved_tree_detail::fnv1a64(std::span(decreasing).first(decreasing.size() - 8));
  for (int i = 0; i < 8; ++i)
    decreasing[decreasing.size() - 8 + std::size_t(i)] = std::byte((sum >> (8 * i)) & 0xff);
  expect_refused(decreasing, "not monotone");
  EXPECT_THROW((void)CalibrationMap({{0.5, 0.2}, {0.5, 0.3}}), CalibrationError);
  EXPECT_THROW((void)CalibrationMap({{0.5, 1.2}}), CalibrationError);
  EXPECT_THROW((void)CalibrationMap::fit(std::vector<CalibrationSample>{{1.5, true}}), CalibrationError);
}

/// The largest |mean probability - observed frequency| over the deciles holding at least 50 answers, as the
/// report judges a series.
double largest_decile_gap(const std::vector<double>& probability, const std::vector<bool>& collided) {
  std::array<double, 10> count{}, sum{}, hits{};
  for (std::size_t i = 0; i < probability.size(); ++i) {
    const auto bin = std::min<std::size_t>(9, static_cast<std::size_t>(probability[i] * 10));
    count[bin] += 1;
    sum[bin] += probability[i];
    hits[bin] += collided[i];
  }
  double gap = 0;
  for (std::size_t b = 0; b < 10; ++b)
    if (count[b] >= 50) gap = std::max(gap, std::abs(sum[b] - hits[b]) / count[b]);
  return gap;
}

TEST(Calibration, RepairsAMiscalibratedSeriesOnHeldOutSamples) {
  // A series that overstates: reported p, true frequency p^3 (like a dense scan's coarse node pairs).
  auto draw = [](std::uint64_t seed, std::size_t n, std::vector<double>& p, std::vector<bool>& hit) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> unit(0, 1);
    for (std::size_t i = 0; i < n; ++i) {
      p.push_back(unit(rng));
      hit.push_back(unit(rng) < p.back() * p.back() * p.back());
    }
  };
  std::vector<double> train_p, test_p;
  std::vector<bool> train_hit, test_hit;
  draw(1, 20000, train_p, train_hit);
  draw(2, 40000, test_p, test_hit);
  std::vector<CalibrationSample> samples;
  for (std::size_t i = 0; i < train_p.size(); ++i) samples.push_back({train_p[i], train_hit[i]});
  const CalibrationMap map = CalibrationMap::fit(samples);
  std::vector<double> calibrated;
  for (double p : test_p) calibrated.push_back(map(p));
  EXPECT_GT(largest_decile_gap(test_p, test_hit), 0.2);
  EXPECT_LE(largest_decile_gap(calibrated, test_hit), 0.05);
}

}  // namespace
}  // namespace bvhlab

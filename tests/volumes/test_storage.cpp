// Outward rounding to float, the basis of every float-stored volume's conservativeness.
#include "support/random_draws.hpp"
#include "volumes/aabb.hpp"
#include "volumes/storage.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace bvhlab {
namespace {

using testing::draw_vec3;

// The shape GCC 12's SLP vectoriser miscompiles (double(float(x)) folded back to x): several coordinates
// rounded and compared in one function, vectorisable, not inlined into the test loop.
__attribute__((noinline)) void round_pair(const double* __restrict p, float* __restrict lo,
                                          float* __restrict hi) {
  lo[0] = float_down(p[0]);
  lo[1] = float_down(p[1]);
  hi[0] = float_up(p[0]);
  hi[1] = float_up(p[1]);
}

TEST(FloatStorage, OutwardRoundingBracketsEveryValueTightly) {
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> mantissa(-1, 1);
  std::uniform_int_distribution<int> exponent(-100, 100);
  int exact = 0;
  for (int i = 0; i < 200000; ++i) {
    const auto draw = [&] {
      const int e = exponent(rng);
      return std::ldexp(mantissa(rng), e);
    };
    const double p[2] = {draw(), draw()};
    float lo[2], hi[2];
    round_pair(p, lo, hi);
    for (int k = 0; k < 2; ++k) {
      ASSERT_LE(double(lo[k]), p[k]);
      ASSERT_GE(double(hi[k]), p[k]);
      // Tight: the neighbours outside would no longer bracket.
      ASSERT_GT(double(std::nextafter(lo[k], INFINITY)), p[k] - 0.0) << p[k];
      ASSERT_LT(double(std::nextafter(hi[k], -INFINITY)), p[k] + 0.0) << p[k];
      exact += lo[k] == hi[k];
    }
  }
  EXPECT_LT(exact, 100);  // doubles drawn at random are almost never floats: the rounding was exercised
}

TEST(FloatStorage, AabbFitContainsItsPointsAfterRounding) {
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> u(-10, 10);
  for (int i = 0; i < 100000; ++i) {
    const Vec3 points[2] = {draw_vec3(u, rng), draw_vec3(u, rng) * 1e-3};
    const Aabb box = Aabb::fit(points);
    ASSERT_TRUE(box.contains(points[0]) && box.contains(points[1])) << i;
  }
}

}  // namespace
}  // namespace bvhlab

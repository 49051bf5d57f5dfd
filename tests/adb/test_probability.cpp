// The ADB probability model against exact integer/rational arithmetic (GMP), closed forms and the
// properties the traversal relies on (range, monotonicity, symmetry, error handling).
#include <gmpxx.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "adb/lb_table.hpp"
#include "adb/probability.hpp"

namespace bvhlab {
namespace {

// num / den to double with relative error below 1e-15 (each operand truncated to 53 bits, no gcd).
double ratio_to_double(const mpz_class& num, const mpz_class& den) {
  if (num == 0) return 0.0;
  long exp_num = 0;
  long exp_den = 0;
  const double mant_num = mpz_get_d_2exp(&exp_num, num.get_mpz_t());
  const double mant_den = mpz_get_d_2exp(&exp_den, den.get_mpz_t());
  return std::ldexp(mant_num / mant_den, static_cast<int>(exp_num - exp_den));
}

mpz_class binomial(unsigned long n, unsigned long k) {
  constexpr unsigned long kCached = 64;  // Pascal's triangle for the table domain, computed once
  static const std::vector<std::vector<mpz_class>> pascal = [] {
    std::vector<std::vector<mpz_class>> rows(kCached + 1);
    for (unsigned long r = 0; r <= kCached; ++r) {
      rows[r].assign(r + 1, 1);
      for (unsigned long c = 1; c < r; ++c) rows[r][c] = rows[r - 1][c - 1] + rows[r - 1][c];
    }
    return rows;
  }();
  if (n <= kCached) return k <= n ? pascal[n][k] : mpz_class(0);
  mpz_class c;
  mpz_bin_uiui(c.get_mpz_t(), n, k);
  return c;
}

// Exact hypergeometric counts: tail[x] = sum_{i >= x} C(s_b, i) C(s - s_b, s_a - i), for x in [0, s + 1];
// Pr[cc >= x] = tail[x] / C(s, s_a).
std::vector<mpz_class> exact_tail_counts(int s, int s_a, int s_b) {
  std::vector<mpz_class> tail(static_cast<std::size_t>(s) + 2, 0);
  for (int i = s; i >= 0; --i) {
    mpz_class term = 0;
    if (i <= s_b && s_a - i >= 0 && s_a - i <= s - s_b) {
      term = binomial(static_cast<unsigned long>(s_b), static_cast<unsigned long>(i)) *
             binomial(static_cast<unsigned long>(s - s_b), static_cast<unsigned long>(s_a - i));
    }
    tail[static_cast<std::size_t>(i)] = tail[static_cast<std::size_t>(i) + 1] + term;
  }
  return tail;
}

std::string fmt_scientific(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3e", value);
  return text;
}

double relative_error(double got, double exact) {
  if (exact == 0.0) return got == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  return std::fabs(got - exact) / exact;
}

constexpr double kTolerance = 1e-12;  // relative, against exact arithmetic
constexpr int kExactDomain = 64;      // s <= 64: the table a 4x4x4 cell grid needs

TEST(HypergeometricTail, MatchesExactArithmeticOnWholeDomain) {
  double worst = 0.0;
  for (int s = 0; s <= kExactDomain; ++s) {
    for (int s_a = 0; s_a <= s; ++s_a) {
      for (int s_b = 0; s_b <= s; ++s_b) {
        const std::vector<mpz_class> tail = exact_tail_counts(s, s_a, s_b);
        ASSERT_EQ(tail[0], binomial(static_cast<unsigned long>(s), static_cast<unsigned long>(s_a)))
            << "Vandermonde's identity fails: the exact reference is wrong";
        for (int x = -1; x <= s + 1; ++x) {
          const double exact = x <= 0 ? 1.0 : ratio_to_double(tail[static_cast<std::size_t>(x)], tail[0]);
          const double got = pr_collision_cells_at_least(s, s_a, s_b, x);
          const double err = relative_error(got, exact);
          worst = std::max(worst, err);
          ASSERT_LE(err, kTolerance) << "s=" << s << " s_a=" << s_a << " s_b=" << s_b << " x=" << x << " got "
                                     << got << " exact " << exact;
        }
      }
    }
  }
  RecordProperty("worst_relative_error", fmt_scientific(worst));
}

// The table for one LB against exact rationals. lb is a double, hence exactly the dyadic rational
// num / den; 1 - (1 - lb)^x = (den^x - (den - num)^x) / den^x. All candidates over x share the
// denominator C(s, s_a) den^S, so the maximum is taken over exact integers.
class TableVsExact : public ::testing::TestWithParam<double> {};

TEST_P(TableVsExact, EveryEntryWithinTolerance) {
  const double lb = GetParam();
  const ProbabilityTable table(kExactDomain, lb);
  const mpq_class lb_exact(lb);
  const mpz_class den = lb_exact.get_den();
  const mpz_class keep = den - lb_exact.get_num();      // numerator of 1 - lb
  std::vector<mpz_class> hit_scaled(kExactDomain + 1);  // (den^x - keep^x) den^(S - x)
  for (int x = 0; x <= kExactDomain; ++x) {
    mpz_class den_x;
    mpz_class keep_x;
    mpz_class den_rest;
    mpz_pow_ui(den_x.get_mpz_t(), den.get_mpz_t(), static_cast<unsigned long>(x));
    mpz_pow_ui(keep_x.get_mpz_t(), keep.get_mpz_t(), static_cast<unsigned long>(x));
    mpz_pow_ui(den_rest.get_mpz_t(), den.get_mpz_t(), static_cast<unsigned long>(kExactDomain - x));
    hit_scaled[static_cast<std::size_t>(x)] = (den_x - keep_x) * den_rest;
  }
  mpz_class den_all;
  mpz_pow_ui(den_all.get_mpz_t(), den.get_mpz_t(), static_cast<unsigned long>(kExactDomain));

  std::size_t checked = 0;
  for (int s = 0; s <= kExactDomain; ++s) {
    for (int s_a = 0; s_a <= s; ++s_a) {
      for (int s_b = 0; s_b <= s_a; ++s_b) {
        const std::vector<mpz_class> tail = exact_tail_counts(s, s_a, s_b);
        mpz_class best = 0;
        for (int x = 1; x <= s_b; ++x) {
          const mpz_class candidate =
              tail[static_cast<std::size_t>(x)] * hit_scaled[static_cast<std::size_t>(x)];
          if (candidate > best) best = candidate;
        }
        const double exact = ratio_to_double(best, tail[0] * den_all);
        const double got = table.lookup(s, s_a, s_b);
        ASSERT_LE(relative_error(got, exact), kTolerance)
            << "lb=" << lb << " s=" << s << " s_a=" << s_a << " s_b=" << s_b << " got " << got << " exact "
            << exact;
        ASSERT_EQ(got, table.lookup(s, s_b, s_a)) << "symmetry";
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, table.entries());
}

INSTANTIATE_TEST_SUITE_P(LbValues, TableVsExact,
                         ::testing::Values(0.0, 1e-3, 0.3, 0.5, lb_for_tau(0.5), 0.99, 1.0));

TEST(ProbabilityTable, LookupIsBitIdenticalToDirectEstimate) {
  const double lb = lb_for_tau(0.5);
  const ProbabilityTable table(kExactDomain, lb);
  for (int s = 0; s <= kExactDomain; ++s) {
    for (int s_a = 0; s_a <= s; ++s_a) {
      for (int s_b = 0; s_b <= s; ++s_b) {
        ASSERT_EQ(table.lookup(s, s_a, s_b), estimate_probability(s, s_a, s_b, lb))
            << "s=" << s << " s_a=" << s_a << " s_b=" << s_b;
      }
    }
  }
}

TEST(ProbabilityTable, BeyondSmaxComputesDirectlyInsteadOfRescaling) {
  const double lb = 0.8;
  const ProbabilityTable table(8, lb);
  EXPECT_EQ(table.estimate(8, 3, 5), table.lookup(8, 3, 5));
  for (const auto& [s, s_a, s_b] :
       {std::array{9, 4, 4}, std::array{27, 10, 13}, std::array{64, 1, 64}, std::array{1000, 300, 200}}) {
    const double direct = estimate_probability(s, s_a, s_b, lb);
    EXPECT_EQ(table.estimate(s, s_a, s_b), direct);
    // The rescaling rejected in the doc comment would indeed bias low: fewer expected collision cells.
    const int a = static_cast<int>(std::lround(s_a * 8.0 / s));
    const int b = static_cast<int>(std::lround(s_b * 8.0 / s));
    if (s >= 27) {
      EXPECT_LT(table.lookup(8, a, b), direct) << s;
    }
  }
}

TEST(ProbabilityTable, SizeAndMemoryAsDocumented) {
  EXPECT_EQ(ProbabilityTable(8, 0.5).entries(), 9u * 10u * 11u / 6u);
  EXPECT_EQ(ProbabilityTable(64, 0.5).entries(), 65u * 66u * 67u / 6u);
  EXPECT_LT(ProbabilityTable(64, 0.5).memory_bytes(), 400u * 1024u);
}

TEST(ProbabilityModel, BadInputIsRejectedWithAMessage) {
  EXPECT_THROW(pr_collision_cells_at_least(-1, 0, 0, 1), std::invalid_argument);
  EXPECT_THROW(pr_collision_cells_at_least(5, 6, 1, 1), std::invalid_argument);
  EXPECT_THROW(pr_collision_cells_at_least(5, 1, -1, 1), std::invalid_argument);
  EXPECT_THROW(pr_collision_cells_at_least(kMaxProbabilityCells + 1, 1, 1, 1), std::invalid_argument);
  EXPECT_THROW(estimate_probability(8, 2, 2, -0.1), std::invalid_argument);
  EXPECT_THROW(estimate_probability(8, 2, 2, 1.5), std::invalid_argument);
  EXPECT_THROW(estimate_probability(8, 2, 2, std::numeric_limits<double>::quiet_NaN()),
               std::invalid_argument);
  EXPECT_THROW(hit_probability(0.5, -1), std::invalid_argument);
  EXPECT_THROW(ProbabilityTable(-1, 0.5), std::invalid_argument);
  EXPECT_THROW(ProbabilityTable(ProbabilityTable::kMaxTableCells + 1, 0.5), std::invalid_argument);
  EXPECT_THROW(ProbabilityTable(8, 2.0), std::invalid_argument);
  const ProbabilityTable table(8, 0.5);
  EXPECT_THROW((void)table.estimate(8, 9, 1), std::invalid_argument);
  EXPECT_THROW((void)table.estimate(-1, 0, 0), std::invalid_argument);
  try {
    pr_collision_cells_at_least(5, 6, 1, 1);
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("s_a = 6"), std::string::npos) << e.what();
  }
}

TEST(ProbabilityModel, EdgeCountsHaveClosedForms) {
  for (int s : {1, 2, 8, 64, 1000, 10'000, kMaxProbabilityCells}) {
    for (int s_b : {0, 1, s - 1, s}) {
      // All cells possible for A: cc = s_b exactly.
      EXPECT_EQ(pr_collision_cells_at_least(s, s, s_b, s_b), 1.0);
      EXPECT_EQ(pr_collision_cells_at_least(s, s, s_b, s_b + 1), 0.0);
      // One cell for A: it is one of B's with probability s_b / s.
      EXPECT_NEAR(pr_collision_cells_at_least(s, 1, s_b, 1), static_cast<double>(s_b) / s, 1e-15);
      // No cell for A: no collision cell, and x = 0 is certain.
      EXPECT_EQ(pr_collision_cells_at_least(s, 0, s_b, 1), 0.0);
      EXPECT_EQ(pr_collision_cells_at_least(s, 0, s_b, 0), 1.0);
      EXPECT_EQ(estimate_probability(s, 0, s_b, 1.0), 0.0);
    }
    if (s >= 2) {  // s_a = s_b = s - 1: cc is s - 2, or s - 1 when both miss the same cell (1 in s)
      EXPECT_EQ(pr_collision_cells_at_least(s, s - 1, s - 1, s - 2), 1.0);
      EXPECT_NEAR(pr_collision_cells_at_least(s, s - 1, s - 1, s - 1), 1.0 / s, 1e-12 / s);
    }
  }
  // The maximising x is not always small: when every cell is possible for both, cc = s for sure and the
  // best x is s (why x is not capped; capping at 2 would lose up to 0.23 at LB = 0.52, see the doc).
  for (int s : {1, 8, 64}) {
    const ProbabilityEstimate full = estimate_probability_detailed(s, s, s, 0.5);
    EXPECT_EQ(full.best_x, s);
    EXPECT_DOUBLE_EQ(full.probability, 1.0 - std::pow(0.5, s));
  }
  EXPECT_EQ(estimate_probability(0, 0, 0, 1.0), 0.0);  // an empty overlap
  EXPECT_EQ(pr_collision_cells_at_least(0, 0, 0, 0), 1.0);
}

TEST(ProbabilityModel, LargeCountsMatchExactArithmetic) {
  // s = 10^4, mid-size sets; x from far below the mean (~1500, sd ~28) into the 1e-300 tail.
  const int s = 10'000;
  const int s_a = 5000;
  const int s_b = 3000;
  const std::vector<mpz_class> tail = exact_tail_counts(s, s_a, s_b);
  for (int x : {0, 1, 1000, 1400, 1450, 1500, 1501, 1550, 1600, 1700, 2000, 2400, 3000, 3001}) {
    const double exact = ratio_to_double(tail[static_cast<std::size_t>(x)], tail[0]);
    const double got = pr_collision_cells_at_least(s, s_a, s_b, x);
    ASSERT_TRUE(std::isfinite(got));
    // Thousands of recurrence steps from the mode, yet the same tolerance holds (measured: 4e-15).
    if (exact > std::numeric_limits<double>::min()) {
      EXPECT_LE(relative_error(got, exact), kTolerance) << "x=" << x << " got " << got << " exact " << exact;
    } else {
      EXPECT_LE(got, 1e-300) << "x=" << x;
    }
  }
}

TEST(ProbabilityModel, ExtremesStayFiniteAndInUnitInterval) {
  for (int s : {0, 1, 2, 3, 100, 10'000, 100'000}) {
    std::vector<int> counts{0, 1, s - 1, s};
    std::erase_if(counts, [s](int c) { return c < 0 || c > s; });
    for (int s_a : counts) {
      for (int s_b : counts) {
        for (int x : {-1, 0, 1, 2, s / 2, s - 1, s, s + 1}) {
          const double p = pr_collision_cells_at_least(s, s_a, s_b, x);
          ASSERT_TRUE(p >= 0.0 && p <= 1.0) << s << " " << s_a << " " << s_b << " " << x << " " << p;
        }
        double previous = 0.0;
        for (double lb : {0.0, 1e-12, 0.5, 1.0 - 1e-12, 1.0}) {
          const double e = estimate_probability(s, s_a, s_b, lb);
          ASSERT_TRUE(e >= 0.0 && e <= 1.0) << s << " " << s_a << " " << s_b << " " << lb << " " << e;
          ASSERT_GE(e, previous) << "estimate not monotone in lb";
          previous = e;
        }
        EXPECT_EQ(estimate_probability(s, s_a, s_b, 0.0), 0.0);
        // LB = 1: one collision cell suffices, so the estimate is Pr[cc >= 1].
        EXPECT_EQ(estimate_probability(s, s_a, s_b, 1.0), pr_collision_cells_at_least(s, s_a, s_b, 1));
      }
    }
  }
  // Tiny LB keeps its digits: 1 - (1 - 1e-12)^x ~ x 1e-12 (a naive pow(1 - lb, x) is off by ~1e-4).
  EXPECT_NEAR(hit_probability(1e-12, 3) / 3e-12, 1.0, 1e-9);
  EXPECT_NEAR(hit_probability(1.0 - 1e-12, 2), 1.0 - 1e-24, 1e-16);
  EXPECT_EQ(hit_probability(1.0, 1), 1.0);
  EXPECT_EQ(hit_probability(1.0, 0), 0.0);
}

TEST(ProbabilityModel, MorePossibleCollisionCellsNeverLowerTheTail) {
  auto check = [](int s, int step) {
    for (int s_a = 0; s_a <= s; s_a += step) {
      for (int s_b = 0; s_b < s; s_b += step) {
        for (int x = 0; x <= std::min(s_a, s_b + 1) + 1; x += std::max(1, step / 2)) {
          const double fewer = pr_collision_cells_at_least(s, s_a, s_b, x);
          ASSERT_GE(pr_collision_cells_at_least(s, s_a, s_b + 1, x), fewer)
              << "s=" << s << " s_a=" << s_a << " s_b=" << s_b << " x=" << x;
          ASSERT_GE(pr_collision_cells_at_least(s, s_b + 1, s_a, x), fewer) << "swapped";
        }
      }
    }
  };
  for (int s = 1; s <= kExactDomain; ++s) check(s, 1);
  check(10'000, 997);
}

TEST(ProbabilityModel, EstimateMonotoneInLbOverTable) {
  const std::vector<double> lbs{0.0, 1e-12, 1e-6, 0.01, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99, 1.0 - 1e-12, 1.0};
  std::vector<ProbabilityTable> tables;
  for (double lb : lbs) tables.emplace_back(kExactDomain, lb);
  for (int s = 0; s <= kExactDomain; ++s) {
    for (int s_a = 0; s_a <= s; ++s_a) {
      for (int s_b = 0; s_b <= s_a; ++s_b) {
        for (std::size_t k = 1; k < tables.size(); ++k) {
          ASSERT_GE(tables[k].lookup(s, s_a, s_b), tables[k - 1].lookup(s, s_a, s_b))
              << "lb " << lbs[k - 1] << " -> " << lbs[k] << " at s=" << s << " s_a=" << s_a << " s_b=" << s_b;
        }
      }
    }
  }
}

TEST(ProbabilityModel, BestXIsAFeasibleMaximiser) {
  const double lb = 0.3;
  for (int s = 1; s <= 32; ++s) {
    for (int s_a = 1; s_a <= s; ++s_a) {
      for (int s_b = 1; s_b <= s; ++s_b) {
        const ProbabilityEstimate e = estimate_probability_detailed(s, s_a, s_b, lb);
        ASSERT_GE(e.best_x, std::max(1, s_a + s_b - s));
        ASSERT_LE(e.best_x, std::min(s_a, s_b));
        EXPECT_EQ(e.probability,
                  pr_collision_cells_at_least(s, s_a, s_b, e.best_x) * hit_probability(lb, e.best_x));
        for (int x = 1; x <= s + 1; ++x) {  // also x outside the feasible range
          ASSERT_LE(pr_collision_cells_at_least(s, s_a, s_b, x) * hit_probability(lb, x),
                    e.probability * (1 + 1e-15));
        }
      }
    }
  }
}

}  // namespace
}  // namespace bvhlab

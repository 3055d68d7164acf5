// Coefficient tables: consistency, symmetry, published values, force evaluations per step.
#include "bodypoint/methods.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/splitting/blanes_moan.hpp"
#include "bodypoint/splitting/classic.hpp"
#include "bodypoint/splitting/kahan_li.hpp"
#include "bodypoint/splitting/mclachlan.hpp"
#include "bodypoint/splitting/sofroniou_spaletta.hpp"
#include "bodypoint/splitting/yoshida.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace bodypoint::splitting {
namespace {

// A sum of at most 36 coefficients of size <= 2.4 carries at most ~36 * 2.4 * 2^-53 ~ 1e-14 of
// rounding; 2e-14 leaves room and still rejects any wrong digit.
constexpr double kSumTol = 2e-14;
// Published tables give 16-20 significant digits; derived weights match to the last printed one.
constexpr double kPublishedTol = 2e-15;
// Blanes-Moan and Yoshida print 15 significant digits: the derived middle weight matches to that.
constexpr double kFifteenDigitsTol = 1e-14;

template <std::size_t N>
void expect_consistent(const Table<N>& t, const char* name) {
  EXPECT_NEAR(drift_sum(t), 1.0, kSumTol) << name;
  EXPECT_NEAR(kick_sum(t), 1.0, kSumTol) << name;
}

template <std::size_t S>
void expect_palindrome(const std::array<double, S>& g, const char* name) {
  double sum = 0;
  for (std::size_t i = 0; i < S; ++i) {
    EXPECT_EQ(g[i], g[S - 1 - i]) << name << " weight " << i;
    sum += g[i];
  }
  EXPECT_NEAR(sum, 1.0, kSumTol) << name;
}

TEST(Tables, EveryTableIsConsistent) {
  expect_consistent(euler, "euler");
  expect_consistent(verlet_kdk, "verlet");
  expect_consistent(strang_dkd_table, "strang");
  expect_consistent(ruth3, "ruth3");
  expect_consistent(yoshida4, "yoshida4");
  expect_consistent(blanes_moan4, "blanes_moan4");
  expect_consistent(blanes_moan_rkn4, "blanes_moan_rkn4");
  expect_consistent(blanes_moan_rkn6, "blanes_moan_rkn6");
  expect_consistent(yoshida6, "yoshida6");
  expect_consistent(kahan_li6, "kahan_li6");
  expect_consistent(yoshida8, "yoshida8");
  expect_consistent(yoshida8d, "yoshida8d");
  expect_consistent(mclachlan8, "mclachlan8");
  expect_consistent(kahan_li8, "kahan_li8");
  expect_consistent(sofroniou_spaletta10, "sofroniou_spaletta10");
}

TEST(Tables, SymmetricCompositionsArePalindromic) {
  expect_palindrome(yoshida4_weights, "yoshida4");
  expect_palindrome(yoshida6_weights, "yoshida6");
  expect_palindrome(yoshida8_weights, "yoshida8");
  expect_palindrome(yoshida8d_weights, "yoshida8d");
  expect_palindrome(kahan_li6_weights, "kahan_li6");
  expect_palindrome(kahan_li8_weights, "kahan_li8");
  expect_palindrome(mclachlan8_weights, "mclachlan8");
  expect_palindrome(sofroniou_spaletta10_weights, "sofroniou_spaletta10");
  for (std::size_t i = 0; i < blanes_moan4.a.size(); ++i)
    EXPECT_EQ(blanes_moan4.a[i], blanes_moan4.a[blanes_moan4.a.size() - 1 - i]);
}

TEST(Tables, DerivedMiddleWeightsMatchPublishedOnes) {
  EXPECT_NEAR(kahan_li6_weights[4], kahan_li6_middle, kPublishedTol);
  EXPECT_NEAR(kahan_li8_weights[8], kahan_li8_middle, kPublishedTol);
  EXPECT_NEAR(mclachlan8_weights[7], mclachlan8_middle, kPublishedTol);
  EXPECT_NEAR(sofroniou_spaletta10_weights[17], sofroniou_spaletta10_middle, kPublishedTol);
  // Blanes-Moan SRKN_11^b: the derived middle drift, as printed in their table 3.
  EXPECT_NEAR(blanes_moan_rkn6.a[6], 0.20477705429147, kFifteenDigitsTol);
  // Yoshida 1990 table 2 solution D: w0 = 1.7084530707869978 (15 digits printed for w1..w7).
  EXPECT_NEAR(yoshida8d_weights[7], 1.7084530707869978, kFifteenDigitsTol);
}

TEST(Tables, ForestRuthMatchesThesisEquations29And210) {
  const double x1 = 1.0 / (2.0 - std::cbrt(2.0)), x0 = -std::cbrt(2.0) / (2.0 - std::cbrt(2.0));
  const std::array<double, 4> C{x1 / 2, (x0 + x1) / 2, (x0 + x1) / 2, x1 / 2}, D{x1, x0, x1, 0.0};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(yoshida4.a[i], C[i], kPublishedTol);
    EXPECT_NEAR(yoshida4.b[i], D[i], kPublishedTol);
  }
}

TEST(Tables, YoshidaSixMatchesThesisTable21) {
  // Thesis table 2.1, "numerical value" column, as printed.
  const std::array<double, 10> C{0.7936124638611216,   -0.20627658481643985, -0.20627658481643985,
                                 -0.11800886788129283, 0.2369495736530507,   0.2369495736530507,
                                 -0.11800886788129283, -0.20627658481643985, -0.20627658481643985,
                                 0.7936124638611216};
  const std::array<double, 10> D{1.5872249277222432,  -1.999778097355123, 1.5872249277222432,
                                 -1.8232426634848289, 2.2971418107909303, -1.8232426634848289,
                                 1.5872249277222432,  -1.999778097355123, 1.5872249277222432,
                                 0.0};
  for (int i = 0; i < 10; ++i) {
    EXPECT_NEAR(yoshida6.a[i], C[i], kPublishedTol) << "C_" << i + 1;
    EXPECT_NEAR(yoshida6.b[i], D[i], kPublishedTol) << "D_" << i + 1;
  }
}

TEST(Tables, ForceEvaluationsPerStep) {
  // Thesis table 4.1 for its drift/kick family (no sharing between steps).
  EXPECT_EQ(method_or_throw("thesis-euler").evals_per_step, 1);
  EXPECT_EQ(method_or_throw("thesis-verlet").evals_per_step, 2);
  EXPECT_EQ(method_or_throw("thesis-ruth3").evals_per_step, 3);
  EXPECT_EQ(method_or_throw("thesis-fr4").evals_per_step, 3);
  EXPECT_EQ(method_or_throw("thesis-y6").evals_per_step, 9);
  // A symmetric s-stage composition costs s force evaluations per step (first same as last).
  EXPECT_EQ(method_or_throw("lp-verlet").evals_per_step, 1);
  EXPECT_EQ(method_or_throw("lp-y4").evals_per_step, 3);
  EXPECT_EQ(method_or_throw("lp-bm4").evals_per_step, 6);
  EXPECT_EQ(method_or_throw("lp-rkn4").evals_per_step, 6);
  EXPECT_EQ(method_or_throw("lp-rkn6").evals_per_step, 11);
  EXPECT_EQ(method_or_throw("lp-kl6").evals_per_step, 9);
  EXPECT_EQ(method_or_throw("lp-y8").evals_per_step, 27);
  EXPECT_EQ(method_or_throw("lp-mcl8").evals_per_step, 15);
  EXPECT_EQ(method_or_throw("lp-kl8").evals_per_step, 17);
  EXPECT_EQ(method_or_throw("lp-ss10").evals_per_step, 35);
  for (const MethodInfo& m : methods()) {
    if (m.name != "odeint-bs" && m.name != "ks") {  // Bulirsch-Stoer: order varies; ks: exact flow (0)
      EXPECT_GE(m.order, 1) << m.name;
    }
    EXPECT_EQ(find_method(m.name), &m) << m.name;
  }
}

}  // namespace
}  // namespace bodypoint::splitting

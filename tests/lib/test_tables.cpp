// Coefficient tables: order-condition residuals, published values, force evaluations per step.
#include "bodypoint/methods.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/splitting/catalogue.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace bodypoint::splitting {
namespace {

// Published tables give 16-20 significant digits; derived weights match to the last printed one.
constexpr double kPublishedTol = 2e-15;
// Blanes-Moan and Yoshida print 15 significant digits: the derived middle weight matches to that.
constexpr double kFifteenDigitsTol = 1e-14;

// ---- order conditions --------------------------------------------------------------------------
// A table has order p when its composition of the two sub-flows agrees with the full flow up to h^p
// for every split x' = (A + B) x. With matrix flows the h^k coefficients of both sides are exact
// finite sums, computed here in long double as truncated power series in h: the residual of the
// degree-k order conditions is the largest entry of coef_k(composition) - coef_k(exp(h (A + B))).
// It must be rounding for k <= p, and not for k = p + 1 (the table is not of higher order than
// claimed, so the test also catches a table that lost a stage or a digit at degree p + 1).
using Mat = Eigen::Matrix<long double, 4, 4>;
using Series = std::vector<Mat>;  // coefficients of h^0 .. h^K

/// The coefficients are doubles: each carries a relative rounding of up to 2^-53, which moves a degree-k
/// coefficient by at most that times the sum of the magnitudes of its terms (the same series with
/// |a_i|, |b_i|, |A|, |B|); 8 double epsilons of that bound it, the long-double arithmetic adding
/// 2^11 times less. Measured residuals stay below 0.12 of it. Mutation check: one Kahan-Li 6 weight
/// changed by 9e-12 fails degrees 3 and 4; changed by 4e-13 it passes (the bound's cancellation).
constexpr long double kRoundingFactor = 8.0L * std::numeric_limits<double>::epsilon();
/// The first degree that does not vanish stands at least this far above every residual below it
/// (measured: 1e8 for Sofroniou-Spaletta 10, more for every other table).
constexpr long double kNonZeroFactor = 1e4L;

Series exp_series(long double c, const Mat& A, std::size_t K) {
  Series e(K + 1);
  e[0] = Mat::Identity();
  for (std::size_t k = 1; k <= K; ++k) e[k] = e[k - 1] * (c * A) / static_cast<long double>(k);
  return e;
}

/// Truncated product P Q (Q's flow first).
Series times(const Series& P, const Series& Q) {
  Series r(P.size(), Mat::Zero());
  for (std::size_t i = 0; i < P.size(); ++i)
    for (std::size_t j = 0; i + j < P.size(); ++j) r[i + j] += P[i] * Q[j];
  return r;
}

template <std::size_t N>
Series composition(const Table<N>& t, const Mat& A, const Mat& B, std::size_t K, bool magnitudes) {
  Series m = exp_series(0.0L, A, K);  // the identity
  for (std::size_t i = 0; i < N; ++i) {
    const long double a = t.a[i], b = t.b[i];
    m = times(exp_series(magnitudes ? std::abs(a) : a, A, K), m);
    m = times(exp_series(magnitudes ? std::abs(b) : b, B, K), m);
  }
  return m;
}

/// A drift generator and a kick generator: general ones, or a kinetic-potential pair (q' = p and
/// p' = S q, S symmetric) for the Runge-Kutta-Nystrom tables, whose order needs that structure.
std::pair<Mat, Mat> test_split(bool nystrom) {
  std::mt19937_64 rng(20261122);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Mat A = Mat::Zero(), B = Mat::Zero();
  if (!nystrom) {
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        A(i, j) = u(rng);
        B(i, j) = u(rng);
      }
  } else {
    A.topRightCorner<2, 2>() = Eigen::Matrix<long double, 2, 2>::Identity();
    Eigen::Matrix<long double, 2, 2> S;
    S << u(rng), u(rng), 0, u(rng);
    S(1, 0) = S(0, 1);
    B.bottomLeftCorner<2, 2>() = S;
  }
  return {A, B};
}

template <std::size_t N>
void expect_order(const Table<N>& t, const char* name, std::size_t p, bool nystrom = false) {
  const auto [A, B] = test_split(nystrom);
  const std::size_t K = p + 1;
  const Series m = composition(t, A, B, K, false), exact = exp_series(1.0L, A + B, K);
  const Mat Aa = A.cwiseAbs(), Ba = B.cwiseAbs();
  const Series scale = composition(t, Aa, Ba, K, true), exact_scale = exp_series(1.0L, Aa + Ba, K);
  long double below = 0.0L;  // the largest residual of the degrees <= p
  for (std::size_t k = 1; k <= p; ++k) {
    const long double residual = (m[k] - exact[k]).cwiseAbs().maxCoeff();
    const long double rounding = kRoundingFactor * std::max(scale[k].maxCoeff(), exact_scale[k].maxCoeff());
    EXPECT_LE(residual, rounding) << name << ": the order conditions of degree " << k << " fail";
    below = std::max(below, residual);
  }
  const long double next = (m[K] - exact[K]).cwiseAbs().maxCoeff();
  EXPECT_GT(next, kNonZeroFactor * below) << name << ": degree " << K << " vanishes too (order above " << p << "?)";
}

// Every table of the catalogue, at the order its type states: a new table is checked by being listed.
// The catalogue held 15 tables when it was introduced and only grows; fewer means the list lost one.
constexpr int kTablesWhenListed = 15;
TEST(Tables, OrderConditionResidualsVanishUpToTheClaimedOrder) {
  int checked = 0;
  for_each(AllTables{}, [&checked]<class E>() {
    using T = typename E::type;
    expect_order(T::table, std::string(T::tag).c_str(), static_cast<std::size_t>(T::order), is_nystrom<T>());
    ++checked;
  });
  EXPECT_GE(checked, kTablesWhenListed);
}

/// Whether a table's step is its own adjoint, S(-h) S(h) = I, by the series: every degree 1 .. p + 1 of the
/// product vanishes to the coefficients' rounding (a table of order p that is not symmetric differs from its
/// adjoint at degree p + 1). Returns that verdict, checking that a non-vanishing degree stands clear of it.
template <std::size_t N>
bool symmetric_by_series(const Table<N>& t, std::size_t p, bool nystrom, const char* name) {
  const auto [A, B] = test_split(nystrom);
  const std::size_t K = p + 1;
  Table<N> back = t;  // S(-h): every coefficient negated
  for (std::size_t i = 0; i < N; ++i) back.a[i] = -t.a[i], back.b[i] = -t.b[i];
  const Series m = times(composition(back, A, B, K, false), composition(t, A, B, K, false));
  const Mat Aa = A.cwiseAbs(), Ba = B.cwiseAbs();
  const Series scale = times(composition(t, Aa, Ba, K, true), composition(t, Aa, Ba, K, true));
  long double worst = 0.0L, rounding = 0.0L;
  for (std::size_t k = 1; k <= K; ++k) {
    worst = std::max(worst, m[k].cwiseAbs().maxCoeff());
    rounding = std::max(rounding, kRoundingFactor * scale[k].maxCoeff());
  }
  if (worst > rounding) {
    EXPECT_GT(worst, kNonZeroFactor * rounding) << name << ": neither symmetric nor clearly not";
  }
  return worst <= rounding;
}

// The catalogue's symmetry of a step (its sub-flows read the same backwards: OpSequence::symmetric, the
// paper's table of compositions) is the algebraic one: S(-h) S(h) = I. Euler and Ruth 3 are the tables that
// are not symmetric.
TEST(Tables, SymmetryOfEveryTableIsItsAdjointsEquality) {
  int not_symmetric = 0;
  for_each(AllTables{}, [&not_symmetric]<class E>() {
    using T = typename E::type;
    const bool by_series = symmetric_by_series(T::table, static_cast<std::size_t>(T::order), is_nystrom<T>(),
                                               std::string(T::tag).c_str());
    EXPECT_EQ(ops_of<T>.symmetric(), by_series) << T::tag;
    not_symmetric += by_series ? 0 : 1;
  });
  EXPECT_EQ(not_symmetric, 2);  // euler and ruth3
  for (const MethodInfo& m : methods()) {
    if (!m.table.empty()) {
      EXPECT_EQ(m.symmetric, m.table != "euler" && m.table != "ruth3") << m.name;
    }
  }
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
    // Bulirsch-Stoer extrapolation (odeint-bs, logh-bs) and CVODE's Adams method (orders 1-12): the order
    // varies; ks: exact flow (0); far-ip: spectral in its step (0).
    if (m.name != "odeint-bs" && m.name != "ks" && m.family != Family::Extrapolated && m.family != Family::FarField &&
        m.family != Family::Sundials) {
      EXPECT_GE(m.order, 1) << m.name;
    }
    EXPECT_EQ(find_method(m.name), &m) << m.name;
  }
}

// A splitting method's catalogue row names the composition table it applies (auto asks the catalogue for
// a family and a table, not for a name): the table is what its name says after the family's prefix, and
// every splitting family (Lie-Poisson, Kepler split, time-transformed) carries one.
TEST(Tables, EverySplittingRowNamesItsTable) {
  int with_table = 0;
  for (const MethodInfo& m : methods()) {
    if (m.table.empty()) continue;
    ++with_table;
    const std::string tail = "-" + m.table;
    ASSERT_GE(m.name.size(), tail.size()) << m.name;
    EXPECT_EQ(m.name.substr(m.name.size() - tail.size()), tail) << m.name << " applies table " << m.table;
  }
  for (const char* name : {"lp-y4", "kep-kl6", "logh-kl8", "ttl-y4"})
    EXPECT_FALSE(method_or_throw(name).table.empty()) << name;
  EXPECT_TRUE(method_or_throw("rk4").table.empty());
  EXPECT_GT(with_table, 40);  // 4 splitting families of at least 10 tables each
}

}  // namespace
}  // namespace bodypoint::splitting

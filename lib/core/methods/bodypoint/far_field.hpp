// bodypoint: a step set by the field's slow scale, not by the spin (far-ip).
//
// docs/physics.md, "The far field in the interaction picture". Far from every centre a spinning
// body's fast motion is the exact kinetic drift Phi_t (K2 turns about K1, R follows the helix about
// its guiding centre), and the force changes on the slow scale r/|v|. The exact splittings cannot take
// steps much longer than a few radians of spin there (each kick moves the axis K2 turns about at the
// same phase: resonances at pi, 2 pi, 4 pi). This step does not kick. It writes the state as
// x(t) = Phi_t(y(t)), so that y changes by the force only,
//
//   y' = DPhi_{-t}(x(t)) P(x(t)),   P = (0, F(R), 0),
//
// with the pulled-back field in closed form (theta = (B/D)|K1| t, u = K1/|K1|, K2par = u.K2, and y_K2 =
// K2 turned back by theta about u):
//
//   y_K1' = F,
//   y_K2' = (B/D) t (u.F) u x y_K2 + sin(theta) du x K2 + (1 - cos theta) (K2par du + (du.K2) u),
//           du = (F - (u.F) u)/|K1|,
//   y_R'  = -t dVg + (F x (K2 - y_K2) - K1 x y_K2')/|K1|^2 - 2 (K1.F) K1 x (K2 - y_K2)/|K1|^4,
//           dVg = (J F - B ((du.K2) u + K2par du))/D,
//
// and solves it over the step by Picard iteration on Chebyshev-Lobatto points of the step (a spectral
// collocation: the iteration's integral is exact for the polynomial through the points), with the
// exact force at the drifted points. Its points per radian of spin (points_for) resolve the
// pulled-back field's harmonics; the points per step (at least kMinPoints) resolve the force's slow
// change. So the step is bounded by the field's slow scale and by the iteration's convergence
// (h^2 |grad F|/m well below 1), never by the spin: one step may turn it by tens of radians.
// The method is Chebyshev-Picard iteration (Clenshaw and Norton, Comput. J. 6, 1963; Bai and Junkins,
// J. Astronaut. Sci. 58, 2011, for perturbed orbits) applied in the interaction picture of the exact
// spin drift; the iteration's late sweeps take the force linearised about the points last evaluated
// (kLinearRemainder).
#pragma once

#include "bodypoint/model.hpp"

#include <Eigen/Dense>

#include <map>
#include <vector>

namespace bodypoint::far_field {

/// The harmonics a step resolves. Along the helix the force's k-th harmonic in the spin's phase is
/// about (rho/r)^k of it (rho = |K1 x K2|/|K1|^2, the helix's radius; r: the distance to the nearest
/// centre), and the pull-back shifts each by one. A step resolves the harmonics up to the first whose
/// share is below kAliasShare, at least kMinHarmonic and at most kMaxHarmonic; a harmonic k over a
/// step that turns the spin by phi needs about k phi/2 Chebyshev points (pi points per wavelength).
inline constexpr double kAliasShare = 1e-13;
inline constexpr int kMinHarmonic = 2;
inline constexpr int kMaxHarmonic = 32;
/// Points of a step beyond those its harmonics need, and the fewest points of a step: the polynomial
/// through them carries the force's slow change.
inline constexpr int kExtraPoints = 8;
inline constexpr int kMinPoints = 16;
/// The most points of a step: its quadrature matrix is 8 MB and is built in about 0.3 s (once per
/// number of points); a step that needs more is refused as too long.
inline constexpr int kMaxPoints = 1024;
/// The Chebyshev intervals of a step that turns the spin by `angle` radians where the helix's radius
/// over the distance to the nearest centre is `ratio` (far_field.cpp); -1 above kMaxPoints.
int points_for(double angle, double ratio);
/// The iteration has converged when an iteration changes y by less than this (relative, per part).
inline constexpr double kConverged = 4e-16;
/// Iterations before a step is declared too long for the field it crosses.
inline constexpr int kMaxIterations = 20;
/// An iteration that no longer halves the change has reached rounding when the change is below this
/// (relative); above it, it diverges (the step is too long for the field).
inline constexpr double kRoundingChange = 1e-13;
/// The iterations after one that moved the points by delta take the force linearised about the points
/// last evaluated (F and its Jacobian, one force evaluation per point) once what that omits is below
/// this share of the state per step: the second-order term of a Coulomb force, at most
/// kSecondOrder (delta/r)^2 of it (r: the distance to the nearest centre), times the step's impulse
/// h |F| / |K1|, the share of the state the force changes in the step.
inline constexpr double kLinearRemainder = 1e-17;
/// |d^2 F[delta, delta]| / 2 <= kSecondOrder (delta/r)^2 |F| for F = -A d/|d|^3 (the terms 3/2 |delta|^2/r^2
/// and 15/2 (d.delta)^2/r^4 of its expansion).
inline constexpr double kSecondOrder = 9.0;

/// Chebyshev-Lobatto points of [0, 1] and the matrix of the integral from 0 to each point of the
/// polynomial through values at them.
struct Nodes {
  Eigen::VectorXd sigma;  ///< n + 1 points, increasing, sigma(0) = 0, sigma(n) = 1
  Eigen::MatrixXd Q;      ///< (n + 1) x (n + 1)
};
/// The nodes for n intervals (n >= 1).
Nodes chebyshev_nodes(int n);

/// One body-point in Coulomb centres, stepped by the far-field collocation (file comment).
class Stepper {
 public:
  Stepper(const BodyPoint& p, std::vector<Centre> centres);

  /// Advances (R, K1, K2) by h. Throws Error when |K1| = 0 (no drift to follow) or when the iteration
  /// does not converge (the step is too long for the field where it is taken).
  void step(Momenta& x, double h);

  /// The last step's inner collocation points (its first and last excluded): their number, and the state at
  /// point j (1 <= j < inner_points() + 1) with its time from the step's start. The step's dense output: the
  /// converged iterate drifted there, as accurate as the step's end, at no force evaluation.
  [[nodiscard]] int inner_points() const { return points - 2; }
  [[nodiscard]] Momenta at_point(int j, double& tau) const;

  long evals = 0;          ///< force evaluations (F and its Jacobian at a point): points x evaluating iterations
  long iterations = 0;     ///< Picard iterations over all steps
  int points = 0;          ///< Chebyshev points of the last step

 private:
  /// F at R, its Jacobian into `jac`, and the distance to the nearest centre folded into `nearest`.
  Vec3 force(const Vec3& R, Eigen::Matrix3d& jac, double& nearest) const;
  const Nodes& nodes_for(int n);
  /// The Chebyshev degree n of a step h from x (points_for: the spin it turns, its closest pass); throws
  /// when more than kMaxPoints would be needed.
  int points_of_step(const Momenta& x, double h) const;
  /// The state drifted (the exact flow of the kinetic part) to tau from the pulled-back y = (yR, K1, yK2),
  /// with what the pull-back of the force reuses.
  struct Drifted {
    Vec3 R, K2, u, uxy, d;
    double kk, par, s, c;
  };
  Drifted drift(const Vec3& yR, const Vec3& K1, const Vec3& yK2, double tau) const;
  /// The pulled-back field G at the N points of the iterate Y (rows of Y_, G_): the force evaluated with its
  /// Jacobian (stored in lin_) where `evaluate`, otherwise linearised about the last evaluated points;
  /// `nearest` and `strongest` fold in the nearest centre and the largest force met.
  void pulled_back_field(const Nodes& nd, int N, double h, bool evaluate, double& nearest, double& strongest);

  using Block = Eigen::Matrix<double, Eigen::Dynamic, 9>;  ///< a row per point: y_R, y_K1, y_K2
  BodyPoint p_;
  std::vector<Centre> centres_;
  double inv_D_, spin_;  ///< 1/D and B/D
  double h_ = 0.0;       ///< the last step
  std::map<int, Nodes> nodes_;
  Block Y_, G_, next_;   ///< the iterate, its field and the next iterate: grown, never shrunk (no
                         ///< allocation inside a run's step loop once the largest step was taken)
  Eigen::Matrix<double, Eigen::Dynamic, 15> lin_;  ///< per point: R, F(R) and the Jacobian (row-major)
};

}  // namespace bodypoint::far_field

// bodypoint: the far-field collocation step (far_field.hpp).
#include "bodypoint/far_field.hpp"

#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace bodypoint::far_field {

Nodes chebyshev_nodes(int n) {
  // x_i = cos(theta_i), theta_i = pi (n - i)/n: increasing from -1 to 1; T_k(x_i) = cos(k theta_i).
  const int N = n + 1;
  Eigen::VectorXd theta(N);
  for (int i = 0; i < N; ++i) theta(i) = M_PI * static_cast<double>(n - i) / static_cast<double>(n);
  Eigen::MatrixXd V(N, N), I(N, N);  // values of T_k; integrals of T_k from -1
  for (int i = 0; i < N; ++i) {
    const double x = std::cos(theta(i));
    for (int k = 0; k < N; ++k) {
      V(i, k) = std::cos(k * theta(i));
      if (k == 0) {
        I(i, k) = x + 1.0;
      } else if (k == 1) {
        I(i, k) = 0.5 * (x * x - 1.0);
      } else {
        // int T_k = T_{k+1}/(2 (k+1)) - T_{k-1}/(2 (k-1)), and T_j(-1) = (-1)^j.
        const double up = 1.0 / (k + 1), down = 1.0 / (k - 1);
        const double sign = (k % 2 == 0) ? -1.0 : 1.0;  // (-1)^(k+1) = (-1)^(k-1)
        I(i, k) = 0.5 * (std::cos((k + 1) * theta(i)) * up - std::cos((k - 1) * theta(i)) * down) -
                  0.5 * sign * (up - down);
      }
    }
  }
  Nodes nd;
  nd.sigma = 0.5 * (theta.array().cos() + 1.0).matrix();
  nd.sigma(0) = 0.0;
  nd.sigma(n) = 1.0;
  // Values -> Chebyshev coefficients (V^-1) -> integrals from -1; d sigma = dx/2.
  nd.Q = 0.5 * I * V.partialPivLu().inverse();
  return nd;
}

int points_for(double angle, double ratio) {
  int harmonics = kMaxHarmonic;
  if (ratio <= 0.0) harmonics = kMinHarmonic;
  else if (ratio < 1.0) harmonics = static_cast<int>(std::ceil(std::log(kAliasShare) / std::log(ratio)));
  harmonics = std::clamp(harmonics + 1, kMinHarmonic, kMaxHarmonic);  // + 1: the pull-back's shift
  const double wanted = std::ceil(0.5 * harmonics * angle) + kExtraPoints;
  if (!(wanted <= kMaxPoints)) return -1;
  return std::max(kMinPoints, static_cast<int>(wanted));
}

Stepper::Stepper(const BodyPoint& p, std::vector<Centre> centres)
    : p_(p), centres_(std::move(centres)), inv_D_(1.0 / p.D()), spin_(p.B / p.D()) {}

const Nodes& Stepper::nodes_for(int n) {
  auto it = nodes_.find(n);
  if (it == nodes_.end()) it = nodes_.emplace(n, chebyshev_nodes(n)).first;
  return it->second;
}

Vec3 Stepper::force(const Vec3& R, Eigen::Matrix3d& jac, double& nearest) const {
  Vec3 F = Vec3::Zero();
  jac.setZero();
  for (const Centre& k : centres_) {
    const Vec3 d = R - k.c;
    const double r2 = d.squaredNorm(), inv_r = 1.0 / std::sqrt(r2);
    const double inv_r3 = inv_r * inv_r * inv_r, inv_r5 = inv_r3 * inv_r * inv_r;
    F -= (k.A * inv_r3) * d;
    // grad F = -A (I/r^3 - 3 d d^T/r^5)
    jac.diagonal().array() -= k.A * inv_r3;
    jac.noalias() += (3.0 * k.A * inv_r5) * (d * d.transpose());
    nearest = std::min(nearest, r2 * inv_r);
  }
  return F;
}

int Stepper::points_of_step(const Momenta& x, double h) const {
  const double angle = std::abs(spin_) * x.K1.norm() * h;  // spin turned by the step, radians
  // The helix's radius over the closest the step comes to a centre: the guiding centre's straight path
  // over the step (the force bends it little where the step is long), less the radius.
  const Helix helix = helix_of(p_, x);
  double closest = std::numeric_limits<double>::infinity();
  for (const Centre& k : centres_)
    if (k.A != 0.0) closest = std::min(closest, path_distance(helix, k.c, h) - helix.radius);  // A = 0: no field
  const int n = points_for(angle, closest > 0.0 ? helix.radius / closest : 1.0);
  if (n < 0)
    throw Error("far-ip: a step of h = " + detail::short_number(h) + " at |R| = " + detail::short_number(x.R.norm()) +
                " is too long for the spin there: it turns it by " + detail::short_number(angle) + " rad, more than " +
                std::to_string(kMaxPoints) + " points resolve; take a smaller step");
  return n;
}

Stepper::Drifted Stepper::drift(const Vec3& yR, const Vec3& K1, const Vec3& yK2, double tau) const {
  Drifted z;
  z.kk = K1.norm();
  z.u = K1 / z.kk;
  const double theta = spin_ * z.kk * tau;  // y's K2 is K2 turned back by theta about u
  z.s = std::sin(theta);
  z.c = std::cos(theta);
  z.uxy = z.u.cross(yK2);
  z.par = z.u.dot(yK2);
  z.K2 = z.c * yK2 - z.s * z.uxy + (z.par * (1.0 - z.c)) * z.u;
  const Vec3 Vg = (p_.J * K1 - (p_.B * z.par) * z.u) * inv_D_;  // the guiding centre's velocity
  z.d = z.K2 - yK2;
  z.R = yR + tau * Vg - K1.cross(z.d) / (z.kk * z.kk);
  return z;
}

void Stepper::pulled_back_field(const Nodes& nd, int N, double h, bool evaluate, double& nearest, double& strongest) {
  for (int j = 0; j < N; ++j) {
    const double tau = h * nd.sigma(j);
    const Vec3 yR = Y_.block<1, 3>(j, 0).transpose(), K1 = Y_.block<1, 3>(j, 3).transpose(),
               yK2 = Y_.block<1, 3>(j, 6).transpose();
    const Drifted z = drift(yR, K1, yK2, tau);
    Vec3 F;
    if (evaluate) {
      Eigen::Matrix3d jac;
      F = force(z.R, jac, nearest);
      strongest = std::max(strongest, F.norm());
      lin_.block<1, 3>(j, 0) = z.R.transpose();
      lin_.block<1, 3>(j, 3) = F.transpose();
      lin_.block<1, 9>(j, 6) = Eigen::Map<const Eigen::Matrix<double, 1, 9>>(jac.data());
    } else {
      const Eigen::Matrix<double, 1, 9> stored = lin_.block<1, 9>(j, 6);
      const Eigen::Map<const Eigen::Matrix3d> jac(stored.data());
      F = lin_.block<1, 3>(j, 3).transpose() + jac * (z.R - lin_.block<1, 3>(j, 0).transpose());
    }
    const double uF = z.u.dot(F);
    const Vec3 du = (F - uF * z.u) / z.kk;
    const Vec3 dK2 = (spin_ * tau * uF) * z.uxy + z.s * du.cross(z.K2) + (1.0 - z.c) * (z.par * du + du.dot(z.K2) * z.u);
    const Vec3 dVg = (p_.J * F - p_.B * (du.dot(z.K2) * z.u + z.par * du)) * inv_D_;
    const double k2 = z.kk * z.kk;
    const Vec3 dR = -tau * dVg + (F.cross(z.d) - K1.cross(dK2)) / k2 - (2.0 * K1.dot(F) / (k2 * k2)) * K1.cross(z.d);
    G_.block<1, 3>(j, 0) = dR.transpose();
    G_.block<1, 3>(j, 3) = F.transpose();
    G_.block<1, 3>(j, 6) = dK2.transpose();
  }
}

void Stepper::step(Momenta& x, double h) {
  const double k1 = x.K1.norm();
  if (!(k1 > 0.0)) throw Error("far-ip follows the drift along K1 and needs |K1| > 0 (here the body is at rest)");
  const int n = points_of_step(x, h);
  const Nodes& nd = nodes_for(n);
  const int N = n + 1;
  points = N;
  h_ = h;
  if (Y_.rows() < N) {
    Y_.resize(N, 9);
    G_.resize(N, 9);
    next_.resize(N, 9);
    lin_.resize(N, 15);
  }
  auto Y = Y_.topRows(N);
  auto next = next_.topRows(N);
  Eigen::Matrix<double, 1, 9> y0;
  y0 << x.R.transpose(), x.K1.transpose(), x.K2.transpose();
  Y = y0.replicate(N, 1);
  // The change of an iteration is measured per part against that part's size: R against |R| and the
  // distance the step travels, K1 and K2 against their lengths.
  const double speed = ((p_.J * x.K1 - p_.B * x.K2) * inv_D_).norm();
  const double travel = x.R.norm() + h * speed;
  const double scale[3] = {travel > 0.0 ? travel : 1.0, k1, x.K2.norm() > 0.0 ? x.K2.norm() : 1.0};
  double previous = std::numeric_limits<double>::infinity();
  bool evaluate = true;  // false: the force linearised about the last evaluated points (kLinearRemainder)
  for (int it = 1;; ++it) {
    double nearest = std::numeric_limits<double>::infinity(), strongest = 0.0;
    pulled_back_field(nd, N, h, evaluate, nearest, strongest);
    if (evaluate) evals += N;
    ++iterations;
    next.noalias() = h * (nd.Q * G_.topRows(N));
    next.rowwise() += y0;
    double change = 0.0;
    for (int part = 0; part < 3; ++part)
      change = std::max(change, (next.middleCols<3>(3 * part) - Y.middleCols<3>(3 * part)).cwiseAbs().maxCoeff() / scale[part]);
    Y = next;
    if (change <= kConverged) break;
    // The next iterations move the points by about delta = change x scale: once the force's second-order
    // term over delta leaves less than kLinearRemainder of the state, it is linearised about these points.
    if (evaluate) {
      const double delta = change * scale[0] / nearest, impulse = h * strongest / k1;
      if (kSecondOrder * delta * delta * impulse <= kLinearRemainder) evaluate = false;
    }
    // A non-finite change is an iteration that ran away (it fails the comparisons below as NaN does).
    const bool stalled = it >= 2 && !(change <= 0.5 * previous);
    if (stalled || it >= kMaxIterations || !std::isfinite(change)) {
      if (change <= kRoundingChange) break;  // converged to rounding
      throw Error("far-ip: a step of h = " + detail::short_number(h) + " at |R| = " + detail::short_number(x.R.norm()) +
                  " is too long for the field there (its iteration changes the state by " + detail::short_number(change) +
                  " after " + std::to_string(it) + " iterations); take a smaller step");
    }
    previous = change;
  }
  const Drifted z = drift(Y.block<1, 3>(n, 0).transpose(), Y.block<1, 3>(n, 3).transpose(),
                          Y.block<1, 3>(n, 6).transpose(), h);
  x.R = z.R;
  x.K1 = Y.block<1, 3>(n, 3).transpose();
  x.K2 = z.K2;
}

Momenta Stepper::at_point(int j, double& tau) const {
  const Nodes& nd = nodes_.at(points - 1);
  tau = h_ * nd.sigma(j);
  const Vec3 K1 = Y_.block<1, 3>(j, 3).transpose();
  const Drifted z = drift(Y_.block<1, 3>(j, 0).transpose(), K1, Y_.block<1, 3>(j, 6).transpose(), tau);
  return Momenta{z.R, K1, z.K2};
}

}  // namespace bodypoint::far_field

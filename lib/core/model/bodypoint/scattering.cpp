// bodypoint: the observables of a scattering encounter (scattering.hpp; docs/physics.md, "Scattering").
#include "bodypoint/scattering.hpp"

#include "bodypoint/io.hpp"

#include "bodypoint/field.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "bodypoint/invariants.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <utility>

namespace bodypoint {

double angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

std::optional<Asymptote> kepler_asymptote(double mu, double kappa, const Vec3& X, const Vec3& P, bool outgoing) {
  const double r = X.norm(), E = P.squaredNorm() / (2.0 * mu) + kappa / r;
  if (!(E > 0.0) || !(r > 0.0)) return std::nullopt;
  const double p_inf = std::sqrt(2.0 * mu * E);
  const Vec3 Lv = X.cross(P);
  const Vec3 Avec = P.cross(Lv) + (mu * kappa / r) * X;
  Vec3 u = (outgoing ? mu * kappa : -mu * kappa) * Avec + p_inf * Lv.cross(Avec);
  // Avec = 0 only without a force (kappa = 0) on a line through the centre: the body moves along P.
  if (!(u.squaredNorm() > 0.0)) u = P;
  Asymptote a;
  a.direction = u.normalized();
  a.impact = a.direction.cross(Lv) / p_inf;
  a.p_inf = p_inf;
  a.v_inf = p_inf / mu;
  return a;
}

std::optional<Periapsis> kepler_periapsis(double mu, double kappa, const Vec3& X, const Vec3& P) {
  const double r = X.norm(), E = P.squaredNorm() / (2.0 * mu) + kappa / r;
  if (!(E > 0.0) || !(r > 0.0)) return std::nullopt;
  const double l2 = X.cross(P).squaredNorm();
  // E r^2 - kappa r - l^2/(2 mu) = 0 at the turning point (P perpendicular to X): the larger root,
  // written without cancellation for either sign of kappa.
  const double disc = std::sqrt(kappa * kappa + 2.0 * E * l2 / mu);
  Periapsis q;
  q.r = kappa >= 0.0 ? (kappa + disc) / (2.0 * E) : (l2 / mu) / (disc - kappa);
  const double v_inf = std::sqrt(2.0 * E / mu);
  if (kappa == 0.0) {  // a straight line
    q.dt = -X.dot(P) / mu / (v_inf * v_inf);
    return q;
  }
  // Hyperbolic anomaly H: r = a (e cosh H - s), s = +1 attracting, -1 repelling, a = |kappa|/(2E);
  // mean anomaly e sinh H - s H = n t (t from periapsis), n = v_inf/a; sinh H = X.P/(mu n a^2 e).
  const double a = std::abs(kappa) / (2.0 * E), n = v_inf / a;
  const double e = std::sqrt(1.0 + 2.0 * E * l2 / (mu * kappa * kappa));
  q.e = e;
  const double s = kappa < 0.0 ? 1.0 : -1.0;
  const double sinh_H = X.dot(P) / (mu * n * a * a * e);
  q.dt = -(e * sinh_H - s * std::asinh(sinh_H)) / n;
  return q;
}

std::optional<KeplerParticle> kepler_particle(const BodyPoint& p, const State& s, const Vec3& c) {
  const Momenta q = to_momenta(p, s);
  KeplerParticle k;
  k.P = q.K1;
  if (p.B == 0.0) {
    k.mu = p.m;
    k.X = s.R - c;
    return k;
  }
  const double K1sq = q.K1.squaredNorm();
  const double drift = p.J * K1sq - p.B * q.K2.dot(q.K1);  // u |K1| D
  if (!(K1sq > 0.0) || drift == 0.0 || !std::isfinite(drift)) return std::nullopt;
  // G moves at u K1/|K1|. Drifting against K1 (u < 0, a spin along K1 that outweighs it) it is a
  // particle of momentum -K1, which the field pushes the other way: kappa's sign turns.
  k.mu = p.D() * K1sq / std::abs(drift);
  k.X = s.R + q.K1.cross(q.K2) / K1sq - c;
  if (drift < 0.0) {
    k.P = -q.K1;
    k.kappa_sign = -1.0;
  }
  return k;
}

namespace {

/// The asymptote of a body about the centre at c (constant A). B = 0: its Kepler hyperbola's, exact. B != 0:
/// the direction from the guiding centre's hyperbola (mass mu = |K1|/u at the state), and the two numbers
/// that hyperbola would get wrong by O(1/r) from exact first integrals instead (docs/physics.md,
/// "Scattering"): the guiding centre's kinetic energy J P^2/(2D) - B k P/D + m|K2|^2/(2D) (k = K2.K1/|K1|,
/// an adiabatic invariant far away) is not P^2/(2 mu) with one mu, so the momentum at infinity P solves it
/// at the body's energy and the speed there is |J P - B k|/D; and G x K1 = K2Q - k K1/|K1| turns with K1,
/// so the impact is taken from the total angular momentum K2Q, which does not: direction x K2Q/P.
/// K1 less its quiver: the helix R = G + rho turns rho at Omega = -(B/D)|K1| K1/|K1|, so the force at R
/// carries (rho.grad) F(G) at the spin's frequency, and K1 = K1_mean + (W.grad) F(G) with W = -Omega x rho /
/// |Omega|^2 (the integral of rho over time). Its size, rho |grad F|/(|Omega| |K1|) of K1 (1.5e-8 at r = 200
/// on table 3.1), turned the asymptote's direction with the helix's phase: the deflection from a pair of
/// centres taken at r = 200, 100 and 800 on one run read 2.3e-9 and -1.2e-9 from the last.
Vec3 mean_momentum(const BodyPoint& p, const Momenta& q, const Vec3& G, const std::vector<Centre>& centres) {
  const double K1 = q.K1.norm(), rate = p.B / p.D() * K1;
  if (!(rate != 0.0) || !(K1 > 0.0)) return q.K1;
  const Vec3 Omega = -rate / K1 * q.K1, rho = -q.K1.cross(q.K2) / (K1 * K1);
  const Vec3 W = -Omega.cross(rho) / (rate * rate);
  Vec3 dK1 = Vec3::Zero();
  for (const Centre& c : centres) {
    const Vec3 d = G - c.c;
    const double r2 = d.squaredNorm(), r = std::sqrt(r2), r3 = r2 * r;
    dK1 += -c.A * (W / r3 - 3.0 * W.dot(d) * d / (r3 * r2));
  }
  return q.K1 - dK1;
}

std::optional<Asymptote> body_asymptote(const BodyPoint& p, const State& s, const std::vector<Centre>& centres,
                                        const Centre& c, const KeplerParticle& k, bool outgoing) {
  if (p.B == 0.0) return kepler_asymptote(k.mu, k.kappa(c.A), k.X, k.P, outgoing);
  const Momenta q = to_momenta(p, s);
  std::optional<Asymptote> a =
      kepler_asymptote(k.mu, k.kappa(c.A), k.X, k.kappa_sign * mean_momentum(p, q, k.X + c.c, centres), outgoing);
  if (!a) return a;
  const double K1 = q.K1.norm(), kpar = q.K2.dot(q.K1) / K1, D = p.D();
  const double E = energy(p, CentreList{centres}, s);
  const double disc = p.B * p.B * kpar * kpar + p.J * (2.0 * D * E - p.m * q.K2.squaredNorm());
  // The root on the guiding centre's branch: drifting along K1 (J P > B k) the larger, against it the smaller.
  const double P = disc >= 0.0 ? (p.B * kpar + k.kappa_sign * std::sqrt(disc)) / p.J : std::numeric_limits<double>::quiet_NaN();
  if (!(P > 0.0) || !std::isfinite(P) || (p.J * P - p.B * kpar) * k.kappa_sign <= 0.0) return a;  // the hyperbola's, then
  const Vec3 K2Q = total_angular_momentum(p, s, c.c);
  a->p_inf = P;
  a->v_inf = std::abs(p.J * P - p.B * kpar) / D;
  a->impact = k.kappa_sign * a->direction.cross(K2Q) / P;
  return a;
}

/// One leg's Coulomb time delay, -kappa/(mu v_inf^3) (1 + ln e) (scattering.hpp, time_delay), and for
/// a spinning body the term that makes the delay converge: the guiding centre's kinetic energy
/// (J P^2 - 2 B K2.K1/|K1| P)/(2D) is not P^2/(2 mu), so its time along a leg grows as
/// r/v + kappa J/(D v^3) ln r, not kappa/(mu v^3) ln r as the Kepler hyperbola's; the difference,
/// -kappa/v^3 (J/D - 1/mu) ln(2 r/a) at the leg's distance r (a = |kappa|/(mu v^2)), is added (0 for B = 0).
/// A guiding centre drifting against K1 (kappa_sign -1, kappa the leg's) slows as |K1| grows: s J/D.
double leg_delay(const BodyPoint& b, const KeplerParticle& k, double kappa, const Periapsis& q, double p_inf) {
  if (kappa == 0.0) return 0.0;
  const double v = p_inf / k.mu, v3 = v * v * v;
  const double a = std::abs(kappa) / (k.mu * v * v);
  const double spin = b.B == 0.0 ? 0.0 : -kappa / v3 * (k.kappa_sign * b.J / b.D() - 1.0 / k.mu) * std::log(2.0 * k.X.norm() / a);
  return -kappa / (k.mu * v3) * (1.0 + std::log(q.e)) + spin;
}

/// A spinning body's leg from its guiding centre's distance r out to infinity, as the averaged far field moves
/// it: G drifts at v(P) = (J P - B k)/D along K1, K1 is pushed by the force at G, so |G x K1| = l and the energy
/// h(P) - A/r with h(P) = (J P^2 - 2 B k P + m |K2|^2)/(2D) are kept, and dr/dt = v(P) sqrt(P^2 - l^2/r^2)/P.
/// leg_delay's Kepler hyperbola takes the mass mu = P/v(P) at r for the whole leg, so its time to infinity is
/// O(1/r) off for a dispersion h that is not P^2/(2 mu) (the time delay converged as 1/L: table 3.1 given by b = 3
/// and arrival phase 1, 3.3e-5 between the starts at L = 200 and 400, growing with k = K2.K1/|K1|, 0 for k = 0).
/// The leg's time must not depend on where it is cut (the run's time grows by dr/(dr/dt) as the cut moves out),
/// so the leg's value at r is that at a far cut r_f, less the averaged flight from r to r_f: the correction
/// C(r_f) + T(r, r_f) - C(r), C the Kepler value of a cut, taken at r_f = kLegFar r and 2 kLegFar r and
/// extrapolated in 1/r_f.
struct SpinLeg {
  const BodyPoint& p;
  double k, K2sq, E, A, l;
  /// |K1| at distance r on the guiding centre's branch (drifting along K1), or NaN.
  [[nodiscard]] double P(double r) const {
    const double disc = p.B * p.B * k * k - p.J * (p.m * K2sq - 2.0 * p.D() * (E + (r > 0.0 ? A / r : 0.0)));
    const double P = disc >= 0.0 ? (p.B * k + std::sqrt(disc)) / p.J : std::numeric_limits<double>::quiet_NaN();
    return P > 0.0 && p.J * P - p.B * k > 0.0 ? P : std::numeric_limits<double>::quiet_NaN();
  }
  [[nodiscard]] double v(double P) const { return (p.J * P - p.B * k) / p.D(); }
  /// The Kepler value of a cut at r: the time to the hyperbola's periapsis plus leg_delay, NaN where none.
  [[nodiscard]] double kepler_cut(double r) const {
    const double Pr = P(r), radial2 = Pr * Pr - l * l / (r * r);
    if (!(radial2 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    KeplerParticle kp;
    kp.mu = Pr / v(Pr);
    kp.X = Vec3(r, 0.0, 0.0);
    kp.P = Vec3(std::sqrt(radial2), l / r, 0.0);
    const double kappa = kp.kappa(A);
    const auto q = kepler_periapsis(kp.mu, kappa, kp.X, kp.P);
    return q ? q->dt + leg_delay(p, kp, kappa, *q, P(0.0)) : std::numeric_limits<double>::quiet_NaN();
  }
  /// The averaged flight's time from r0 to r1 less (r1 - r0)/v_inf: Gauss-Legendre panels in ln r.
  [[nodiscard]] double flight_less_free(double r0, double r1) const {
    static constexpr double x[4] = {0.3399810435848563, 0.8611363115940526, -0.3399810435848563, -0.8611363115940526};
    static constexpr double w[4] = {0.6521451548625461, 0.3478548451374538, 0.6521451548625461, 0.3478548451374538};
    const double v_inf = v(P(0.0)), span = std::log(r1 / r0);
    const int panels = std::max(1, static_cast<int>(std::ceil(span / kLegPanel)));
    const double width = span / panels;
    double sum = 0.0;
    for (int i = 0; i < panels; ++i)
      for (int j = 0; j < 4; ++j) {
        const double r = r0 * std::exp(width * (i + 0.5 + 0.5 * x[j])), Pr = P(r);
        const double rate = v(Pr) * std::sqrt(Pr * Pr - l * l / (r * r)) / Pr;
        sum += 0.5 * width * w[j] * r * (1.0 / rate - 1.0 / v_inf);
      }
    return sum;
  }
  /// C(r_f) + T(r, r_f) at r_f = far.
  [[nodiscard]] double cut_moved_out(double r, double far) const {
    return kepler_cut(far) + (far - r) / v(P(0.0)) + flight_less_free(r, far);
  }
  /// What leg_delay's hyperbola leaves of the leg's time at r (0 where the model has no leg there).
  [[nodiscard]] double correction(double r) const {
    const double near = kepler_cut(r);
    // Close to the periapsis (radial momentum small against P) the averaged flight is not a far field.
    if (!std::isfinite(near) || l > kLegRadial * P(r) * r) return 0.0;
    const double g1 = cut_moved_out(r, kLegFar * r), g2 = cut_moved_out(r, 2.0 * kLegFar * r);
    const double c = 2.0 * g2 - g1 - near;  // the cut's error falls as 1/r_f
    return std::isfinite(c) ? c : 0.0;
  }
  /// The far cut's distance (in units of r), the panels' width in ln r (4-point Gauss-Legendre: its error
  /// ~ (width/2)^8 / 8! of the integrand, which is smooth in ln r away from the periapsis), and the
  /// largest l/(P r) (the sine of the angle between K1 and G) where the correction is taken.
  static constexpr double kLegFar = 1e3, kLegPanel = 0.125, kLegRadial = 0.7;
};

/// The leg correction of one end of a spinning body's encounter (0 for B = 0 or a guiding centre drifting
/// against K1, where the hyperbola's mass is kept).
double spin_leg_correction(const BodyPoint& p, const State& s, const std::vector<Centre>& centres, const Centre& c,
                           const KeplerParticle& k) {
  if (p.B == 0.0 || k.kappa_sign < 0.0) return 0.0;
  const Momenta q = to_momenta(p, s);
  const SpinLeg leg{p, q.K2.dot(q.K1) / q.K1.norm(), q.K2.squaredNorm(), energy(p, CentreList{centres}, s), c.A,
                    k.X.cross(k.P).norm()};
  return leg.correction(k.X.norm());
}

}  // namespace

std::optional<Centre> far_field_centre(const std::vector<Centre>& centres) {
  if (centres.empty()) return std::nullopt;
  Centre k;
  double weight = 0.0;
  Vec3 weighted = Vec3::Zero(), plain = Vec3::Zero();
  for (const Centre& c : centres) {
    if (c.law != ForceLaw::coulomb) return std::nullopt;
    k.A += c.A;
    weight += std::abs(c.A);
    weighted += std::abs(c.A) * c.c;
    plain += c.c;
  }
  if (centres.size() == 1) return centres.front();
  k.c = weight > 0.0 ? Vec3(weighted / weight) : Vec3(plain / static_cast<double>(centres.size()));
  return k;
}

Scattering scattering(const BodyPoint& p, const std::vector<Centre>& centres, const State& start, const State& end,
                      double elapsed) {
  Scattering out;
  const Momenta q0 = to_momenta(p, start), q1 = to_momenta(p, end);
  out.K1_start = q0.K1;
  out.K1_end = q1.K1;
  out.K2_start = q0.K2;
  out.K2_end = q1.K2;
  const CentreList field{centres};
  out.E_start = energy(p, field, start);
  out.E_end = energy(p, field, end);
  out.K1_turn = angle_between(q0.K1, q1.K1);
  out.spin_turn = angle_between(q0.K2, q1.K2);
  if (centres.size() == 1) {
    out.has_K2Q = true;
    out.K2Q_start = total_angular_momentum(p, start, centres.front().c);
    out.K2Q_end = total_angular_momentum(p, end, centres.front().c);
  }
  const std::optional<Centre> far = far_field_centre(centres);
  if (!far) {
    out.asymptotes = centres.empty() ? "none: no centre" : "none: asymptotes need Coulomb's law";
    return out;
  }
  const Centre& k = *far;
  const auto in = kepler_particle(p, start, k.c), fin = kepler_particle(p, end, k.c);
  if (!in || !fin) {
    out.asymptotes = "none: the guiding centre does not drift (u = 0)";
    return out;
  }
  const double kappa_in = in->kappa(k.A), kappa_out = fin->kappa(k.A);
  out.in = body_asymptote(p, start, centres, k, *in, false);
  out.out = body_asymptote(p, end, centres, k, *fin, true);
  if (!out.in || !out.out) {
    out.asymptotes = "none: the orbit is bound (energy at infinity <= 0)";
    out.in.reset();
    out.out.reset();
    return out;
  }
  out.asymptotes = std::string(p.B == 0.0 ? "kepler" : "guiding-centre") +
                   (centres.size() > 1 ? " (about the centres' total charge at their centre)" : "");
  out.deflection = angle_between(out.in->direction, out.out->direction);
  out.b = out.in->b();
  out.v_inf = out.in->v_inf;
  const Vec3 normal = out.in->direction.cross(out.in->impact);
  out.out_of_plane = normal.squaredNorm() > 0.0 ? std::asin(std::clamp(out.out->direction.dot(normal.normalized()), -1.0, 1.0))
                                                : 0.0;
  const auto q_in = kepler_periapsis(in->mu, kappa_in, in->X, in->P);
  const auto q_out = kepler_periapsis(fin->mu, kappa_out, fin->X, fin->P);
  if (std::isfinite(elapsed) && q_in && q_out)
    out.time_delay = elapsed - q_in->dt + q_out->dt + leg_delay(p, *in, kappa_in, *q_in, out.in->p_inf) +
                     leg_delay(p, *fin, kappa_out, *q_out, out.out->p_inf) + spin_leg_correction(p, start, centres, k, *in) +
                     spin_leg_correction(p, end, centres, k, *fin);
  return out;
}

namespace {

/// Secant iterations stop when d changes by less than this relative amount: b(d) is then exact to
/// round-off (the map is smooth and close to a shift, db/dd ~ 1).
constexpr double kImpactRelTol = 1e-14;
constexpr int kImpactIterations = 60;

/// The incoming asymptote of the thesis's scene with parameters p and the mass of its Kepler particle,
/// or why the scene has none.
struct Incoming {
  std::optional<Asymptote> asymptote;
  double mu = 0.0;
  std::string why;
};
Incoming incoming(const SceneParams& p) {
  if (std::string why = why_invalid(p); !why.empty()) return {std::nullopt, 0.0, std::move(why)};  // a secant's trial
  const Scene s = thesis_scene(p);
  const Body& body = s.bodies.front();
  const auto k = kepler_particle(body.p, body.s0, s.centres.front().c);
  if (!k) return {std::nullopt, 0.0, "the scene's body does not drift along K1: it has no incoming asymptote"};
  // An encounter needs the guiding centre to approach the centre: drifting away from the start (K1 below
  // the drift's zero, B Kx/J, where it drifts against K1), it has no periapsis ahead and no incoming leg.
  if (!(k->X.dot(k->P) < 0.0))
    return {std::nullopt, 0.0, "the scene's guiding centre drifts away from the centre at the start: no encounter happens"};
  const auto a = body_asymptote(body.p, body.s0, s.centres, s.centres.front(), *k, false);
  if (!a) return {std::nullopt, 0.0, "the scene's orbit is bound (energy at infinity <= 0): it has no incoming asymptote"};
  return {*a, k->mu, ""};
}

/// A datum of the incoming asymptote at p (b, or the speed at infinity); nothing, with `why`, where the
/// scene has no incoming asymptote.
using Datum = std::optional<double> (*)(const SceneParams&, std::string& why);
std::optional<double> b_of(const SceneParams& p, std::string& why) {
  const Incoming in = incoming(p);
  why = in.why;
  return in.asymptote ? std::optional<double>(in.asymptote->b()) : std::nullopt;
}
std::optional<double> v_of(const SceneParams& p, std::string& why) {
  const Incoming in = incoming(p);
  why = in.why;
  return in.asymptote ? std::optional<double>(in.asymptote->v_inf) : std::nullopt;
}
/// f at p, or why it is not defined there.
Expected<double> defined(Datum f, const SceneParams& p) {
  std::string why;
  if (const std::optional<double> x = f(p, why)) return *x;
  return Expected<double>::failure(why);
}

/// Secant iterations on one scene parameter x (field) for f(x) = target, from x0 (where f is defined)
/// and x1. A trial where f is not defined (a scene without an incoming asymptote: K1 so small that the
/// body does not drift along it) is pulled halfway back to the last point where it was, so that the
/// secant approaches the edge of the admissible range instead of giving up (v_inf = 0.5 on table 3.1:
/// the first guess K1 = 0.35 does not drift, the answer K1 = 1.65 does).
/// f must be defined at x0: the answer is why not otherwise (as where no trial was).
Expected<double> solve_parameter(SceneParams params, double& (*field)(SceneParams&), Datum f, double target, double x0,
                                 double x1) {
  field(params) = x0;
  const Expected<double> at_x0 = defined(f, params);
  if (!at_x0) return at_x0;
  double f0 = *at_x0 - target;
  std::string why;
  for (int i = 0; i < kImpactIterations; ++i) {
    if (!std::isfinite(x1)) return x1;  // the secant left the numbers: the caller says which datum
    field(params) = x1;
    const std::optional<double> y = f(params, why);
    if (!y) {
      if (i + 1 == kImpactIterations) return Expected<double>::failure(why);
      x1 = 0.5 * (x0 + x1);
      continue;
    }
    const double f1 = *y - target;
    if (f1 == 0.0 || std::abs(x1 - x0) <= kImpactRelTol * std::max(std::abs(x1), std::abs(target))) return x1;
    const double slope = (f1 - f0) / (x1 - x0);
    x0 = x1;
    f0 = f1;
    x1 = x1 - (std::isfinite(slope) && slope != 0.0 ? f1 / slope : f1);
  }
  return x1;
}

double& d_of(SceneParams& p) { return p.start.d; }
double& k1_of(SceneParams& p) { return p.start.K1; }

}  // namespace

namespace {

/// The guiding centre's far-field model from the thesis's start (centre at the origin): G moves at
/// u K1/|K1| with u = (J |K1| - B k)/D (k = K2.K1/|K1|, constant far away) and K1 feels the force at G,
/// while the helix turns about K1 at -(B/D)|K1|. Integrated by RK4 in the transformed time
/// dt/ds = |G|/|u| (steps of ds move G by a fixed fraction of its distance) until G's periapsis (or
/// the turn where u changes sign): returns the helix's turn on the way, -(B/D) int |K1| dt.
constexpr double kPhaseStep = 2e-3;     ///< ds: RK4's error per unit ln r is ~ds^4, far below 1e-10 rad
/// Near a head-on periapsis the force turns K1 in a time over which G barely moves (|K1| and u small): a
/// step of ds = 2e-3 there changed K1 by far more than 2e-3 of itself, and the arrival phase came out
/// 6.2e-3 rad off (B = 0.5, d = 0.03163, L = 400: 1.324058 for 1.330283), which moved the scattering
/// study's start and its deflection by 3e-5, out of its stated error. Each step also changes K1 by at
/// most this fraction of itself (a kick dt |F| <= kPhaseKick |K1|).
constexpr double kPhaseKick = 2e-3;
constexpr long kPhaseMaxSteps = 5000000;  ///< ~ln(r0/r_min)/ds steps; beyond: no periapsis (error)

struct GuidingModel {
  double A, B, J, D, k;
  struct Y {
    Vec3 G, K;
    double phase;
  };
  [[nodiscard]] double u(const Y& y) const { return (J * y.K.norm() - B * k) / D; }
  [[nodiscard]] double dt_ds(const Y& y, double u_floor) const { return y.G.norm() / std::max(std::abs(u(y)), u_floor); }
  /// dy/ds.
  [[nodiscard]] Y rate(const Y& y, double u_floor) const {
    const double P = y.K.norm(), r = y.G.norm(), ts = dt_ds(y, u_floor);
    return {u(y) / P * y.K * ts, -A / (r * r * r) * y.G * ts, -B / D * P * ts};
  }
  [[nodiscard]] Y step(const Y& y, double ds, double u_floor) const {
    const auto add = [](const Y& a, const Y& d, double f) { return Y{a.G + f * d.G, a.K + f * d.K, a.phase + f * d.phase}; };
    const Y k1 = rate(y, u_floor), k2 = rate(add(y, k1, ds / 2), u_floor), k3 = rate(add(y, k2, ds / 2), u_floor),
            k4 = rate(add(y, k3, ds), u_floor);
    return Y{y.G + ds / 6 * (k1.G + 2 * k2.G + 2 * k3.G + k4.G), y.K + ds / 6 * (k1.K + 2 * k2.K + 2 * k3.K + k4.K),
             y.phase + ds / 6 * (k1.phase + 2 * k2.phase + 2 * k3.phase + k4.phase)};
  }
  /// The step in s: kPhaseStep, or less where the force would change K by more than kPhaseKick of itself.
  [[nodiscard]] double ds(const Y& y, double u_floor) const {
    const double r = y.G.norm(), kick = std::abs(A) / (r * r) * dt_ds(y, u_floor);  // |dK/ds|
    return kick > 0.0 ? std::min(kPhaseStep, kPhaseKick * y.K.norm() / kick) : kPhaseStep;
  }
  /// G.dG/dt: < 0 on the way in.
  [[nodiscard]] double radial(const Y& y) const { return u(y) * y.G.dot(y.K); }
};

/// Number of halvings that locate the periapsis inside its last step (ds 2e-3 / 2^40: to round-off).
constexpr int kPhaseBisections = 40;

Expected<double> helix_turn_to_periapsis(const SceneParams& p) {
  const Momenta q = thesis_momenta(p.start);
  const double D = p.m * p.J - p.B * p.B;
  GuidingModel model{p.A, p.B, p.J, D, q.K2.dot(q.K1) / q.K1.norm()};
  GuidingModel::Y y{q.R + q.K1.cross(q.K2) / q.K1.squaredNorm(), q.K1, 0.0};
  const double u_floor = 1e-3 * std::abs(model.u(y));
  if (!(u_floor > 0.0)) return Expected<double>::failure("the guiding centre does not drift (u = 0): it has no arrival phase");
  if (!(model.radial(y) < 0.0)) return 0.0;  // not approaching: the start is its arrival
  for (long i = 0; i < kPhaseMaxSteps; ++i) {
    const double ds = model.ds(y, u_floor);
    const GuidingModel::Y next = model.step(y, ds, u_floor);
    if (model.radial(next) >= 0.0) {
      double lo = 0.0, hi = ds;
      for (int it = 0; it < kPhaseBisections; ++it) {
        const double mid = 0.5 * (lo + hi);
        (model.radial(model.step(y, mid, u_floor)) < 0.0 ? lo : hi) = mid;
      }
      return model.step(y, hi, u_floor).phase;
    }
    y = next;
  }
  return Expected<double>::failure("the guiding centre reaches no periapsis: the scene has no arrival phase");
}

double wrapped(double angle) {
  const double two_pi = 2.0 * std::numbers::pi;
  const double w = std::fmod(angle, two_pi);
  return w < 0.0 ? w + two_pi : w;
}

}  // namespace

Expected<double> solve_arrival_phase(const SceneParams& params) {
  const Expected<double> turn = helix_turn_to_periapsis(params);
  if (!turn) return turn;
  return wrapped(params.start.phase + *turn);
}

double arrival_phase(const SceneParams& params) { return solve_arrival_phase(params).value(); }

namespace {

Expected<double> solve_start_phase(const SceneParams& params, double arrival) {
  if (!std::isfinite(arrival)) return Expected<double>::failure("the arrival phase must be a finite number (rad)");
  SceneParams at_zero = params;
  at_zero.start.phase = 0.0;
  const Expected<double> turn = helix_turn_to_periapsis(at_zero);
  if (!turn) return turn;
  return wrapped(arrival - *turn);
}

Expected<double> solve_d(SceneParams params, double b) {
  if (!(std::isfinite(b) && b > 0.0)) return Expected<double>::failure("the impact parameter b must be a finite number > 0");
  const std::string none = "no start distance d gives the impact parameter b = " + fmt(b);
  const double d0 = params.B == 0.0 ? params.start.Kz / params.start.K1 + b : b;
  params.start.d = d0;
  const Expected<double> b0 = defined(b_of, params);
  const Expected<double> d = b0 ? solve_parameter(params, d_of, b_of, b, d0, d0 - (*b0 - b)) : b0;  // db/dd ~ 1
  // The scene at the first guess has no incoming asymptote, or cannot be built; or the secant overflowed.
  if (!d) return Expected<double>::failure(none + ": " + d.error());
  if (!std::isfinite(*d)) return Expected<double>::failure(none + " (the scene's numbers overflow on the way; give a smaller b)");
  return d;
}

/// The first K1 the search for v_inf starts from: the scene's own where it approaches the centre,
/// otherwise twice the drift's zero (v is 0 at the zero and grows with K1: one root on the branch).
constexpr double kApproachingStart = 2.0;

Expected<double> solve_k1(SceneParams params, double v_inf) {
  if (!(std::isfinite(v_inf) && v_inf > 0.0))
    return Expected<double>::failure("the speed at infinity v_inf must be a finite number > 0");
  // Only the branch on which the guiding centre drifts towards the centre has an encounter: below the
  // drift's zero it drifts away, its "incoming" asymptote a leg it never travels (v_inf = 1 on table 3.1
  // solved K1 = 0.884 there). incoming() refuses that branch, so a secant trial on it is pulled back.
  const double k_min = least_approaching_k1(params);
  if (!(params.start.K1 > k_min)) params.start.K1 = k_min > 0.0 ? kApproachingStart * k_min : 1.0;
  const double k0 = params.start.K1;
  const Expected<double> v0 = defined(v_of, params);
  if (!v0) return v0;
  const Expected<double> k = solve_parameter(params, k1_of, v_of, v_inf, k0, k0 * v_inf / *v0);  // v_inf ~ K1 / mass
  if (!k) return k;
  if (!(std::isfinite(*k) && *k > k_min))
    return Expected<double>::failure("no momentum K1 above " + fmt(k_min) +
                                     " (where the guiding centre approaches the centre) gives the speed at infinity v_inf = " +
                                     fmt(v_inf));
  return k;
}

}  // namespace

Expected<double> incoming_speed(const SceneParams& p) { return defined(v_of, p); }

double speed_at_infinity_of(const SceneParams& p) {
  // K2.K1/|K1| = Kx at the start (the phase turns K2 about K1 = K1 i): the guiding centre's speed at momentum K1.
  const double v = p.B == 0.0 ? p.start.K1 / p.m : (p.J * p.start.K1 - p.B * p.start.Kx) / (p.m * p.J - p.B * p.B);
  return v > 0.0 ? v : std::numeric_limits<double>::quiet_NaN();
}

double least_approaching_k1(const SceneParams& p) { return std::max(0.0, p.B * p.start.Kx / p.J); }

double start_phase_for_arrival(const SceneParams& params, double arrival) { return solve_start_phase(params, arrival).value(); }

double d_for_impact_parameter(SceneParams params, double b) { return solve_d(std::move(params), b).value(); }

double k1_for_speed_at_infinity(SceneParams params, double v_inf) { return solve_k1(std::move(params), v_inf).value(); }

Expected<SceneParams> solve_asymptotic_data(SceneParams params, double b, double v_inf, double arrival) {
  // Each datum depends a little on the others' parameters through the start at finite distance L: b and
  // v_inf on the start phase too (the body's place on its helix sets its potential energy and K2Q). So
  // all are solved in turn until none moves; one datum given is one solve.
  // An encounter given by its impact parameter has its L -> infinity limit at a fixed momentum at infinity:
  // the scene's K1 is read as that momentum (its speed there, speed_at_infinity_of), not as K1 at the start,
  // which moves the speed at infinity by O(1/L) (the potential at L is part of the start's energy).
  if (std::isnan(v_inf) && !std::isnan(b)) v_inf = speed_at_infinity_of(params);
  const int given = !std::isnan(b) + !std::isnan(v_inf) + !std::isnan(arrival);
  for (int i = 0; i < kImpactIterations; ++i) {
    const SceneParams before = params;
    if (!std::isnan(v_inf)) {
      const Expected<double> k = solve_k1(params, v_inf);
      if (!k) return Expected<SceneParams>::failure(k.error());
      params.start.K1 = *k;
    }
    if (!std::isnan(b)) {
      const Expected<double> d = solve_d(params, b);
      if (!d) return Expected<SceneParams>::failure(d.error());
      params.start.d = *d;
    }
    if (!std::isnan(arrival)) {
      const Expected<double> phase = solve_start_phase(params, arrival);
      if (!phase) return Expected<SceneParams>::failure(phase.error());
      params.start.phase = *phase;
    }
    const auto still = [](double x, double y, double scale) { return std::abs(x - y) <= kImpactRelTol * scale; };
    if (given <= 1 || (still(params.start.K1, before.start.K1, params.start.K1) &&
                       still(params.start.d, before.start.d, std::max(params.start.d, std::isnan(b) ? 0.0 : b)) &&
                       still(params.start.phase, before.start.phase, 2.0 * std::numbers::pi)))
      break;
  }
  return params;
}

SceneParams with_asymptotic_data(SceneParams params, double b, double v_inf, double arrival) {
  return solve_asymptotic_data(std::move(params), b, v_inf, arrival).value();
}

SceneParams with_asymptotic_data(SceneParams params, double b, double v_inf) {
  return with_asymptotic_data(std::move(params), b, v_inf, std::numeric_limits<double>::quiet_NaN());
}

void check_data_beside_solved(const std::vector<std::string>& data, const std::vector<std::string>& given) {
  const auto has = [](const std::vector<std::string>& names, std::string_view name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  for (const auto& [datum, solved] : {std::pair{"b", "d"}, {"v_inf", "K1"}, {"arrival_phase", "phase"}})
    if (has(data, datum) && has(given, solved))
      throw Error(std::string("give ") + datum + " or " + solved + ", not both (" + datum + " solves " + solved + ")");
}

SceneParams with_asymptotic_data(const SceneParams& params, const AsymptoticData& data,
                                 const std::vector<std::string>& given) {
  std::vector<std::string> named;
  if (data.b) named.emplace_back("b");
  if (data.v_inf) named.emplace_back("v_inf");
  if (data.arrival_phase) named.emplace_back("arrival_phase");
  check_data_beside_solved(named, given);
  if (data.b) require_positive(*data.b, "the impact parameter b");
  if (data.v_inf) require_positive(*data.v_inf, "the speed at infinity v_inf");
  if (data.arrival_phase && !std::isfinite(*data.arrival_phase)) throw Error("the arrival phase arrival_phase must be a finite number");
  if (!data.b && !data.v_inf && !data.arrival_phase) return params;
  validate(thesis_scene(params));  // the scene's own errors first, in their words
  constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  return with_asymptotic_data(params, data.b.value_or(kNone), data.v_inf.value_or(kNone), data.arrival_phase.value_or(kNone));
}

}  // namespace bodypoint

// bodypoint: `--method auto`, the method for a scene and a tolerance (methods.hpp).
#include "bodypoint/methods.hpp"

#include "choice.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/adaptive/tolerance.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace bodypoint {
namespace {

/// auto's table: Yoshida 4 from this tolerance up, Kahan-Li 6 from kTightTolerance, Kahan-Li 8 below.
constexpr double kLooseTolerance = 1e-5;
constexpr double kTightTolerance = 1e-10;

/// auto takes a fixed step when the potential at the estimated closest approach is below this
/// fraction of the time-step constant c: the time transformation would then change the step by < 10%.
constexpr double kFarFraction = 0.1;

/// Straight-line estimate of the closest approach to c. A spinning body does not travel along v,
/// which precesses about K1: far from the centres it follows a helix whose axis passes through the
/// guiding centre R + K1 x K2/|K1|^2 along K1, at the speed (J |K1| - B K2.K1/|K1|)/D (the kinetic
/// drift, docs/physics.md). For B = 0 that is the line along v.
double closest_approach(const Body& b, const Centre& c) {
  const Momenta q = to_momenta(b.p, b.s0);
  const double k2 = q.K1.squaredNorm();
  if (!(k2 > 0.0)) return (b.s0.R - c.c).norm();  // no drift
  const Vec3 axis = q.K1 / std::sqrt(k2);
  const double speed = (b.p.J * std::sqrt(k2) - b.p.B * q.K2.dot(axis)) / b.p.D();
  const Vec3 d = b.s0.R + q.K1.cross(q.K2) / k2 - c.c;
  const Vec3 u = speed >= 0.0 ? axis : Vec3(-axis);
  if (d.dot(u) >= 0.0 || speed == 0.0) return d.norm();  // moving away, or at rest
  return d.cross(u).norm();
}

}  // namespace

const MethodInfo& choose_method(const Body& body, const std::vector<Centre>& centres, double tol, std::string* why) {
  adaptive::check_tolerance(tol);
  return detail::choose_method_for(body, centres, tol, why);
}

const MethodInfo& detail::choose_method_for(const Body& body, const std::vector<Centre>& centres, double tol,
                                            std::string* why) {
  // The table by tolerance, measured (logh on the close, thesis and two-centres scenes, force
  // evaluations of the whole search): Yoshida 4 (3 stages) is cheapest down to 1e-5 (thesis 3,648
  // against 10,944 for Kahan-Li 6), Kahan-Li 6 down to 1e-10 (close 1e-9: 21,690 against 33,218 for
  // Kahan-Li 8), Kahan-Li 8 below.
  const char* table = tol >= kLooseTolerance ? "y4" : tol >= kTightTolerance ? "kl6" : "kl8";
  std::ostringstream os;
  bool repulsive = true;
  double potential_at_closest = 0.0;
  for (const Centre& c : centres) {
    repulsive = repulsive && c.A < 0.0;
    potential_at_closest += std::abs(c.A) / std::max(closest_approach(body, c), 1e-300);
  }
  const double c = adaptive::automatic_omega_c(body, centres, 0.0);
  std::string name;
  if (body.p.B == 0.0 && centres.size() == 1) {
    name = "ks";
    os << "ks: a material point and one centre (exact Kepler/Rutherford flow)";
  } else if (c > 0.0 && potential_at_closest < kFarFraction * c) {
    name = std::string("lp-") + table;
    os << name << ": the body stays far from every centre (sum |A|/r_min ~ " << potential_at_closest
       << " < c/10 = " << 0.1 * c << ", so a time transformation would hardly change the step)";
  } else if (repulsive) {
    name = std::string("logh-") + table;
    os << name << ": every centre repels (logarithmic Hamiltonian, step ~ distance to the centres)";
  } else {
    name = std::string("ttl-") + table;
    os << name << ": an attracting centre (time-transformed leapfrog, step ~ distance to the centres)";
  }
  if (name != "ks")
    os << "; " << (tol >= kLooseTolerance ? "Yoshida 4 for tol >= 1e-5"
                   : tol >= kTightTolerance ? "Kahan-Li 6 for 1e-10 <= tol < 1e-5" : "Kahan-Li 8 for tol < 1e-10");
  if (why) *why = os.str();
  return method_or_throw(name);
}

}  // namespace bodypoint

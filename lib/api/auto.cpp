// bodypoint: `--method auto`, the method for a scene and a tolerance (methods.hpp).
#include "bodypoint/methods.hpp"

#include "choice.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/adaptive/tolerance.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace bodypoint {
namespace {

/// auto's table: Yoshida 4 from this tolerance up, Kahan-Li 6 from kTightTolerance, Kahan-Li 8 below. Each
/// constant's measurement: docs/developers.md, "Tuned constants".
constexpr double kLooseTolerance = 1e-5;
constexpr double kTightTolerance = 1e-10;

/// auto takes a fixed step when the potential at the estimated closest approach is below this
/// fraction of the time-step constant c: the time transformation would then change the step by < 10%.
constexpr double kFarFraction = 0.1;

}  // namespace

const MethodInfo& choose_method(const Body& body, const std::vector<Centre>& centres, double tol, std::string* why) {
  adaptive::check_tolerance(tol);
  return detail::choose_method_for(body, centres, tol, why);
}

const MethodInfo& detail::choose_method_for(const Body& body, const std::vector<Centre>& centres, double tol,
                                            std::string* why) {
  // The table by tolerance (docs/developers.md, "Tuned constants"): Yoshida 4 (3 stages) down to 1e-5,
  // Kahan-Li 6 down to 1e-10, Kahan-Li 8 below.
  const std::string_view table = tol >= kLooseTolerance ? "y4" : tol >= kTightTolerance ? "kl6" : "kl8";
  std::ostringstream os;
  double potential_at_closest = 0.0;  // at the guiding centre's closest approach to each centre
  const Helix helix = helix_of(body.p, to_momenta(body.p, body.s0));
  for (const Centre& c : centres)
    potential_at_closest += std::abs(c.A) / std::max(path_distance(helix, c.c, std::numeric_limits<double>::infinity()), 1e-300);
  const double c = adaptive::automatic_omega_c(body, centres, 0.0);
  // What each branch needs is asked of the catalogue: the regularised flow where it accepts the scene (a
  // material point, one centre), the Lie-Poisson splitting far from every centre, else the first
  // time-transformed method of the table that accepts the scene (logH before TTL: logH refuses attraction).
  const MethodInfo* m = method_of(Family::Regularised, "", body, centres);
  if (m && refusal(*m, body, centres).empty()) {
    os << m->name << ": a material point and one centre (exact Kepler/Rutherford flow)";
  } else if (c > 0.0 && potential_at_closest < kFarFraction * c) {
    m = method_of(Family::LiePoisson, table, body, centres);
    os << m->name << ": the body stays far from every centre (sum |A|/r_min ~ " << potential_at_closest
       << " < c/10 = " << 0.1 * c << ", so a time transformation would hardly change the step)";
  } else {
    m = method_of(Family::TimeTransformed, table, body, centres);
    os << m->name << (all_repulsive(centres) ? ": every centre repels (logarithmic Hamiltonian, step ~ distance to the centres)"
                                             : ": an attracting centre (time-transformed leapfrog, step ~ distance to the centres)");
  }
  if (m->table == table)
    os << "; " << (tol >= kLooseTolerance ? "Yoshida 4 for tol >= 1e-5"
                   : tol >= kTightTolerance ? "Kahan-Li 6 for 1e-10 <= tol < 1e-5" : "Kahan-Li 8 for tol < 1e-10");
  if (why) *why = os.str();
  return *m;
}

}  // namespace bodypoint

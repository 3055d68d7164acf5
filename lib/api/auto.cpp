// bodypoint: `--method auto`, the method for a scene and a tolerance (methods.hpp).
#include "bodypoint/methods.hpp"

#include "choice.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "bodypoint/detail/run_support.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string_view>

namespace bodypoint {
namespace {

/// What auto's whole search costs with each composition table it may choose, measured: per decade of tol
/// from 1e-4 to 1e-8, the geometric mean over the named scenes thesis, close, long, two-centres and
/// three-centres of the search's force evaluations over the cheapest table's on that scene (bench/auto_costs:
/// the searches as auto runs them, verified about several centres; docs/measurements.md, "Tuned constants").
/// auto takes the table of least cost at tol, interpolated in log10(tol) between decades, held above 1e-4.
struct MeasuredCost {
  std::string_view table;
  std::array<double, 5> by_decade;  ///< tol = 1e-4, 1e-5, ..., 1e-8
};
constexpr std::array<MeasuredCost, 6> kMeasuredCost = {{
    {"verlet", {1.16, 1.73, 3.31, 8.41, 17.7}},
    {"y4", {1.59, 1.66, 1.38, 1.41, 1.47}},
    {"pefrl", {1.90, 1.94, 1.32, 1.10, 1.13}},
    {"bm4", {3.10, 2.15, 2.00, 1.72, 1.25}},
    {"kl6", {5.14, 3.93, 3.22, 2.17, 1.94}},
    {"kl8", {6.55, 4.95, 4.07, 3.79, 2.67}},
}};
constexpr double kFirstDecade = 4.0;  ///< by_decade[0] is tol = 1e-4
/// Below kMeasuredDown auto keeps the tables it had: Kahan-Li 6 down to kTightTolerance, Kahan-Li 8 below.
/// The five scenes measured others cheapest there (Blanes-Moan 4 at 1e-9, Kahan-Li 6 at 1e-11, McLachlan
/// 8 at 1e-12), but with them the scattering study's encounters (`study --quick --name scattering`, which
/// asks 1e-12 and retries 10x looser down to 1e-9) refined for minutes: over 400 s in all against 19.6 s.
constexpr double kMeasuredDown = 1e-8;
constexpr double kTightTolerance = 1e-10;

/// A table's measured cost at tol >= kMeasuredDown (kMeasuredCost).
double measured_cost(const MeasuredCost& c, double tol) {
  const double x = std::clamp(-std::log10(tol) - kFirstDecade, 0.0, static_cast<double>(c.by_decade.size() - 1));
  const auto i = std::min(static_cast<std::size_t>(x), c.by_decade.size() - 2);
  const double f = x - static_cast<double>(i);
  return c.by_decade[i] * std::pow(c.by_decade[i + 1] / c.by_decade[i], f);
}

/// The table of least measured cost at tol; nullptr below kMeasuredDown.
const MeasuredCost* cheapest_measured(double tol) {
  if (tol < kMeasuredDown) return nullptr;
  return &*std::min_element(kMeasuredCost.begin(), kMeasuredCost.end(), [tol](const MeasuredCost& a, const MeasuredCost& b) {
    return measured_cost(a, tol) < measured_cost(b, tol);
  });
}

/// auto takes a fixed step when the potential at the estimated closest approach is below this
/// fraction of the time-step constant c: the time transformation would then change the step by < 10%.
constexpr double kFarFraction = 0.1;

}  // namespace

bool auto_verifies(const std::vector<Centre>& centres) { return centres.size() > 1; }

const MethodInfo& choose_method(const Body& body, const std::vector<Centre>& centres, double tol, std::string* why) {
  check_tolerance(tol);
  return detail::choose_method_for(body, centres, tol, why);
}

const MethodInfo& detail::choose_method_for(const Body& body, const std::vector<Centre>& centres, double tol,
                                            std::string* why) {
  // The table whose whole search was measured cheapest at this tol (kMeasuredCost), or Kahan-Li 6 or 8.
  const MeasuredCost* measured = cheapest_measured(tol);
  const std::string_view table = measured ? measured->table : tol >= kTightTolerance ? "kl6" : "kl8";
  std::ostringstream os;
  double potential_at_closest = 0.0;  // at the guiding centre's closest approach to each centre
  const Helix helix = helix_of(body.p, to_momenta(body.p, body.s0));
  for (const Centre& c : centres)
    potential_at_closest += std::abs(c.A) / std::max(path_distance(helix, c.c, std::numeric_limits<double>::infinity()), 1e-300);
  const double c = automatic_omega_c(body, centres, 0.0);
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
  if (m->table == table && measured)
    os << "; its table's search was measured the cheapest at this tol (" << detail::short_number(measured_cost(*measured, tol))
       << "x the cheapest table on each scene, geometric mean)";
  else if (m->table == table)
    os << (tol >= kTightTolerance ? "; Kahan-Li 6 for 1e-10 <= tol < 1e-8" : "; Kahan-Li 8 for tol < 1e-10");
  if (why) *why = os.str();
  return *m;
}

}  // namespace bodypoint

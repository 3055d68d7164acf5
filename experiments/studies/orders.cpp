// bodypoint study orders: for every fixed-step and time-transformed method, a ladder of steps h0/sqrt(2)^k
// on the two scenes of tests/lib/test_convergence.cpp, the final position against a long-double reference,
// and the slope fitted above round-off (bodypoint/order_fit.hpp):
//   encounter  table 3.1 moved close (L = 20, d = 1), stopped at t = 3 next to the closest approach;
//   orbit      a bound eccentric orbit (A = 1, e ~ 0.44) for two periods (t = 30): a longer run widens
//              the window above round-off, which the order-8 and order-10 tables need.
// B = 0.7 (ks: B = 0). h0 is found per method, halved from kFirstStep until the error is below
// kStartError. Time-transformed methods run with c = 0 (--omega-c 0): the automatic c grows with the
// fictitious step and would change the transformation along the ladder. The thesis's drift/kick schemes
// are measured on the encounter only (first order: their orbit ladder would need 1e8 steps).
#include "orders.hpp"

#include "cli.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/order_fit.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scenes.hpp"

#include <cmath>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace bodypoint::cli {
namespace {

constexpr double kFirstStep = 1.5;
/// A ladder starts where the relative error is below this: the leading error term dominates there for
/// every method here (the drift/kick schemes with B != 0 are first order from 1e-2 down).
constexpr double kStartError = 1e-2;
constexpr double kSmallestStart = 1e-5;  // no method here needs a smaller first step
constexpr int kPoints = 13;              // h0 down to h0/64

struct Probe {
  Scene scene;
  double t_end;
  State ref;
};

Probe probe(const NamedScene& ns) {
  Probe p{ns.scene, ns.t_end, {}};
  p.ref = reference_state(p.scene.bodies.front(), p.scene.centres, p.t_end);
  return p;
}

double error_at(const MethodInfo& m, const Probe& p, double h) {
  Options o = unobserved();
  if (takes_time_step_constant(m)) o.omega_c = 0.0;
  // A fictitious step ends exactly at t_end; a fixed one is the nearest that lands there.
  const Advance how = advance_of(m, {.step = h, .end = p.t_end, .grid = FixedGrid::nearest});
  const BodyResult r = run_unestimated(m, p.scene.bodies.front(), p.scene.centres, how, o);
  if (!ran(r.outcome)) return std::numeric_limits<double>::infinity();  // a step too large for this encounter (logH's E - T + c <= 0)
  return bodypoint::state_distance(r.run.final, p.ref);  // the tool's error norm, max(|dR|/|R|, |dv|/|v|)
}

/// The fitted slope, or NaN when the method does not run on the scene or no ladder start was found.
double measured_order(const MethodInfo& m, const Probe& p, std::size_t* used) {
  *used = 0;
  double h = kFirstStep;
  while (h > kSmallestStart && !(error_at(m, p, h) < kStartError)) h /= 2.0;
  if (!(h > kSmallestStart)) return std::numeric_limits<double>::quiet_NaN();
  std::vector<std::pair<double, double>> ladder;
  for (int k = 0; k < kPoints; ++k) {
    const double hk = h / std::pow(std::sqrt(2.0), k);
    ladder.emplace_back(hk, error_at(m, p, hk));
  }
  const double slope = asymptotic_slope(ladder, used);
  return *used >= 2 ? slope : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

void write_orders(std::ostream& csv) {
  csv << "method,nominal,encounter,encounter_points,orbit,orbit_points\n"
      << "# bodypoint study orders: slope of the final-position error against the step, fitted above\n"
      << "# round-off (lib/core/model/bodypoint/order_fit.hpp), on the encounter (L = 20, d = 1, t = 3) and the bound\n"
      << "# orbit (A = 1, t = 30) of tests/lib/test_convergence.cpp, B = 0.7 (ks: B = 0); time-transformed\n"
      << "# methods with c = 0; empty: the method does not run there; revision " << git_revision() << "\n";
  const Probe enc_spin = probe(convergence_encounter(0.7)), enc_material = probe(convergence_encounter(0.0));
  const Probe orb_spin = probe(convergence_orbit(0.7)), orb_material = probe(convergence_orbit(0.0));
  for (const MethodInfo& m : methods()) {
    if (takes_tolerance_per_step(m)) continue;  // no step to refine: a tolerance
    // A method that refuses the spinning body (ks) is measured on the material point.
    const bool ks = !refusal(m, enc_spin.scene.bodies.front(), enc_spin.scene.centres).empty();
    std::size_t ue = 0, uo = 0;
    const double enc = measured_order(m, ks ? enc_material : enc_spin, &ue);
    const double orb = keeps_order_with_spin(m) ? measured_order(m, ks ? orb_material : orb_spin, &uo)
                                                : std::numeric_limits<double>::quiet_NaN();
    csv << CsvLine().text(m.name).count(m.order).num_if(std::isfinite(enc), enc).count(static_cast<long>(ue))
               .num_if(std::isfinite(orb), orb).count(static_cast<long>(uo)).str()
        << '\n';
  }
}

}  // namespace bodypoint::cli

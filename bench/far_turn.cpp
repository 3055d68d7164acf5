// far_turn: the far leg by one turn of the spin a step (splitting/far_turn.hpp) against the exact
// splitting at steps of a fraction of a radian (docs/measurements.md, "An encounter at infinity").
//
// Each row: a scene given by b = 3 and arrival phase 1 (table 3.1's parameters with the row's changes),
// started at L, run by the far leg (Kahan-Li 6 with a turn for each kick, steps eta r/|v|) until a step
// ends within r_stop of the nearest centre, against lp-kl8 at h = 0.004 and 0.002 over the same time
// (the reference; its two runs' difference is printed as its own error). Error: max(|dR|/|R|, |dv|/|v|),
// the estimates' norm; orbit: max(|dG|/|G|, |dK1|/|K1|), the guiding centre's orbit without the helix's
// phase; across: the guiding centre's offset across K1 (absolute), what moves an encounter's path; corr acr:
// the same of the end's quiver correction; quiver: the size of the leg's two quiver corrections
// (FarLeg::quiver, relative); the columns "share 0" and
// "share 1" end the leg with no quiver correction and with the first-order theory's full one (kQuiverShare
// is 0.5).
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/field.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/splitting/catalogue.hpp"
#include "bodypoint/splitting/far_turn.hpp"

#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace {

using namespace bodypoint;
namespace sp = bodypoint::splitting;

/// The guiding centre G = R + K1 x K2/|K1|^2 of a state.
Vec3 guiding(const BodyPoint& p, const State& s) {
  const Momenta q = to_momenta(p, s);
  return s.R + q.K1.cross(q.K2) / q.K1.squaredNorm();
}
/// How far apart two states' guiding centres are across K1 (of `ref`): what moves an encounter's path.
double across(const BodyPoint& p, const State& a, const State& ref) {
  return (guiding(p, a) - guiding(p, ref)).cross(to_momenta(p, ref).K1.normalized()).norm();
}
/// The orbit's error, without the helix's phase: max(|dG|/|G|, |dK1|/|K1|) (G the guiding centre).
double orbit_error(const BodyPoint& p, const State& a, const State& ref) {
  const Momenta qa = to_momenta(p, a), qr = to_momenta(p, ref);
  const Vec3 Ga = a.R + qa.K1.cross(qa.K2) / qa.K1.squaredNorm(), Gr = ref.R + qr.K1.cross(qr.K2) / qr.K1.squaredNorm();
  return std::max((Ga - Gr).norm() / Gr.norm(), (qa.K1 - qr.K1).norm() / qr.K1.norm());
}

/// lp-kl8 at about h over time t, by the public API; its evaluations in *evals.
State reference(const Body& b, const std::vector<Centre>& centres, double t, double h, long* evals) {
  const long n = std::lround(std::ceil(t / h));
  Options o;
  o.track_invariants = false;
  const BodyResult r = integrate_body(b, centres, find_method("lp-kl8"), FixedSteps{t / static_cast<double>(n), n}, o);
  *evals = r.run.force_evals;
  return r.run.final;
}

struct Leg {
  State end;
  sp::FarLeg leg;
  long evals;
};
template <class Field>
Leg leg(const Body& b, const Field& f, double eta, double r_stop, double share, double t_span) {
  sp::FarTurnKernel<Field> k(b.p, f);
  k.quiver_share = share;
  sp::LieState x = k.initial_state(b.s0);
  const sp::FarLeg l = sp::far_leg<sp::ops_of<sp::KahanLi6>>(k, x, t_span, eta, sp::LegStop{Vec3::Zero(), r_stop, false});
  return {k.to_physical(x), l, k.evals()};
}

void row(const char* name, const Body& b, const std::vector<Centre>& centres, double L, double r_stop, double eta) {
  const CentreList f{centres};
  const double inf = std::numeric_limits<double>::infinity();
  const Leg main = leg(b, f, eta, r_stop, sp::kQuiverShare, inf);
  const double t = main.leg.t;
  long ref_evals = 0, ref2_evals = 0;
  const State ref = reference(b, centres, t, 0.002, &ref2_evals);
  const State coarse = reference(b, centres, t, 0.004, &ref_evals);
  const double e0 = state_distance(leg(b, f, eta, r_stop, 0.0, t).end, ref);
  const double e1 = state_distance(leg(b, f, eta, r_stop, 1.0, t).end, ref);
  std::printf("%-26s %6.0f %6.0f %5.2f %6ld %7ld %9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %9.2e %9ld\n", name,
              L, sp::nearest_centre(f, main.end.R), eta, main.leg.steps, main.evals, state_distance(main.end, ref),
              orbit_error(b.p, main.end, ref), across(b.p, main.end, ref), across(b.p, main.leg.averaged_end, main.end),
              main.leg.quiver, e0, e1, state_distance(coarse, ref), ref2_evals);
}

Body body(SceneParams s, double L) {
  s.start.L = L;
  return thesis_scene(with_asymptotic_data(s, 3.0, std::numeric_limits<double>::quiet_NaN(), 1.0)).bodies[0];
}

}  // namespace

int main() {
  std::printf("%-26s %6s %6s %5s %6s %7s %9s %9s %9s %9s %9s %9s %9s %9s %9s\n", "scene", "L", "r_end", "eta", "steps",
              "evals", "error", "orbit", "across", "corr acr", "quiver", "share 0", "share 1", "ref err", "ref evals");
  const SceneParams thesis;
  const std::vector<Centre> one{Centre{Vec3::Zero(), thesis.A}};
  for (double L : {3200.0, 12800.0})
    for (double r_stop : {400.0, 800.0}) row("table 3.1", body(thesis, L), one, L, r_stop, 0.1);
  for (double r_stop : {100.0, 200.0}) row("table 3.1", body(thesis, 3200.0), one, 3200.0, r_stop, 0.1);
  for (const double b_in : {0.3, 1.0, 10.0}) {
    SceneParams p = thesis;
    p.start.L = 3200.0;
    const Body bb = thesis_scene(with_asymptotic_data(p, b_in, std::numeric_limits<double>::quiet_NaN(), 1.0)).bodies[0];
    const std::string label = "table 3.1, b = " + std::to_string(b_in).substr(0, 4);
    for (double r_stop : {400.0, 403.0, 800.0}) row(label.c_str(), bb, one, 3200.0, r_stop, 0.05);
  }
  row("table 3.1, eta 0.05", body(thesis, 3200.0), one, 3200.0, 400.0, 0.05);
  row("table 3.1, eta 0.2", body(thesis, 3200.0), one, 3200.0, 400.0, 0.2);
  SceneParams s = thesis;
  s.B = 0.3;
  for (double r_stop : {200.0, 400.0}) row("B = 0.3", body(s, 3200.0), std::vector<Centre>{Centre{Vec3::Zero(), s.A}}, 3200.0, r_stop, 0.1);
  s = thesis;
  s.B = 0.9;
  for (double r_stop : {200.0, 400.0}) row("B = 0.9", body(s, 3200.0), std::vector<Centre>{Centre{Vec3::Zero(), s.A}}, 3200.0, r_stop, 0.1);
  s = thesis;
  s.start.Kx = 4.0;
  s.A = -1.0;
  for (double r_stop : {200.0, 400.0}) row("Kx = 4, A = -1", body(s, 3200.0), std::vector<Centre>{Centre{Vec3::Zero(), s.A}}, 3200.0, r_stop, 0.1);
  // Two repelling centres 4 apart across the path, their total charge table 3.1's.
  const std::vector<Centre> two{Centre{Vec3(0.0, 2.0, 0.0), -1.0}, Centre{Vec3(0.0, -2.0, 0.0), -1.0}};
  row("two centres (A = -1 each)", body(thesis, 3200.0), two, 3200.0, 400.0, 0.1);
  return 0;
}

// `bodypoint study --name long-time`: bound orbits over many periods. A structure-preserving method keeps its
// energy error bounded and its phase error growing linearly in time; a method that is not lets the energy
// drift and the phase error grow quadratically (docs/physics.md, "Long-time behaviour"). Each method runs
// once, by a Stepper landing on log-spaced times (its step adjusted at most a hair to land), and each time
// reached gives a row: the invariants' relative errors against the start's, the state's distance from
// a reference run (the tool's error norm), and on the Kepler ellipse the mean anomaly against Kepler's n t.
#include "long_time.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/invariants.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "process.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

namespace bodypoint::cli {
namespace {

/// Fixed and fictitious steps per period of the orbit: a 4th-order method's energy error is then far above
/// the rounding (RK4's drift is visible within 10 periods), and lp-kl8's reference far below every other's.
constexpr double kStepsPerPeriod = 100.0;
/// The reference run's steps per period (lp-kl8): its phase error after 10^5 periods stays below 1e-6,
/// where the 4th-order methods' are 1e-2 and more.
constexpr double kReferenceStepsPerPeriod = 400.0;
/// The tolerance per step of the step-size-controlled peers: their energy drift shows within the span.
constexpr double kPeerTolerance = 1e-9;
/// Output times per decade of periods, from kLongTimeFirstPeriods to 10^3 (quick) or 10^5 (or --periods).
constexpr int kTimesPerDecade = 4;
constexpr double kQuickPeriods = 1e3, kFullPeriods = 1e5;

/// The orbit: a = 1 about A = 1 (m = 1, period 2 pi), e = 0.5, from its periapsis. The spinning bodies turn at
/// w = (0.5, 0, 0.5) (B = 0.3): their energy, -0.25 and less, is the scale of its relative error.
constexpr double kEccentricity = 0.5;

struct LongScene {
  std::string name;
  Scene scene;
  double period;
  bool kepler;  ///< a material point about one centre: its mean anomaly is known (n t)
};

Body orbit_body(double B, const Vec3& w) {
  Body b;
  b.name = "body";
  b.p = BodyPoint{1.0, B, 1.0};
  const double e = kEccentricity, r = 1.0 - e;
  b.s0.R = Vec3(r, 0.0, 0.0);
  b.s0.v = Vec3(0.0, std::sqrt((1.0 + e) / r), 0.0);
  b.s0.w = w;
  return b;
}

std::vector<LongScene> scenes() {
  const double P = 2.0 * std::numbers::pi;
  std::vector<LongScene> s;
  s.push_back({"kepler", Scene{{Centre{Vec3::Zero(), 1.0}}, {orbit_body(0.0, Vec3::Zero())}}, P, true});
  s.push_back({"spinning", Scene{{Centre{Vec3::Zero(), 1.0}}, {orbit_body(0.3, Vec3(0.5, 0.0, 0.5))}}, P, false});
  // Two centres 0.3 apart, the body on an orbit about both (their total charge 2 at distance 1.5 at the start).
  Body two = orbit_body(0.3, Vec3(0.5, 0.0, 0.5));
  two.s0.R = Vec3(1.5, 0.0, 0.0);
  two.s0.v = Vec3(0.0, std::sqrt(2.0 / 1.5), 0.0);
  s.push_back({"two-centres", Scene{{Centre{Vec3(-0.15, 0.0, 0.0), 1.0}, Centre{Vec3(0.15, 0.0, 0.0), 1.0}}, {two}},
               2.0 * std::numbers::pi * std::sqrt(1.5 * 1.5 * 1.5 / 2.0), false});
  return s;
}

/// The methods and their steps (h, ds or the tolerance per step): the exact splitting, the time-transformed
/// leapfrog for attracting centres, the Kepler split, RK4, and the step-size-controlled peers.
struct LongMethod {
  std::string name;
  double per_period;  ///< steps per period (0: a tolerance per step)
};
/// The peers that this build has (GSL and SUNDIALS are optional).
std::vector<LongMethod> long_methods() {
  std::vector<LongMethod> m;
  for (const char* name : {"lp-y4", "ttl-y4", "kep-y4", "rk4"}) m.push_back({name, kStepsPerPeriod});
  for (const char* name : {"gsl-rk8pd", "odeint-rkf78", "cvode-adams"})
    if (find_method(name)) m.push_back({name, 0.0});
  return m;
}

/// Log-spaced times from kLongTimeFirstPeriods to `last` periods, `last` itself the final one.
std::vector<double> output_times(double period, double last) {
  std::vector<double> t;
  for (int k = 0;; ++k) {
    const double periods = kLongTimeFirstPeriods * std::pow(10.0, static_cast<double>(k) / kTimesPerDecade);
    if (periods > last * (1.0 - 1e-12)) break;
    t.push_back(periods * period);
  }
  t.push_back(last * period);
  return t;
}

/// The mean anomaly of a Kepler ellipse state (mu = A/m = 1), in (-pi, pi]; NaN off the ellipse (E >= 0).
double mean_anomaly(const State& s) {
  const double r = s.R.norm(), energy = 0.5 * s.v.squaredNorm() - 1.0 / r;
  if (!(energy < 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double a = -1.0 / (2.0 * energy);
  const double e = std::hypot(s.R.dot(s.v) / std::sqrt(a), 1.0 - r / a);
  const double E = std::atan2(s.R.dot(s.v) / std::sqrt(a), 1.0 - r / a);  // e sin E, e cos E
  return E - e * std::sin(E);
}

/// The mean anomaly unwrapped along the run, from every step's state (a step turns it by far less than pi),
/// against Kepler's n t (n = 1 for a = 1): not folded into (-pi, pi], so that a phase error keeps growing past pi.
struct UnwrappedPhase {
  double last = 0.0;  // the start is the periapsis: M = 0
  long turns = 0;     // whole turns counted (a sum of the steps' increments would add their rounding)
  void add(const State& s) {
    const double m = mean_anomaly(s);
    if (m - last < -std::numbers::pi) ++turns;
    if (m - last > std::numbers::pi) --turns;
    last = m;
  }
  [[nodiscard]] double error(double t) const {
    return std::abs(last - (t - 2.0 * std::numbers::pi * static_cast<double>(turns)));
  }
};

struct Invariants {
  double E, K2sq;
  Vec3 K2Q;
};
Invariants invariants_of(const Body& b, const std::vector<Centre>& centres, const State& s) {
  return {energy(b.p, centres, s), to_momenta(b.p, s).K2.squaredNorm(),
          centres.size() == 1 ? total_angular_momentum(b.p, s, centres.front().c) : Vec3::Zero()};
}

/// One method's rows, one per time reached, and its states there; `ref` (empty: this is the reference) the
/// reference's states at the same times.
std::vector<State> run_method(std::ostream& csv, const LongScene& ls, const LongMethod& lm, const std::vector<double>& times,
                              const std::vector<State>& ref) {
  const Body& body = ls.scene.bodies.front();
  const double step = lm.per_period > 0.0 ? ls.period / lm.per_period : kPeerTolerance;
  const MethodInfo& m = method_or_throw(lm.name);
  const Invariants start = invariants_of(body, ls.scene.centres, body.s0);
  // The energy's error at every step, its largest so far: at the output times alone it is sampled at
  // whatever phase of the orbit they fall on (a bounded error then looks like a drift).
  double max_dE = 0.0;
  UnwrappedPhase phase;
  const SampleSink every_step = [&](const Sample& smp) {
    max_dE = std::max(max_dE, std::abs(energy(body.p, ls.scene.centres, smp.s) - start.E) / std::abs(start.E));
    if (ls.kepler) phase.add(smp.s);
  };
  Options options;
  options.sink = &every_step;
  options.max_energy_error = std::numeric_limits<double>::infinity();  // a drift is what this study shows
  options.estimate_error = false;
  Stepper s(m, body, ls.scene.centres, step, options);
  std::vector<State> states;
  for (std::size_t i = 0; i < times.size(); ++i) {
    const Outcome o = s.advance_to(times[i]);
    states.push_back(s.state());
    const Invariants now = invariants_of(body, ls.scene.centres, s.state());
    CsvLine row;
    row.text(ls.name).text(lm.name).text(std::string(step_name(m))).num(step).num(times[i]).num(times[i] / ls.period);
    row.num(std::abs(now.E - start.E) / std::abs(start.E)).num(max_dE);
    row.num_if(start.K2sq > 0.0, std::abs(now.K2sq - start.K2sq) / start.K2sq);  // none without a spin
    row.num_if(ls.scene.centres.size() == 1, (now.K2Q - start.K2Q).norm());
    row.num_if(!ref.empty(), ref.empty() ? 0.0 : bodypoint::state_distance(s.state(), ref[i]));
    row.num_if(ls.kepler, phase.error(times[i]));
    row.count(s.force_evals()).text(std::string(outcome_name(o)));
    csv << row.str() << '\n';
    if (o != Outcome::ok) {  // a flagged segment ends the method's rows (its outcome says why)
      if (ref.empty()) throw Error("the long-time study's reference (lp-kl8) did not reach t = " + fmt(times[i]));
      break;
    }
  }
  return states;
}

}  // namespace

void write_long_time_study(const std::filesystem::path& dir, bool quick, double periods) {
  if (periods == 0.0) periods = quick ? kQuickPeriods : kFullPeriods;
  if (!std::isfinite(periods) || periods < kLongTimeFirstPeriods)
    throw Error("--periods must be a finite number >= " + fmt(kLongTimeFirstPeriods) + ", got " + fmt(periods));
  AtomicFile f((dir / "long_time.csv").string());
  std::ostream& csv = f.stream();
  csv << "scene,method,step_name,step,t,periods,rel_dE,max_rel_dE,rel_dK2sq,abs_dK2Q,err,phase_err,force_evals,outcome\n"
      << "# bodypoint study --name long-time" << (quick ? " --quick" : "") << " (" << fmt(periods) << " periods): err = max(|dR|/|R|, |dv|/|v|) against lp-kl8 at "
      << kReferenceStepsPerPeriod << " steps per period (empty in its own rows); phase_err = |M - n t| of the "
      << "Kepler ellipse, M unwrapped along the run (kepler only); max_rel_dE the largest over every step up to t; "
      << "abs_dK2Q with one centre only\n";
  for (const LongScene& ls : scenes()) {
    const std::vector<double> times = output_times(ls.period, periods);
    const std::vector<State> ref = run_method(csv, ls, {"lp-kl8", kReferenceStepsPerPeriod}, times, {});
    for (const LongMethod& lm : long_methods()) run_method(csv, ls, lm, times, ref);
  }
  f.commit();
  std::cerr << "wrote " << (dir / "long_time.csv").string() << "\n";
}

}  // namespace bodypoint::cli

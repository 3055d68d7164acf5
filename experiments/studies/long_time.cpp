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
#include "bodypoint/threads.hpp"
#include "process.hpp"
#include "rows_file.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <iterator>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>
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
/// The reference runs to at most this many periods: it is 30 % of the study's time (17 stages a step at 400
/// steps a period, against the others' 100; measured at 10^4 periods), so that 10^7 periods take some 6 CPU
/// hours instead of 8. Past it `err` is empty; the energy, the Casimirs and the ellipse's phase need no
/// reference.
constexpr double kReferencePeriods = 1e6;
/// The tolerance per step of the step-size-controlled peers: their energy drift shows within the span.
constexpr double kPeerTolerance = 1e-9;
/// Output times per decade of periods, from kLongTimeFirstPeriods to 10^3 (quick) or 10^5 (or --periods).
constexpr int kTimesPerDecade = 4;
constexpr double kQuickPeriods = 1e3, kFullPeriods = 1e5;
/// A run is journalled at the output times and at least every this many periods: the reference (lp-kl8 at
/// 400 steps a period) takes some 6 s for them on this machine, what an interrupted sitting loses at most.
constexpr double kChunkPeriods = 1e4;

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

/// Where a method's run stands at one boundary: what its row needs, and all a resumed run continues from.
struct Mark {
  double t = 0.0;
  State s;
  long evals = 0;
  double max_dE = 0.0;  ///< the largest relative energy error over every step so far
  UnwrappedPhase phase;
  Outcome outcome = Outcome::ok;
};

/// A journal record of a mark: hexadecimal floats, so that a resumed run goes on from the very bits.
std::string encode(const Mark& m) {
  std::string out;
  char buf[40];
  const auto put = [&](double x) {
    std::snprintf(buf, sizeof buf, "%a ", x);
    out += buf;
  };
  put(m.t);
  for (const Vec3* v : {&m.s.R, &m.s.v, &m.s.w})
    for (int i = 0; i < 3; ++i) put((*v)[i]);
  put(m.max_dE);
  put(m.phase.last);
  out += std::to_string(m.evals) + " " + std::to_string(m.phase.turns) + " " + std::to_string(static_cast<int>(m.outcome));
  return out;
}

Mark decode(const std::string& record, const std::string& journal) {
  std::istringstream in(record);
  std::vector<std::string> f{std::istream_iterator<std::string>(in), std::istream_iterator<std::string>()};
  const auto bad = [&] { return Error("the journal '" + journal + "' holds a record that is not a long-time mark; delete it to start over"); };
  if (f.size() != 15) throw bad();
  std::vector<double> x;
  for (std::size_t i = 0; i < 12; ++i) {
    char* end = nullptr;
    x.push_back(std::strtod(f[i].c_str(), &end));
    if (end == f[i].c_str() || *end != '\0') throw bad();
  }
  Mark m;
  m.t = x[0];
  m.s.R = Vec3(x[1], x[2], x[3]);
  m.s.v = Vec3(x[4], x[5], x[6]);
  m.s.w = Vec3(x[7], x[8], x[9]);
  m.max_dE = x[10];
  m.phase.last = x[11];
  long n[3];
  for (std::size_t i = 0; i < 3; ++i) {
    char* end = nullptr;
    errno = 0;
    n[i] = std::strtol(f[12 + i].c_str(), &end, 10);
    if (end == f[12 + i].c_str() || *end != '\0' || errno == ERANGE) throw bad();
  }
  if (n[2] < 0 || n[2] > static_cast<long>(Outcome::incomplete)) throw bad();
  m.evals = n[0];
  m.phase.turns = n[1];
  m.outcome = static_cast<Outcome>(n[2]);
  return m;
}

/// The times a run stops at: the output times and, between them, every kChunkPeriods periods; after each
/// the run's mark is journalled. The same for every method of a scene, whatever was resumed.
std::vector<double> boundaries(const std::vector<double>& times, double period) {
  std::vector<double> b = times;
  const double last = times.back();
  for (double k = 1.0; k * kChunkPeriods * period < last; k += 1.0) {
    const double t = k * kChunkPeriods * period;
    const bool near_output = std::any_of(times.begin(), times.end(), [&](double o) { return std::abs(o - t) <= 1e-9 * o; });
    if (!near_output) b.push_back(t);
  }
  std::sort(b.begin(), b.end());
  return b;
}

/// One run of the study: a method on a scene (the reference is lp-kl8).
struct Pair {
  std::size_t scene;
  LongMethod method;
  std::size_t reach = 0;  ///< the boundaries it runs to (all but the reference's past kReferencePeriods)
};

/// What the runs share: the scenes, every run's boundaries' marks, the journal that keeps them.
struct LongRuns {
  std::vector<LongScene> scenes;
  std::vector<std::vector<double>> times, bounds;  ///< per scene
  std::vector<Pair> pairs;
  std::vector<std::vector<std::optional<Mark>>> marks;  ///< per pair, per boundary
  std::size_t stride = 0;                               ///< journal index = pair * stride + boundary
};

/// Runs pair `p` from its last journalled mark to its last boundary (or its first outcome that is not ok),
/// journalling every boundary's mark.
void run_pair(LongRuns& runs, std::size_t p, RowJournal& journal) {
  const LongScene& ls = runs.scenes[runs.pairs[p].scene];
  const LongMethod& lm = runs.pairs[p].method;
  const std::vector<double>& bounds = runs.bounds[runs.pairs[p].scene];
  std::vector<std::optional<Mark>>& marks = runs.marks[p];
  const std::size_t reach = runs.pairs[p].reach;
  std::size_t k = 0;  // the first boundary not reached
  while (k < reach && marks[k]) ++k;
  if (k > 0 && marks[k - 1]->outcome != Outcome::ok) return;
  const Body& body = ls.scene.bodies.front();
  const double start_E = energy(body.p, ls.scene.centres, body.s0);
  Mark now = k > 0 ? *marks[k - 1] : Mark{0.0, body.s0, 0, 0.0, {}, Outcome::ok};
  // The energy's error at every step, its largest so far: at the output times alone it is sampled at
  // whatever phase of the orbit they fall on (a bounded error then looks like a drift).
  const SampleSink every_step = [&](const Sample& smp) {
    now.max_dE = std::max(now.max_dE, std::abs(energy(body.p, ls.scene.centres, smp.s) - start_E) / std::abs(start_E));
    if (ls.kepler) now.phase.add(smp.s);
  };
  Options options;
  options.sink = &every_step;
  options.max_energy_error = std::numeric_limits<double>::infinity();  // a drift is what this study shows
  options.estimate_error = false;
  Stepper s(method_or_throw(lm.name), body, ls.scene.centres, lm.per_period > 0.0 ? ls.period / lm.per_period : kPeerTolerance, options);
  if (k > 0) s.set_state(now.s, now.t);
  const long evals_before = now.evals;
  for (; k < reach; ++k) {
    CooperativeInterrupt::check();
    now.outcome = s.advance_to(bounds[k]);
    now.t = bounds[k];
    now.s = s.state();
    now.evals = evals_before + s.force_evals();
    marks[k] = now;
    journal.append(p * runs.stride + k, encode(now));
    if (now.outcome != Outcome::ok) break;  // a flagged segment ends the method's rows (its outcome says why)
  }
}

/// The CSV rows of pair `p`: one per output time reached, and its flagged segment's, if any.
void write_rows(std::ostream& csv, const LongRuns& runs, std::size_t p, std::size_t ref) {
  const LongScene& ls = runs.scenes[runs.pairs[p].scene];
  const LongMethod& lm = runs.pairs[p].method;
  const std::vector<double>& bounds = runs.bounds[runs.pairs[p].scene];
  const std::vector<double>& times = runs.times[runs.pairs[p].scene];
  const Body& body = ls.scene.bodies.front();
  const Invariants start = invariants_of(body, ls.scene.centres, body.s0);
  const double step = lm.per_period > 0.0 ? ls.period / lm.per_period : kPeerTolerance;
  for (std::size_t k = 0; k < bounds.size(); ++k) {
    const std::optional<Mark>& m = runs.marks[p][k];
    if (!m || (m->outcome == Outcome::ok && !std::binary_search(times.begin(), times.end(), bounds[k]))) continue;
    if (p == ref && m->outcome != Outcome::ok)
      throw Error("the long-time study's reference (lp-kl8) did not reach t = " + fmt(bounds[k]));
    const Invariants now = invariants_of(body, ls.scene.centres, m->s);
    CsvLine row;
    row.text(ls.name).text(lm.name).text(std::string(step_name(method_or_throw(lm.name)))).num(step).num(bounds[k]).num(bounds[k] / ls.period);
    row.num(std::abs(now.E - start.E) / std::abs(start.E)).num(m->max_dE);
    row.num_if(start.K2sq > 0.0, std::abs(now.K2sq - start.K2sq) / start.K2sq);  // none without a spin
    row.num_if(ls.scene.centres.size() == 1, (now.K2Q - start.K2Q).norm());
    const bool has_ref = p != ref && runs.marks[ref][k].has_value();
    row.num_if(has_ref, has_ref ? bodypoint::state_distance(m->s, runs.marks[ref][k]->s) : 0.0);
    row.num_if(ls.kepler, m->phase.error(bounds[k]));
    row.count(m->evals).text(std::string(outcome_name(m->outcome)));
    csv << row.str() << '\n';
  }
}

LongRuns plan_runs(double periods) {
  LongRuns runs;
  runs.scenes = scenes();
  for (std::size_t i = 0; i < runs.scenes.size(); ++i) {
    runs.times.push_back(output_times(runs.scenes[i].period, periods));
    runs.bounds.push_back(boundaries(runs.times.back(), runs.scenes[i].period));
    runs.stride = std::max(runs.stride, runs.bounds.back().size());
    const std::vector<double>& b = runs.bounds.back();
    const double ref_last = kReferencePeriods * runs.scenes[i].period * (1.0 + 1e-9);
    const auto ref_reach = static_cast<std::size_t>(std::upper_bound(b.begin(), b.end(), ref_last) - b.begin());
    runs.pairs.push_back({i, {"lp-kl8", kReferenceStepsPerPeriod}, ref_reach});
    for (const LongMethod& lm : long_methods()) runs.pairs.push_back({i, lm, b.size()});
  }
  runs.marks.assign(runs.pairs.size(), {});
  for (std::size_t p = 0; p < runs.pairs.size(); ++p) runs.marks[p].resize(runs.bounds[runs.pairs[p].scene].size());
  return runs;
}

/// Everything that decides the marks: a journal of another request is refused.
std::string journal_key(const LongRuns& runs, double periods) {
  std::string request = "long-time|" + fmt(periods) + "|" + fmt(kChunkPeriods) + "|" + fmt(kPeerTolerance) + "|" + fmt(kReferencePeriods);
  for (const Pair& p : runs.pairs) request += "|" + runs.scenes[p.scene].name + ":" + p.method.name + ":" + fmt(p.method.per_period);
  return sweep_key_of(git_revision(), "long-time scenes", request);
}

}  // namespace

void write_long_time_study(const std::filesystem::path& dir, const LongTimeRequest& request) {
  const double periods = request.periods == 0.0 ? (request.quick ? kQuickPeriods : kFullPeriods) : request.periods;
  if (!std::isfinite(periods) || periods < kLongTimeFirstPeriods)
    throw Error("--periods must be a finite number >= " + fmt(kLongTimeFirstPeriods) + ", got " + fmt(periods));
  const std::string path = (dir / "long_time.csv").string();
  AtomicFile f(path);
  LongRuns runs = plan_runs(periods);
  const std::string header = "# bodypoint study --name long-time" + std::string(request.quick ? " --quick" : "") + " (" + fmt(periods) +
      " periods): err = max(|dR|/|R|, |dv|/|v|) against lp-kl8 at " + fmt(kReferenceStepsPerPeriod) +
      " steps per period up to " + fmt(std::min(periods, kReferencePeriods)) + " periods (empty in its own rows and past them); phase_err = |M - n t| of the Kepler ellipse, M unwrapped along the run "
      "(kepler only); max_rel_dE the largest over every step up to t; abs_dK2Q with one centre only";
  RowJournal journal(path + ".journal", journal_key(runs, periods), runs.pairs.size() * runs.stride, {header}, request.resume);
  for (const auto& [index, record] : journal.done())
    runs.marks[index / runs.stride].at(index % runs.stride) = decode(record, journal.path());
  {
    const CooperativeInterrupt stop_at_a_boundary;  // a signal stops every run at its next boundary
    parallel_for(runs.pairs.size(), request.threads, [&](std::size_t p) { run_pair(runs, p, journal); });
  }
  std::ostream& csv = f.stream();
  csv << "scene,method,step_name,step,t,periods,rel_dE,max_rel_dE,rel_dK2sq,abs_dK2Q,err,phase_err,force_evals,outcome\n"
      << header << "\n";
  for (std::size_t p = 0, ref = 0; p < runs.pairs.size(); ++p) {
    if (runs.pairs[p].method.name == "lp-kl8") ref = p;
    write_rows(csv, runs, p, ref);
  }
  f.commit();
  journal.remove();
  std::cerr << "wrote " << path << "\n";
}

}  // namespace bodypoint::cli

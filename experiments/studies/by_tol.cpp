// `bodypoint work-precision --by-tol`: the same requested tolerance for everyone.
//
// For each named scene and each TOL, `--method auto` (which chooses its method and step and
// estimates its own error, tolerance.hpp) and each general-purpose peer with a step-size controller
// (Boost.Odeint dopri5, rkf78, Bulirsch-Stoer; GSL rk8pd, rkf45) are run with that TOL. The delivered
// error is max(|dR|/|R_ref|, |dv|/|v_ref|) against Boost.Odeint rkf78 in long double at tolerance
// 1e-18; a run meets TOL when its delivered error is at most TOL. Every configuration of a scene runs
// once, untimed, for its error; then all of them are timed under the commands' timing rules
// (stopwatch.hpp: warm-up, repeats interleaved across the configurations, wall and CPU time, median
// and spread, a flag where a time does not count). A call is the whole request: for auto every run its
// search makes (the pilot runs, the error estimate's companion run and the delivered run), so its
// error estimate is paid for in full.
#include "by_tol.hpp"

#include "cli.hpp"
#include "stopwatch.hpp"

#include "bodypoint/accuracy.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <iomanip>
#include <iostream>
#include <limits>
#include <sstream>
#include <utility>

namespace bodypoint::cli {
namespace {

struct TolRow {
  std::string scene, method;
  double tol = 0, h = 0, err_estimate = 0, err = 0;
  Timing time;                  ///< the whole call (auto: its search included), stopwatch.hpp
  std::function<void()> run;    ///< the call, as timed
  /// auto: the delivered run's step loop in each timed call; its median, what a search costing
  /// nothing would take
  std::shared_ptr<std::vector<double>> delivered_samples;
  double delivered_wall_s = 0;
  long force_evals = 0, delivered_force_evals = 0;
  int runs = 1;
  bool met = false;
  std::string refusal;  ///< auto refused TOL (out of reach on the scene, over the budget), or a peer's run failed: why; "" otherwise
  bool is_auto = false;
  bool is_ladder = false;  ///< a peer's run from its tolerance ladder (oracle view), not at TOL
  bool is_own = false;     ///< a configuration of bodypoint's own methods (own_ladders): a method and a step
  bool method_is_exact = false;  ///< own: an exact flow (ks), whose force_evals count its steps
  /// own: the same configuration run as `simulate --h` runs it by default (invariants on, the error
  /// estimate made): what its estimate cost in force evaluations, and the estimate; -1 / NaN where it has none
  long estimate_force_evals = -1;
  double own_estimate = std::numeric_limits<double>::quiet_NaN();
  /// auto: bodypoint's cheapest own configuration whose default estimate shows TOL and that delivers it
  /// (mark_trusted_bests): "method h=..." or "" where none does, and its price, the run and its estimate
  std::string trusted;
  long trusted_evals = 0;
};

/// A peer's ladder stops once its delivered error is below this (the smallest TOL of the grid is 1e-12).
constexpr double kLadderFloor = 1e-13;
/// ... or after this many half-decade rungs in a row that did not halve its best error: it has met its
/// round-off floor, and a tighter tolerance costs more without delivering more (on scene long, rkf45's
/// ladder went on to 1e-15 at about 1e8 force evaluations a run).
constexpr int kLadderStalls = 3;

std::vector<std::string> peer_names() {
  std::vector<std::string> out;
  for (const MethodInfo& m : methods())
    if (takes_tolerance_per_step(m)) out.emplace_back(m.name);
  return out;
}

/// auto at TOL as a user asks for it (integrate_body with the accuracy mode, no method named); a TOL it
/// refuses (below the round-off floor, over the budget) is a row with its reason in `refusal`.
TolRow measure_auto(const NamedScene& ns, const State& ref, double tol) {
  const Body& body = ns.scene.bodies.front();
  TolRow row;
  row.scene = ns.name;
  row.tol = tol;
  row.is_auto = true;
  const Accuracy accuracy{tol, ns.t_end};
  const BodyResult r = integrate_body(body, ns.scene.centres, nullptr, accuracy, unobserved());
  if (!ran(r.outcome)) {
    row.method = "refused";
    row.err = row.err_estimate = std::numeric_limits<double>::quiet_NaN();
    row.refusal = r.reason;
    return row;
  }
  const MethodInfo& m = *r.method;
  row.method = std::string(m.name);
  row.h = r.accuracy->h_chosen;
  row.err_estimate = r.accuracy->err_estimate;
  row.err = bodypoint::state_distance(r.run.final, ref);
  row.met = row.err <= tol;
  row.delivered_samples = std::make_shared<std::vector<double>>();
  // The delivered run again, through the public API: the method auto chose at its step and time-step constant.
  Options delivered = unobserved();
  if (takes_time_step_constant(m)) delivered.omega_c = r.accuracy->omega_c;
  row.run = [&m, body, centres = ns.scene.centres, how = advance_to(m, row.h, ns.t_end), delivered,
             samples = row.delivered_samples] {
    samples->push_back(integrate_body(body, centres, &m, how, delivered).run.wall_s);
  };
  row.force_evals = r.accuracy->force_evals;
  row.delivered_force_evals = r.run.force_evals;
  row.runs = r.accuracy->runs;
  return row;
}

/// A peer at TOL, driven as its users drive it (first trial step 1e-3); a run that fails is a row with
/// its reason in `refusal`, for the caller to drop.
TolRow measure_peer(const NamedScene& ns, const std::string& name, const State& ref, double tol) {
  const Body& body = ns.scene.bodies.front();
  TolRow row;
  row.scene = ns.name;
  row.method = name;
  row.tol = tol;
  const ControlledSteps how{1e-3, ns.t_end, tol};
  const MethodInfo& m = method_or_throw(name);
  const BodyResult x = run_unestimated(m, body, ns.scene.centres, how, unobserved());
  if (!ran(x.outcome)) {
    row.refusal = x.reason;
    return row;
  }
  const RunResult& r = x.run;
  row.run = [&m, body, centres = ns.scene.centres, how] { run_or_throw(m, body, centres, how, unobserved()); };
  row.err = bodypoint::state_distance(r.final, ref);
  if (!std::isfinite(row.err)) row.err = std::numeric_limits<double>::infinity();
  row.met = row.err <= tol;
  row.force_evals = r.force_evals;
  return row;
}

std::string sci(double x, int digits = 2) {
  std::ostringstream os;
  os << std::setprecision(digits) << std::scientific << x;
  return os.str();
}

/// auto at each tolerance, then every peer at the same tolerance; a refusal (below the round-off
/// floor, over the budget) is recorded as such.
void measure_at_tolerances(const NamedScene& ns, const State& ref, const std::vector<double>& tols,
                           const std::vector<std::string>& peers, std::vector<TolRow>& rows) {
  for (double tol : tols) {
    rows.push_back(measure_auto(ns, ref, tol));
    if (!rows.back().refusal.empty()) {
      std::cerr << "  " << ns.name << " tol " << sci(tol, 0) << ": auto refused (" << rows.back().refusal << ")\n";
      continue;
    }
    std::cerr << "  " << ns.name << " tol " << sci(tol, 0) << ": auto " << rows.back().method << " err "
              << sci(rows.back().err) << " (estimate " << sci(rows.back().err_estimate) << ")\n";
    for (const std::string& p : peers) {
      TolRow r = measure_peer(ns, p, ref, tol);
      if (r.refusal.empty()) rows.push_back(std::move(r));
      else std::cerr << "  " << ns.name << " " << p << " tol " << sci(tol, 0) << ": failed (" << r.refusal << ")\n";
    }
  }
}

/// The peers' own ladders, for the oracle comparison: each peer at requested tolerances from 1e-3
/// down by half decades, as if the user had known which one delivers TOL.
void measure_peer_ladders(const NamedScene& ns, const State& ref, const std::vector<std::string>& peers,
                          std::vector<TolRow>& rows) {
  for (const std::string& p : peers) {
    double best = std::numeric_limits<double>::infinity();
    int stalled = 0;  // rungs in a row that did not halve the best error: the peer's round-off floor
    for (int k = 6; k <= 30; ++k) {
      const double t = std::pow(10.0, -0.5 * k);
      TolRow r = measure_peer(ns, p, ref, t);
      if (!r.refusal.empty()) break;  // the peer's run failed: its ladder ends
      r.is_ladder = true;
      rows.push_back(r);
      if (r.err < kLadderFloor) break;
      stalled = r.err < 0.5 * best ? 0 : stalled + 1;
      best = std::min(best, r.err);
      if (stalled >= kLadderStalls) break;
    }
  }
}

/// bodypoint's own ladders start at this step (h, or ds) and go down by half octaves (a factor sqrt 2), so
/// that its fastest configuration at a TOL is within that factor of the best any step would give.
constexpr double kOwnFirstStep = 0.5;
constexpr double kOwnRungRatio = 1.4142135623730951;
/// An own ladder ends after this many rungs that failed (a step too coarse for the scene) or that are
/// at or below the smallest TOL asked for (the rungs that matter are above it, and one more below).
constexpr int kOwnFailures = 3;
constexpr int kOwnBelowSmallest = 2;
/// ... or after this many rungs in a row below kOwnStallBelow that did not halve its best error (a
/// first-order scheme, or its round-off floor: the thesis's schemes with B != 0 went on to 2e7 evaluations
/// a run; above it a coarse step's error need not fall yet: logh-mcl8's ladder on two-centres ended before
/// its fastest rung at 1e-10 with 3 rungs and no level),
constexpr int kOwnStalls = 6;
constexpr double kOwnStallBelow = 1e-2;
/// ... or once a run costs this many times auto's costliest call on the scene: a configuration that
/// dear is not the fastest where auto delivered (where none is cheaper, the cell says none).
constexpr double kOwnOverAuto = 4.0;

/// One rung of an own ladder: `m` at step h (fixed steps landing on t_end, or the fictitious step ds with
/// its automatic constant c), as a user would run `--method m --h h --no-error-estimate`.
Advance own_advance(const MethodInfo& m, double h, double t_end) { return advance_to(m, h, t_end); }

/// bodypoint's own configurations, untimed: every own method that takes the scene at a fixed or
/// fictitious step (not the peers; not far-ip, whose step is set by the field), from kOwnFirstStep down
/// until two rungs are below the smallest TOL, kOwnStalls rungs did not halve the error, a run would
/// exceed max_evals, or kOwnFailures steps failed. The fastest per TOL (own_best_for) is then timed with the rest.
void measure_own_ladders(const NamedScene& ns, const State& ref, double smallest_tol, double max_evals,
                         std::vector<TolRow>& rows) {
  const Body& body = ns.scene.bodies.front();
  for (const MethodInfo& m : methods()) {
    if (is_peer(m) || !refines_by_step(m)) continue;
    if (!refusal(m, body, ns.scene.centres).empty()) continue;
    int failures = 0, below = 0, stalled = 0;
    double best = std::numeric_limits<double>::infinity();
    for (double h = kOwnFirstStep; failures < kOwnFailures && below < kOwnBelowSmallest && stalled < kOwnStalls;
         h /= kOwnRungRatio) {
      const Advance how = own_advance(m, h, ns.t_end);
      if (const auto* f = std::get_if<FixedSteps>(&how);
          f && static_cast<double>(f->steps) * std::max(1, m.evals_per_step) > max_evals)
        break;
      TolRow r;
      r.scene = ns.name;
      r.method = m.name;
      r.h = h;
      r.is_own = true;
      r.method_is_exact = is_exact_flow(m);
      const BodyResult x = run_unestimated(m, body, ns.scene.centres, how, unobserved());
      if (!ran(x.outcome)) {
        ++failures;
        continue;
      }
      r.err = bodypoint::state_distance(x.run.final, ref);
      r.force_evals = std::max(x.run.force_evals, x.run.steps);  // ks counts its exact steps
      if (!std::isfinite(r.err)) r.err = std::numeric_limits<double>::infinity();
      r.run = [&m, body, centres = ns.scene.centres, how] { run_or_throw(m, body, centres, how, unobserved()); };
      rows.push_back(std::move(r));
      below = rows.back().err <= smallest_tol ? below + 1 : 0;
      stalled = rows.back().err < 0.5 * best || rows.back().err > kOwnStallBelow ? 0 : stalled + 1;
      best = std::min(best, rows.back().err);
      if (static_cast<double>(rows.back().force_evals) > max_evals) break;
    }
  }
}

/// bodypoint's fastest own configuration delivering a's TOL on a's scene whose next finer rung delivers it
/// too (the fewest force evaluations, cheaper_pick's rule without the time: it is not timed yet).
TolRow* own_best_for(std::vector<TolRow>& rows, const TolRow& a) {
  TolRow* best = nullptr;
  for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
    TolRow& r = rows[i];
    const TolRow& next = rows[i + 1];
    if (!r.is_own || r.scene != a.scene || !(r.err <= a.tol)) continue;
    if (!(next.is_own && next.method == r.method && next.scene == r.scene && next.err <= a.tol)) continue;
    if (!best || r.force_evals < best->force_evals) best = &r;
  }
  return best;
}

void write_tol_rows(std::ostream& csv, const std::vector<TolRow>& rows, const TimingRules& rules) {
  csv << "scene,method,kind,tol,h,err_estimate,err,met,runs,force_evals,wall_s,cpu_s,spread,repeats,flag,"
         "delivered_force_evals,delivered_wall_s,estimate_force_evals,own_estimate,trusted_config,trusted_force_evals\n"
      << "# bodypoint work-precision --by-tol, revision " << git_revision() << "\n"
      << "# err = max(|dR|/|R_ref|, |dv|/|v_ref|) against odeint rkf78 in long double at tol 1e-18; met = err <= tol\n"
      << "# met: refused where auto refused TOL with a reason (the summary gives it); a call is the whole request "
         "(auto: all runs of its search); h = ds for logh/ttl/ks\n"
      << "# kind own: bodypoint's fastest own configuration delivering TOL (a method at a step h, no error estimate; the "
         "fewest force evaluations on ladders from h = 0.5 down by factors sqrt 2 whose next finer rung delivers TOL too)\n"
      << timing_rules_note(rules)
      << "# delivered_* (auto only): the delivered run alone (delivered_wall_s: median of its step loop in the timed "
         "calls), the cost if the search were free\n"
      << "# estimate_force_evals, own_estimate (own only): the same configuration run as simulate --h runs it by default "
         "(invariants, error estimate): the force evaluations its estimate took beyond the run, and the estimate\n"
      << "# trusted_config, trusted_force_evals (auto only): bodypoint's cheapest own configuration (the same ladders) "
         "that delivers TOL and whose default estimate says so, and its run's and estimate's force evaluations\n";
  for (const TolRow& r : rows)
    csv << CsvLine().text(r.scene).text(r.method).text(r.is_auto ? "auto" : r.is_ladder ? "ladder" : r.is_own ? "own" : "at-tol")
               .num(r.tol).num_if(r.is_auto || r.is_own, r.h).num_if(r.is_auto, r.err_estimate).num(r.err)
               .text(r.met ? "yes" : r.refusal.empty() ? "no" : "refused").count(r.runs).count(r.force_evals).num(r.time.wall_s)
               .num(r.time.cpu_s).num(r.time.spread()).count(r.time.repeats).quoted(r.time.flag())
               .num_if(r.is_auto, static_cast<double>(r.delivered_force_evals)).num_if(r.is_auto, r.delivered_wall_s)
               .num_if(r.is_own && r.estimate_force_evals >= 0, static_cast<double>(r.estimate_force_evals))
               .num_if(r.is_own && r.estimate_force_evals >= 0, r.own_estimate).text(r.trusted)
               .num_if(!r.trusted.empty(), static_cast<double>(r.trusted_evals)).str()
        << '\n';
}

/// Whether `r` is chosen over `best` by what does not depend on the machine: fewer force evaluations
/// (equal counts: the faster, faster_pick).
bool cheaper_pick(const TolRow& r, const TolRow* best) {
  return !best || r.force_evals < best->force_evals ||
         (r.force_evals == best->force_evals && faster_pick(r.time, &best->time));
}

/// Whether `r` is a third-party peer's run at its tolerance (not auto, not a ladder, not one of bodypoint's own
/// configurations, nor logh-bs: the peer column compares auto with other projects' code).
bool third_party_at_tol(const TolRow& r) {
  return !r.is_auto && !r.is_ladder && !r.is_own && method_or_throw(r.method).traits.third_party;
}

/// The cheapest third-party peer run at auto's tolerance that met it (cheaper_pick), and how many met it.
std::pair<const TolRow*, int> cheapest_meeting(const std::vector<TolRow>& rows, const TolRow& a) {
  const TolRow* best = nullptr;
  int meeting = 0;
  for (const TolRow& r : rows) {
    if (!third_party_at_tol(r) || r.scene != a.scene || r.tol != a.tol || !r.met) continue;
    ++meeting;
    if (cheaper_pick(r, best)) best = &r;
  }
  return {best, meeting};
}

/// Oracle: the cheapest third-party ladder configuration delivering TOL whose next finer one delivers it too
/// (cheaper_pick: the fewest force evaluations, so that the choice does not depend on the machine).
const TolRow* oracle_for(const std::vector<TolRow>& rows, const TolRow& a) {
  const TolRow* oracle = nullptr;
  for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
    const TolRow& r = rows[i];
    const TolRow& next = rows[i + 1];
    if (!r.is_ladder || !method_or_throw(r.method).traits.third_party || r.scene != a.scene || !(r.err <= a.tol)) continue;
    if (!(next.is_ladder && next.method == r.method && next.scene == r.scene && next.err <= a.tol)) continue;
    if (cheaper_pick(r, oracle)) oracle = &r;
  }
  return oracle;
}

/// Both times of a comparison count (stopwatch.hpp's flag).
bool counts(const TolRow& a, const TolRow& b) { return a.time.flag().empty() && b.time.flag().empty(); }

/// auto's whole call against another's time; a refused TOL has no run to compare, and its cell says so (not
/// "flagged", which speaks of a time).
std::string auto_ratio(const TolRow& a, const Timing& other) {
  return a.refusal.empty() ? ratio_cell(&a.time, &other) : std::string("refused");
}

/// auto's delivered run alone, in ms, flagged with the whole call's timing.
std::string delivered_cell(const TolRow& a) {
  if (!(a.delivered_wall_s > 0.0)) return "-";
  Timing t = a.time;
  t.wall_s = a.delivered_wall_s;
  return time_cell(t);
}

/// The last cells of auto's summary row: bodypoint's fastest own configuration delivering TOL (its step
/// and evaluations), its time, auto's whole call over it in evaluations and in time, and what auto's
/// search costs beyond its delivered run (evaluations), and what the fastest configuration's default error
/// estimate costs beyond it (evaluations; measure_own_estimates).
void write_own_cells(std::ostream& summary, const std::vector<TolRow>& rows, const TolRow& a, std::vector<double>& ratios) {
  const TolRow* own = nullptr;
  for (const TolRow& r : rows)
    if (r.is_own && r.scene == a.scene && r.tol == a.tol && r.err <= a.tol) own = &r;  // marked by mark_own_bests
  if (own && a.refusal.empty()) {
    summary << own->method << " h=" << sci(own->h) << " (" << own->force_evals << " evals) | " << time_cell(own->time) << " | ";
    // ks evaluates no force (its flow is exact; its ladder counts steps): no ratio of evaluations.
    if (a.force_evals > 0 && !own->method_is_exact) {
      const double evals = static_cast<double>(a.force_evals) / static_cast<double>(std::max(1L, own->force_evals));
      ratios.push_back(evals);
      summary << std::setprecision(3) << evals << "x | ";
    } else {
      summary << "- (no force evaluations) | ";
    }
    summary << ratio_cell(&own->time, &a.time) << " | ";
  } else {
    summary << "none | - | - | - | ";
  }
  if (a.refusal.empty() && a.delivered_force_evals > 0)
    summary << std::setprecision(3)
            << static_cast<double>(a.force_evals - a.delivered_force_evals) / static_cast<double>(a.delivered_force_evals)
            << "x | ";
  else
    summary << "- | ";
  // What knowing its error costs that configuration (simulate --h's default estimate), and that estimate.
  if (own && own->estimate_force_evals >= 0 && own->force_evals > 0)
    summary << std::setprecision(3)
            << static_cast<double>(own->estimate_force_evals) / static_cast<double>(own->force_evals) << "x ("
            << sci(own->own_estimate) << " for " << sci(own->err) << ") | ";
  else
    summary << "- | ";
}

/// The last cells of auto's summary row: bodypoint's cheapest own configuration that delivers TOL with a
/// default estimate that says so (its run and estimate in force evaluations), and auto's whole call over it.
void write_trusted_cells(std::ostream& summary, const TolRow& a, std::vector<double>& ratios) {
  if (a.trusted.empty() || !a.refusal.empty()) {
    summary << (a.trusted.empty() ? "none" : a.trusted) << " | - |\n";
    return;
  }
  summary << a.trusted << " (" << a.trusted_evals << " evals) | ";
  if (a.force_evals > 0 && a.trusted_evals > 0) {
    const double r = static_cast<double>(a.force_evals) / static_cast<double>(a.trusted_evals);
    ratios.push_back(r);
    summary << std::setprecision(3) << r << "x |\n";
  } else {
    summary << "- (no force evaluations) |\n";
  }
}

/// "median Mx, from Ax to Bx (N <what>).\n" of `values`, a sentence's end under the table.
std::string median_range(std::vector<double> values, const char* what) {
  std::sort(values.begin(), values.end());
  std::ostringstream os;
  os << "median " << std::setprecision(3) << median(values) << "x, from " << values.front() << "x to " << values.back()
     << "x (" << values.size() << " " << what << ").\n";
  return os.str();
}

/// The prices under the table: auto over bodypoint's own fastest configuration (`own_ratios`, force
/// evaluations of the whole call), that configuration's default error estimate over its run, and auto over
/// the cheapest configuration whose default estimate shows TOL (`trusted_ratios`, its run and estimate).
void write_price_medians(std::ostream& summary, const std::vector<TolRow>& rows, const std::vector<double>& own_ratios,
                         const std::vector<double>& trusted_ratios) {
  if (!own_ratios.empty())
    summary << "\nauto against bodypoint's own fastest configuration delivering TOL, force evaluations of the whole call: "
            << median_range(own_ratios, "cases");
  std::vector<double> estimate_prices;  // the fastest configurations' default estimate over their run, evaluations
  for (const TolRow& r : rows)
    if (r.is_own && r.estimate_force_evals >= 0 && r.force_evals > 0 && !r.method_is_exact)
      estimate_prices.push_back(static_cast<double>(r.estimate_force_evals) / static_cast<double>(r.force_evals));
  if (!estimate_prices.empty())
    summary << "\nThe default error estimate of bodypoint's fastest configuration (simulate --h), force evaluations "
            << "beyond the run: " << median_range(estimate_prices, "configurations");
  if (!trusted_ratios.empty())
    summary << "\nauto against bodypoint's cheapest configuration that delivers TOL with a default estimate saying so "
            << "(its run and estimate), force evaluations: " << median_range(trusted_ratios, "cases");
}

void write_tol_summary(std::ostream& summary, const std::vector<TolRow>& rows, std::size_t peer_count) {
  summary << "| scene | TOL | auto method | ds or h | estimate | delivered | met | time [ms] | cheapest peer meeting TOL "
             "| time [ms] | speed-up | peers meeting TOL | cheapest peer config delivering TOL | time [ms] | speed-up "
             "| delivered run [ms] | speed-up if the search were free | bodypoint's fastest config delivering TOL "
             "| time [ms] | auto / it, evals | auto / it, time | auto's search beyond its delivered run / that run, evals "
             "| its estimate / it, evals (estimate for error) | bodypoint's cheapest config whose estimate shows TOL "
             "(run + estimate) | auto / it, evals |\n"
          << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  int met = 0, refused = 0, total = 0, faster3 = 0, compared = 0, oracle3 = 0, oracle_n = 0;
  std::vector<double> own_ratios;  // auto over bodypoint's fastest configuration, force evaluations
  std::vector<double> trusted_ratios;  // auto over the cheapest configuration whose estimate shows TOL
  std::ostringstream refusals;
  for (const TolRow& a : rows) {
    if (!a.is_auto) continue;
    const auto [best, meeting] = cheapest_meeting(rows, a);
    const TolRow* oracle = oracle_for(rows, a);
    ++total;
    met += a.met ? 1 : 0;
    refused += a.refusal.empty() ? 0 : 1;
    if (!a.refusal.empty()) refusals << "- " << a.scene << ", TOL " << sci(a.tol, 0) << ": " << a.refusal << "\n";
    summary << "| " << a.scene << " | " << sci(a.tol, 0) << " | " << a.method << " | " << std::setprecision(3)
            << a.h << " | " << sci(a.err_estimate) << " | " << sci(a.err) << " | "
            << (a.met ? "yes" : a.refusal.empty() ? "**no**" : "refused") << " | "
            << (a.refusal.empty() ? time_cell(a.time) : "-") << " | ";
    if (best) {
      const std::string ratio = auto_ratio(a, best->time);
      ++compared;
      faster3 += counts(a, *best) && best->time.wall_s >= 3.0 * a.time.wall_s ? 1 : 0;
      summary << best->method << " (" << best->force_evals << " evals) | " << time_cell(best->time) << " | " << ratio << " | ";
    } else {
      summary << "none | - | - | ";
    }
    summary << meeting << "/" << peer_count << " | ";
    if (oracle) {
      ++oracle_n;
      oracle3 += counts(a, *oracle) && oracle->time.wall_s >= 3.0 * a.time.wall_s ? 1 : 0;
      summary << oracle->method << " tol=" << sci(oracle->tol, 1) << " (" << oracle->force_evals << " evals) | "
              << time_cell(oracle->time) << " | "
              << auto_ratio(a, oracle->time) << " | " << delivered_cell(a) << " | ";
      if (a.delivered_wall_s > 0.0 && a.time.flag().empty() && oracle->time.flag().empty())
        summary << std::setprecision(3) << oracle->time.wall_s / a.delivered_wall_s << "x | ";
      else
        summary << (a.delivered_wall_s > 0.0 ? "flagged" : "-") << " | ";
    } else {
      summary << "none | - | - | " << delivered_cell(a) << " | - | ";
    }
    write_own_cells(summary, rows, a, own_ratios);
    write_trusted_cells(summary, a, trusted_ratios);
  }
  summary << "\nauto met TOL in " << met << " of " << total << " cases";
  if (refused > 0) summary << " and refused " << refused << " with its reason (below)";
  summary << "; where a peer met it too, auto was >= 3x "
          << "faster in " << faster3 << " of " << compared << "; against the cheapest peer configuration that "
          << "delivers TOL (its tolerance chosen afterwards), >= 3x in " << oracle3 << " of " << oracle_n
          << " (a comparison with a flagged time counts as not >= 3x).\n";
  write_price_medians(summary, rows, own_ratios, trusted_ratios);
  if (refused > 0) summary << "\nauto refused:\n\n" << refusals.str();
}

}  // namespace

/// An own row's configuration made again as `simulate --method M --h h` makes it (Options' defaults: invariants
/// tracked, the estimate on), untimed: its estimate's force evaluations and value (none where the run does not
/// end ok: own_estimate is then +inf, so that it is not made again).
void estimate_own(const NamedScene& ns, TolRow& r) {
  const MethodInfo& m = method_or_throw(r.method);
  const BodyResult x = integrate_body(ns.scene.bodies.front(), ns.scene.centres, &m, own_advance(m, r.h, ns.t_end), Options{});
  if (x.outcome != Outcome::ok || !x.error.known()) {
    r.own_estimate = std::numeric_limits<double>::infinity();
    return;
  }
  r.estimate_force_evals = x.error.force_evals;
  r.own_estimate = x.error.value;
}

/// The price of the default error estimate on each own row from `first` (mark_own_bests' rows; estimate_own),
/// where mark_trusted_bests did not make it already.
void measure_own_estimates(const NamedScene& ns, std::vector<TolRow>& rows, std::size_t first) {
  for (std::size_t i = first; i < rows.size(); ++i) {
    TolRow& r = rows[i];
    if (!r.is_own || r.estimate_force_evals >= 0 || std::isinf(r.own_estimate)) continue;
    // One configuration fastest at several TOLs has a row per TOL: made once, its numbers copied.
    const auto same = std::find_if(rows.begin() + static_cast<std::ptrdiff_t>(first), rows.begin() + static_cast<std::ptrdiff_t>(i),
                                   [&](const TolRow& o) { return o.is_own && o.method == r.method && o.h == r.h; });
    if (same != rows.begin() + static_cast<std::ptrdiff_t>(i)) {
      r.estimate_force_evals = same->estimate_force_evals;
      r.own_estimate = same->own_estimate;
      continue;
    }
    estimate_own(ns, r);
  }
}

/// For each auto row of the scene (rows [first, own_first)), bodypoint's cheapest own configuration (rows from
/// own_first, every rung of the own ladders) that delivers its TOL and whose default estimate says so: what a
/// user who cannot know the error pays to trust a configuration chosen by hand, the run and its estimate.
/// Rungs are tried by their run's evaluations, each estimated once, until a run alone costs more than the
/// best price found.
void mark_trusted_bests(const NamedScene& ns, std::vector<TolRow>& rows, std::size_t first, std::size_t own_first) {
  std::vector<std::size_t> order;
  for (std::size_t i = own_first; i < rows.size(); ++i) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return rows[x].force_evals < rows[y].force_evals; });
  for (std::size_t i = first; i < own_first; ++i) {
    TolRow& a = rows[i];
    if (!a.is_auto) continue;
    long best = std::numeric_limits<long>::max();
    for (std::size_t k : order) {
      TolRow& r = rows[k];
      if (r.force_evals >= best) break;
      if (!(r.err <= a.tol)) continue;
      if (r.estimate_force_evals < 0 && std::isnan(r.own_estimate)) estimate_own(ns, r);
      if (!(r.own_estimate <= a.tol) || r.estimate_force_evals < 0) continue;
      if (r.force_evals + r.estimate_force_evals < best) {
        best = r.force_evals + r.estimate_force_evals;
        a.trusted = r.method + " h=" + sci(r.h);
        a.trusted_evals = best;
      }
    }
  }
}

/// Keeps the own rows (from own_first) that are the fastest at one of the scene's TOLs (own_best_for), each
/// stamped with that TOL (one copy per TOL it is fastest at), and drops the others: only they are timed.
void mark_own_bests(std::vector<TolRow>& rows, std::size_t first, std::size_t own_first) {
  std::vector<TolRow> bests;
  for (std::size_t i = first; i < own_first; ++i) {
    if (!rows[i].is_auto) continue;
    if (TolRow* b = own_best_for(rows, rows[i])) {
      TolRow copy = *b;
      copy.tol = rows[i].tol;
      copy.met = true;  // own_best_for: its error is at most TOL
      bests.push_back(std::move(copy));
    }
  }
  rows.resize(own_first);
  for (TolRow& b : bests) rows.push_back(std::move(b));
}

/// Times every row of one scene (rows [first, end)) interleaved; auto's delivered run from its samples.
void time_rows(std::vector<TolRow>& rows, std::size_t first, const TimingRules& rules) {
  std::vector<std::function<void()>> runs;
  for (std::size_t i = first; i < rows.size(); ++i)
    if (rows[i].run) runs.push_back(rows[i].run);
  const std::vector<Timing> t = time_interleaved(runs, rules);
  std::size_t k = 0;
  for (std::size_t i = first; i < rows.size(); ++i) {
    if (!rows[i].run) continue;
    rows[i].time = t[k++];
    if (rows[i].delivered_samples && !rows[i].delivered_samples->empty())
      rows[i].delivered_wall_s = median(*rows[i].delivered_samples);
  }
}

void run_by_tolerance(const std::vector<NamedScene>& scenes, const std::vector<double>& tols, const TimingRules& rules,
                      double max_evals, std::ostream* csv, std::ostream& summary) {
  std::vector<TolRow> rows;
  const std::vector<std::string> peers = peer_names();
  for (const NamedScene& ns : scenes) {
    const State ref = reference_state(ns.scene.bodies.front(), ns.scene.centres, ns.t_end, 1e-18L);
    const std::size_t first = rows.size();
    measure_at_tolerances(ns, ref, tols, peers, rows);
    measure_peer_ladders(ns, ref, peers, rows);
    const std::size_t own_first = rows.size();
    double auto_evals = 0.0;
    for (std::size_t i = first; i < own_first; ++i)
      if (rows[i].is_auto) auto_evals = std::max(auto_evals, static_cast<double>(rows[i].force_evals));
    const double own_cap = auto_evals > 0.0 ? std::min(max_evals, kOwnOverAuto * auto_evals) : max_evals;
    measure_own_ladders(ns, ref, *std::min_element(tols.begin(), tols.end()), own_cap, rows);
    mark_trusted_bests(ns, rows, first, own_first);
    mark_own_bests(rows, first, own_first);
    measure_own_estimates(ns, rows, own_first);
    std::cerr << "  " << ns.name << ": timing " << rows.size() - first << " configurations, interleaved\n";
    time_rows(rows, first, rules);
  }
  if (csv) write_tol_rows(*csv, rows, rules);
  const auto third_party = std::count_if(peers.begin(), peers.end(), [](const std::string& p) { return method_or_throw(p).traits.third_party; });
  write_tol_summary(summary, rows, static_cast<std::size_t>(third_party));
}

}  // namespace bodypoint::cli

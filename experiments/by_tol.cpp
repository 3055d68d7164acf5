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

#include "bodypoint/adaptive/tolerance.hpp"
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
  std::string refusal;  ///< auto refused TOL (out of reach on the scene, over the budget): why; "" otherwise
  bool is_auto = false;
  bool is_ladder = false;  ///< a peer's run from its tolerance ladder (oracle view), not at TOL
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
    if (is_step_controlled(m)) out.emplace_back(m.name);
  return out;
}

TolRow measure_auto(const NamedScene& ns, const State& ref, double tol) {
  const Body& body = ns.scene.bodies.front();
  TolRow row;
  row.scene = ns.name;
  row.tol = tol;
  row.is_auto = true;
  const MethodInfo& m = choose_method(body, ns.scene.centres, tol, nullptr);
  row.method = std::string(m.name);
  const Accuracy accuracy{tol, ns.t_end};
  const adaptive::ToleranceResult r =
      adaptive::run_to_tolerance(m, body, ns.scene.centres, accuracy, unobserved(), false);  // as auto
  row.h = r.h;
  row.err_estimate = r.err_estimate;
  row.err = adaptive::state_distance(r.result.final, ref);
  row.met = row.err <= tol;
  row.delivered_samples = std::make_shared<std::vector<double>>();
  row.run = [&m, body, centres = ns.scene.centres, accuracy, samples = row.delivered_samples] {
    const adaptive::ToleranceResult x = adaptive::run_to_tolerance(m, body, centres, accuracy, unobserved(), false);
    samples->push_back(x.result.wall_s);
  };
  row.force_evals = r.total_force_evals;
  row.delivered_force_evals = r.result.force_evals;
  row.runs = r.runs;
  return row;
}

TolRow measure_peer(const NamedScene& ns, const std::string& name, const State& ref, double tol) {
  const Body& body = ns.scene.bodies.front();
  TolRow row;
  row.scene = ns.name;
  row.method = name;
  row.tol = tol;
  const ControlledSteps how{1e-3, ns.t_end, tol};
  const MethodInfo& m = method_or_throw(name);
  const RunResult r = run_or_throw(m, body, ns.scene.centres, how, unobserved());
  row.run = [&m, body, centres = ns.scene.centres, how] { run_or_throw(m, body, centres, how, unobserved()); };
  row.err = adaptive::state_distance(r.final, ref);
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
    try {
      rows.push_back(measure_auto(ns, ref, tol));
    } catch (const Error& e) {
      TolRow refused;
      refused.scene = ns.name;
      refused.tol = tol;
      refused.is_auto = true;
      refused.method = "refused";
      refused.err = refused.err_estimate = std::numeric_limits<double>::quiet_NaN();
      refused.refusal = e.what();
      rows.push_back(refused);
      std::cerr << "  " << ns.name << " tol " << sci(tol, 0) << ": auto refused (" << e.what() << ")\n";
      continue;
    }
    std::cerr << "  " << ns.name << " tol " << sci(tol, 0) << ": auto " << rows.back().method << " err "
              << sci(rows.back().err) << " (estimate " << sci(rows.back().err_estimate) << ")\n";
    for (const std::string& p : peers) {
      try {
        rows.push_back(measure_peer(ns, p, ref, tol));
      } catch (const Error& e) {
        std::cerr << "  " << ns.name << " " << p << " tol " << sci(tol, 0) << ": failed (" << e.what() << ")\n";
      }
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
      try {
        TolRow r = measure_peer(ns, p, ref, t);
        r.is_ladder = true;
        rows.push_back(r);
        if (r.err < kLadderFloor) break;
        stalled = r.err < 0.5 * best ? 0 : stalled + 1;
        best = std::min(best, r.err);
        if (stalled >= kLadderStalls) break;
      } catch (const Error& e) {
        break;
      }
    }
  }
}

void write_tol_rows(std::ostream& csv, const std::vector<TolRow>& rows, const TimingRules& rules) {
  csv << "scene,method,kind,tol,h,err_estimate,err,met,runs,force_evals,wall_s,cpu_s,spread,repeats,flag,"
         "delivered_force_evals,delivered_wall_s\n"
      << "# bodypoint work-precision --by-tol, revision " << git_revision() << "\n"
      << "# err = max(|dR|/|R_ref|, |dv|/|v_ref|) against odeint rkf78 in long double at tol 1e-18; met = err <= tol\n"
      << "# met: refused where auto refused TOL with a reason (the summary gives it); a call is the whole request "
         "(auto: all runs of its search); h = ds for logh/ttl/ks\n"
      << timing_rules_note(rules)
      << "# delivered_* (auto only): the delivered run alone (delivered_wall_s: median of its step loop in the timed "
         "calls), the cost if the search were free\n";
  for (const TolRow& r : rows)
    csv << CsvLine().text(r.scene).text(r.method).text(r.is_auto ? "auto" : r.is_ladder ? "ladder" : "at-tol")
               .num(r.tol).num_if(r.is_auto, r.h).num_if(r.is_auto, r.err_estimate).num(r.err)
               .text(r.met ? "yes" : r.refusal.empty() ? "no" : "refused").count(r.runs).count(r.force_evals).num(r.time.wall_s)
               .num(r.time.cpu_s).num(r.time.spread()).count(r.time.repeats).quoted(r.time.flag())
               .num_if(r.is_auto, static_cast<double>(r.delivered_force_evals)).num_if(r.is_auto, r.delivered_wall_s).str()
        << '\n';
}

/// Whether `r` is chosen over `best` by what does not depend on the machine: fewer force evaluations
/// (equal counts: the faster, faster_pick).
bool cheaper_pick(const TolRow& r, const TolRow* best) {
  return !best || r.force_evals < best->force_evals ||
         (r.force_evals == best->force_evals && faster_pick(r.time, &best->time));
}

/// The cheapest peer run at auto's tolerance that met it (cheaper_pick), and how many met it.
std::pair<const TolRow*, int> cheapest_meeting(const std::vector<TolRow>& rows, const TolRow& a) {
  const TolRow* best = nullptr;
  int meeting = 0;
  for (const TolRow& r : rows) {
    if (r.is_auto || r.is_ladder || r.scene != a.scene || r.tol != a.tol || !r.met) continue;
    ++meeting;
    if (cheaper_pick(r, best)) best = &r;
  }
  return {best, meeting};
}

/// Oracle: the cheapest ladder configuration delivering TOL whose next finer one delivers it too
/// (cheaper_pick: the fewest force evaluations, so that the choice does not depend on the machine).
const TolRow* oracle_for(const std::vector<TolRow>& rows, const TolRow& a) {
  const TolRow* oracle = nullptr;
  for (std::size_t i = 0; i + 1 < rows.size(); ++i) {
    const TolRow& r = rows[i];
    const TolRow& next = rows[i + 1];
    if (!r.is_ladder || r.scene != a.scene || !(r.err <= a.tol)) continue;
    if (!(next.is_ladder && next.method == r.method && next.scene == r.scene && next.err <= a.tol)) continue;
    if (cheaper_pick(r, oracle)) oracle = &r;
  }
  return oracle;
}

/// Both times of a comparison count (stopwatch.hpp's flag).
bool counts(const TolRow& a, const TolRow& b) { return a.time.flag().empty() && b.time.flag().empty(); }

/// auto's delivered run alone, in ms, flagged with the whole call's timing.
std::string delivered_cell(const TolRow& a) {
  if (!(a.delivered_wall_s > 0.0)) return "-";
  Timing t = a.time;
  t.wall_s = a.delivered_wall_s;
  return time_cell(t);
}

void write_tol_summary(std::ostream& summary, const std::vector<TolRow>& rows, std::size_t peer_count) {
  summary << "| scene | TOL | auto method | ds or h | estimate | delivered | met | time [ms] | cheapest peer meeting TOL "
             "| time [ms] | speed-up | peers meeting TOL | cheapest peer config delivering TOL | time [ms] | speed-up "
             "| delivered run [ms] | speed-up if the search were free |\n"
          << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  int met = 0, refused = 0, total = 0, faster3 = 0, compared = 0, oracle3 = 0, oracle_n = 0;
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
      const std::string ratio = ratio_cell(&a.time, &best->time);
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
              << ratio_cell(&a.time, &oracle->time) << " | " << delivered_cell(a) << " | ";
      if (a.delivered_wall_s > 0.0 && a.time.flag().empty() && oracle->time.flag().empty())
        summary << std::setprecision(3) << oracle->time.wall_s / a.delivered_wall_s << "x |\n";
      else
        summary << (a.delivered_wall_s > 0.0 ? "flagged" : "-") << " |\n";
    } else {
      summary << "none | - | - | " << delivered_cell(a) << " | - |\n";
    }
  }
  summary << "\nauto met TOL in " << met << " of " << total << " cases";
  if (refused > 0) summary << " and refused " << refused << " with its reason (below)";
  summary << "; where a peer met it too, auto was >= 3x "
          << "faster in " << faster3 << " of " << compared << "; against the cheapest peer configuration that "
          << "delivers TOL (its tolerance chosen afterwards), >= 3x in " << oracle3 << " of " << oracle_n
          << " (a comparison with a flagged time counts as not >= 3x).\n";
  if (refused > 0) summary << "\nauto refused:\n\n" << refusals.str();
}

}  // namespace

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
                      std::ostream* csv, std::ostream& summary) {
  std::vector<TolRow> rows;
  const std::vector<std::string> peers = peer_names();
  for (const NamedScene& ns : scenes) {
    const State ref = reference_state(ns.scene.bodies.front(), ns.scene.centres, ns.t_end, 1e-18L);
    const std::size_t first = rows.size();
    measure_at_tolerances(ns, ref, tols, peers, rows);
    measure_peer_ladders(ns, ref, peers, rows);
    std::cerr << "  " << ns.name << ": timing " << rows.size() - first << " configurations, interleaved\n";
    time_rows(rows, first, rules);
  }
  if (csv) write_tol_rows(*csv, rows, rules);
  write_tol_summary(summary, rows, peers.size());
}

}  // namespace bodypoint::cli

// `bodypoint work-precision`: final-position error against run time for every method, side by side
// with Boost.Odeint, on named scenes (lib/core/model/bodypoint/scenes.hpp).
//
// For each scene the reference is Boost.Odeint rkf78 in long double at tolerance 1e-18; its own error
// is estimated as the larger of its distance to the same integration at tolerance 1e-15 and to the
// 10th-order Lie-Poisson method at a small step (two independent cross-checks). For each method a
// ladder of steps (halving h) or tolerances (dividing by 10) is run once, untimed, for its error, and
// once more with invariant tracking for max_rel_dE; then every configuration of the scene is timed
// under the commands' timing rules (stopwatch.hpp: warm-up, repeats interleaved across all of them,
// wall and CPU time, median and spread, a flag where the time does not count).
#include "process.hpp"
#include "bodypoint/accuracy.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/reference.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/scenes.hpp"
#include "by_tol.hpp"
#include "cli.hpp"
#include "stopwatch.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

namespace bodypoint::cli {
namespace {

struct Row {
  std::string scene, method;
  double h = 0, tol = 0;  // one of them set
  double err_R = 0, err_rel = 0, max_rel_dE = 0;
  long force_evals = 0;
  Timing time;                  ///< from the scene's interleaved timing (stopwatch.hpp)
  std::function<void()> run;    ///< the configuration's run, as timed
};

/// A step-size-controlled ladder ends after this many decades of tolerance in a row that did not halve
/// its best error: its round-off floor (scene long's rkf45 and dopri5 went on to tol 1e-14 for nothing).
constexpr int kPeerStallDecades = 2;
/// far-ip's ladder starts here: 55 rad of spin per step on table 3.1, beyond which its points (2 per
/// radian) no longer resolve what the field's slow scale r/|v| changes at r = 50 (far_field.hpp).
constexpr double kFarFieldFirstStep = 8.0;

/// Small-step run of the highest-order splitting, as a cross-check of the reference.
double splitting_check_step(const std::string& scene) { return scene == "close" ? 5e-4 : 5e-3; }

struct Options {
  TimingRules timing;
  double max_evals = 2e7;     ///< stop a ladder when a run would exceed this many force evaluations
  double floor = 1e-13;       ///< stop a ladder after two runs in a row below this relative error
  bool cap_peers = false;     ///< --quick: max_evals ends the peers' ladders too (never in a full run)
};

/// One configuration run once, untimed: its error, force evaluations and energy error. The time comes
/// later, from the scene's interleaved timing of every configuration (time_scene). No row where the run
/// is refused or fails: `why` says why.
std::optional<Row> measure(const NamedScene& ns, const MethodInfo& m, const Body& body, const State& ref, double h,
                           double tol, std::string& why) {
  // h: the step or the fictitious step ds (0 for a controlled method: its own first trial step); tol: a
  // controlled method's tolerance per step (0 for the others).
  const Advance how = advance_of(m, {.step = h, .end = ns.t_end, .tol = tol, .grid = FixedGrid::nearest});
  const auto* fixed = std::get_if<FixedSteps>(&how);
  const double step = fixed ? fixed->h : h;  // the step of the row: h, or the fictitious step ds
  const BodyResult plain = run_unestimated(m, body, ns.scene.centres, how, unobserved());
  if (!ran(plain.outcome)) {
    why = plain.reason;
    return std::nullopt;
  }
  const RunResult& r = plain.run;
  const RunResult ri = run_or_throw(m, body, ns.scene.centres, how, bodypoint::Options{});  // the same run, monitored
  Row row;
  row.scene = ns.name;
  row.method = std::string(m.name);
  row.h = step;  // for time-transformed methods: ds; 0 for a controlled method
  row.tol = tol;  // 0 but for a controlled method
  row.err_R = (r.final.R - ref.R).norm();
  if (!std::isfinite(row.err_R)) row.err_R = std::numeric_limits<double>::infinity();
  // The tool's one error norm (ErrorEstimate, --tol): max(|dR|/|R|, |dv|/|v|) of the final state.
  row.err_rel = bodypoint::state_distance(r.final, ref);
  if (!std::isfinite(row.err_rel)) row.err_rel = std::numeric_limits<double>::infinity();
  row.max_rel_dE = ri.invariants ? ri.invariants->max_rel_dE : 0.0;
  row.force_evals = r.force_evals;
  row.run = [&m, body, centres = ns.scene.centres, how] { run_or_throw(m, body, centres, how, unobserved()); };
  return row;
}

/// Times every configuration of one scene (rows [first, end)), interleaved (stopwatch.hpp).
void time_scene(std::vector<Row>& rows, std::size_t first, const TimingRules& rules) {
  std::vector<std::function<void()>> runs;
  for (std::size_t i = first; i < rows.size(); ++i) runs.push_back(rows[i].run);
  const std::vector<Timing> t = time_interleaved(runs, rules);
  for (std::size_t i = first; i < rows.size(); ++i) rows[i].time = t[i - first];
}

struct WorkPrecisionArgs {
  std::string scenes = "all", methods = "all", out, summary;
  std::string tols = "1e-4,1e-5,1e-6,1e-7,1e-8,1e-9,1e-10,1e-11,1e-12";
  bool quick = false, by_tol = false, list_scenes = false;
  Options o;
};

void add_work_precision_options(po::options_description& desc, WorkPrecisionArgs& a) {
  desc.add_options()
      ("scenes", defaulted(&a.scenes), "comma-separated: thesis,close,material,long,two-centres,three-centres or all")
      ("methods", defaulted(&a.methods), "comma-separated method names or all")
      ("repeats", defaulted(&a.o.timing.repeats), "timed repeats per configuration, "
       "interleaved across the configurations (median and spread reported; fewer than 5 flag every time)")
      ("max-evals", defaulted(&a.o.max_evals), "largest run of a ladder, in force evaluations")
      ("by-tol", po::bool_switch(&a.by_tol), "second view: auto and every step-size-controlled peer with the same "
       "requested tolerance; delivered error, whether it met TOL, and time; auto against bodypoint's own fastest "
       "configuration delivering TOL (a method at a step; evaluations and time), what that configuration's default "
       "error estimate costs (evaluations), and against the cheapest own configuration that delivers TOL with a "
       "default estimate saying so (its run and estimate, evaluations)")
      ("tols", defaulted(&a.tols), "with --by-tol: the tolerances")
      ("list-scenes", po::bool_switch(&a.list_scenes), "print the named scenes that 'all' means, one per line, and exit")
      ("quick", po::bool_switch(&a.quick), "coarse: scenes thesis and material, every ladder (the peers' too) up to 1e6 force evaluations")
      ("out", po::value(&a.out), "CSV: scene, method, h, tol, err_R, err_rel, max_rel_dE, force_evals, wall_s, cpu_s, "
       "spread, repeats, flag")
      ("summary", po::value(&a.summary), "also write the summary table (Markdown) to this file");
}

/// --quick's defaults and the checks of the numbers.
void settle(const po::variables_map& vm, WorkPrecisionArgs& a) {
  if (a.quick) {
    if (vm["scenes"].defaulted()) a.scenes = "thesis,material";
    a.o.cap_peers = true;  // coarse: scene long's low-order peers down to tol 1e-14 took 130 of 270 s
    if (vm["max-evals"].defaulted()) a.o.max_evals = 1e6;
  }
  check_rules(a.o.timing);
  if (!(a.o.max_evals >= 1)) throw Error("--max-evals must be >= 1");
  // Options that would be ignored or would write an empty table are refused.
  if (!vm["tols"].defaulted() && !a.by_tol) throw Error("--tols is for --by-tol");
  if (vm.count("summary") && a.summary.empty()) throw Error("--summary needs a file name");
  if (vm.count("out") && a.out.empty()) throw Error("--out needs a file name");
  if (split_list(a.scenes).empty()) throw Error("--scenes is empty (thesis, close, material, long, two-centres, three-centres or all)");
}

std::vector<const MethodInfo*> chosen_methods(const std::string& arg) {
  std::vector<const MethodInfo*> ms;
  if (arg == "all") {
    for (const MethodInfo& m : methods()) ms.push_back(&m);
  } else {
    for (const std::string& n : split_list(arg)) ms.push_back(&method_or_throw(n));
  }
  if (ms.empty()) throw Error("--methods is empty");
  return ms;
}

/// The scene's reference state; its estimated error is noted in `refs` (and on stderr).
State reference_of(const NamedScene& ns, std::ostringstream& refs) {
  const Body& body = ns.scene.bodies.front();
  const State ref = reference_state(body, ns.scene.centres, ns.t_end, 1e-18L);
  const State loose = reference_state(body, ns.scene.centres, ns.t_end, 1e-15L);
  const long steps = std::lround(ns.t_end / splitting_check_step(ns.name));
  const FixedSteps check_steps{ns.t_end / static_cast<double>(steps), steps};
  const State split = run_or_throw(method_or_throw("lp-ss10"), body, ns.scene.centres, check_steps, unobserved()).final;
  const double ref_err = std::max((ref.R - loose.R).norm(), (ref.R - split.R).norm());
  const double ref_rel = std::max(bodypoint::state_distance(loose, ref), bodypoint::state_distance(split, ref));
  std::ostringstream line;
  line << "reference " << ns.name << ": odeint rkf78 long double tol 1e-18, t_end " << fmt(ns.t_end)
       << ", |R_ref| = " << fmt(ref.R.norm()) << ", estimated error " << std::setprecision(2) << std::scientific
       << ref_err << " (relative " << ref_rel << ", max(|dR|/|R|, |dv|/|v|))" << std::defaultfloat << "\n";
  refs << line.str();
  std::cerr << line.str();
  return ref;
}

/// One method's ladder on one scene: halving ds (time-transformed) or h, or tolerances divided by 10,
/// until two runs in a row are below the floor or a run exceeds the budget. A configuration that fails (a
/// fictitious step too coarse for the encounter) is left out, with a note. One kind of ladder per method:
/// an exact flow's single configuration, fictitious steps, tolerances per step, fixed steps.
class Ladder {
 public:
  Ladder(const NamedScene& ns, const MethodInfo& m, const State& ref, const Options& o, std::vector<Row>& rows)
      : ns_(ns), m_(m), body_(ns.scene.bodies.front()), ref_(ref), o_(o), rows_(rows),
        // A peer's ladder has no evaluation cap but in --quick: it ends at its tolerance 1e-14, below the
        // floor or at its round-off floor, so a peer that delivers a target is never cut to "-" by a budget.
        capped_(!is_peer(m) || o.cap_peers) {}

  void run() {
    if (is_exact_flow(m_)) exact();
    else if (is_time_transformed(m_)) fictitious();
    else if (is_step_controlled(m_)) tolerances();
    else fixed();
  }

 private:
  /// Measures m at step h or tolerance tol into `row`; false (with a note) where the run fails.
  bool try_measure(double h, double tol, Row& row) {
    std::string why;
    std::optional<Row> r = measure(ns_, m_, body_, ref_, h, tol, why);
    if (!r) {
      std::cerr << "  " << ns_.name << " " << m_.name << (tol > 0 ? " tol=" : " h=") << fmt(tol > 0 ? tol : h)
                << ": skipped (" << why << ")\n";
      return false;
    }
    row = std::move(*r);
    return true;
  }
  /// Keeps the row; true while the ladder goes on (not two rows below the floor, not over the budget).
  bool keep(const Row& r) {
    rows_.push_back(r);
    below_ = r.err_rel < o_.floor ? below_ + 1 : 0;
    return below_ < 2 && (!capped_ || static_cast<double>(r.force_evals) <= o_.max_evals);
  }
  /// Exact in its fictitious time: one configuration, the run of one fictitious step to t_end (the first
  /// ds, doubled from 0.2, whose run takes a single step); a ladder would time one answer many times.
  void exact() {
    Row r;
    for (double ds = 0.2; ds <= 1e6; ds *= 2) {
      if (!try_measure(ds, 0, r)) break;
      const RunResult one = run_or_throw(m_, body_, ns_.scene.centres, FictitiousSteps{ds, EndTime{ns_.t_end}}, unobserved());
      if (one.steps <= 1) {
        rows_.push_back(r);
        break;
      }
    }
  }
  void fictitious() {
    Row r;
    int failures = 0;
    for (double ds = 0.2; ds >= 1e-5; ds /= 2) {
      if (!try_measure(ds, 0, r)) {
        if (++failures > 2) break;  // too coarse for the encounter three times
        continue;
      }
      if (!keep(r)) break;
    }
  }
  void tolerances() {
    Row r;
    double best = std::numeric_limits<double>::infinity();
    int stalled = 0;  // decades in a row that did not halve the best error: the peer's round-off floor
    for (double tol = 1e-3; tol >= 1e-14; tol /= 10) {
      if (!try_measure(0, tol, r) || !keep(r)) break;  // a tolerance the controller cannot meet
      stalled = r.err_rel < 0.5 * best ? 0 : stalled + 1;
      best = std::min(best, r.err_rel);
      if (stalled >= kPeerStallDecades) break;
    }
  }
  /// Fixed steps halving from 0.5 (far-ip's from kFarFieldFirstStep: its step is tens of radians of spin,
  /// far_field.hpp); a step the method cannot take on the scene (an iteration that diverges there, as far-ip's
  /// collocation does) is left out, with a note.
  void fixed() {
    Row r;
    const bool far = m_.traits.search == SearchStrategy::field_pair;
    for (double h = far ? kFarFieldFirstStep : 0.5; ns_.t_end / h * std::max(1, m_.evals_per_step) <= o_.max_evals; h /= 2) {
      if (!try_measure(h, 0, r)) continue;
      if (!keep(r)) break;
    }
  }

  const NamedScene& ns_;
  const MethodInfo& m_;
  const Body& body_;
  const State& ref_;
  const Options& o_;
  std::vector<Row>& rows_;
  bool capped_;
  int below_ = 0;
};

/// One method's ladder on one scene (Ladder); a method that refuses the scene (MethodInfo::check: ks on a
/// body-point, logh with an attracting centre) is left out, with a note.
void run_ladder(const NamedScene& ns, const MethodInfo& m, const State& ref, const Options& o, std::vector<Row>& rows) {
  if (const std::string why = refusal(m, ns.scene.bodies.front(), ns.scene.centres); !why.empty()) {
    std::cerr << "  " << ns.name << " " << m.name << ": refused (" << why << ")\n";
    return;
  }
  Ladder(ns, m, ref, o, rows).run();
}

void write_rows(std::ostream& os, const std::vector<Row>& rows, const std::string& refs, const Options& o) {
  os << "scene,method,h,tol,err_R,err_rel,max_rel_dE,force_evals,wall_s,cpu_s,spread,repeats,flag\n"
     << "# bodypoint work-precision, revision " << git_revision() << "\n"
     << "# err_R = |R(t_end) - R_ref| against odeint rkf78 in long double at tol 1e-18; err_rel = max(|R - R_ref|/|R_ref|, |v - v_ref|/|v_ref|), "
     << "the tool's error norm (its estimates, --tol)\n"
     << "# a call is one run without invariants or output\n"
     << timing_rules_note(o.timing)
     << "# ladders: bodypoint's methods end above " << fmt(o.max_evals) << " force evaluations; the peers' "
     << (o.cap_peers ? "too (--quick)" : "at tol 1e-14 or their round-off floor, with no budget") << "\n";
  std::istringstream ref_lines(refs);
  for (std::string line; std::getline(ref_lines, line);) os << "# " << line << "\n";
  os << "# h is the fictitious step ds for time-transformed methods (logh-*, ttl-*, ks)\n";
  for (const Row& r : rows)
    os << CsvLine().text(r.scene).text(r.method).num_if(r.h > 0, r.h).num_if(r.tol > 0, r.tol).num(r.err_R)
              .num(r.err_rel).num(r.max_rel_dE).count(r.force_evals).num(r.time.wall_s).num(r.time.cpu_s)
              .num(r.time.spread()).count(r.time.repeats).quoted(r.time.flag()).str()
       << '\n';
}

std::string config_of(const Row& r) {
  std::ostringstream c;
  c << std::setprecision(3);
  if (r.h > 0) c << step_name(method_or_throw(r.method)) << "=" << r.h;
  else c << "tol=" << r.tol;
  return c.str();
}

/// Whether rows[i] reaches `target` on `scene` and counts: only when the next finer configuration (the next row
/// of its ladder) reaches it too, so that a lucky cancellation at one step does not count. The exact regularised
/// flow (ks) has one configuration.
bool counts_at(const std::vector<Row>& rows, std::size_t i, const std::string& scene, double target) {
  const Row& r = rows[i];
  if (r.scene != scene || !(r.err_rel <= target)) return false;
  if (is_exact_flow(method_or_throw(r.method))) return true;
  const Row* next = i + 1 < rows.size() ? &rows[i + 1] : nullptr;
  return next && next->scene == r.scene && next->method == r.method && next->err_rel <= target;
}

/// The cheapest configuration of ours and of the peers reaching `target` on a scene (counts_at). Chosen by
/// what does not depend on the machine: the fewest force evaluations (equal counts: the first by name, and the
/// summary names the others, tied_with); its time is then printed, or "flagged" where it does not count.
std::pair<const Row*, const Row*> best_at(const std::vector<Row>& rows, const std::string& scene, double target) {
  const Row* ours = nullptr;
  const Row* peer = nullptr;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (!counts_at(rows, i, scene, target)) continue;
    const Row& r = rows[i];
    const Row*& slot = is_peer(method_or_throw(r.method)) ? peer : ours;
    if (!slot || r.force_evals < slot->force_evals || (r.force_evals == slot->force_evals && r.method < slot->method))
      slot = &r;
  }
  return {ours, peer};
}

/// The other methods on best's side that reach `target` with exactly its force evaluations: a tie the name
/// broke, which a reader should see (logH and TTL of one repelling centre can make the same count).
std::string tied_with(const std::vector<Row>& rows, const Row& best, double target) {
  std::string names;
  const bool peer = is_peer(method_or_throw(best.method));
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    if (&r == &best || r.method == best.method || r.force_evals != best.force_evals ||
        is_peer(method_or_throw(r.method)) != peer || !counts_at(rows, i, best.scene, target) ||
        names.find(r.method) != std::string::npos)
      continue;
    names += (names.empty() ? " (tied: " : ", ") + r.method;
  }
  return names.empty() ? names : names + ")";
}

std::string summary_table(const std::vector<NamedScene>& scenes, const std::vector<Row>& rows) {
  std::ostringstream sum;
  sum << "| scene | target err_rel | best bodypoint method | config | force evals | time [ms] | best peer (Boost.Odeint, GSL, SUNDIALS, logh-bs) | config | force evals | time [ms] | speed-up |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const NamedScene& ns : scenes)
    for (double target : {1e-4, 1e-7, 1e-10, 1e-13}) {
      const auto [ours, peer] = best_at(rows, ns.name, target);
      sum << "| " << ns.name << " | " << std::setprecision(0) << std::scientific << target << std::defaultfloat
          << std::setprecision(3) << " | ";
      for (const Row* r : {ours, peer}) {
        if (r) sum << r->method << tied_with(rows, *r, target) << " | " << config_of(*r) << " | " << r->force_evals << " | " << time_cell(r->time) << " | ";
        else sum << "- | - | - | - | ";
      }
      sum << ratio_cell(ours ? &ours->time : nullptr, peer ? &peer->time : nullptr) << " |\n";
    }
  return sum.str();
}

/// Prints the summary and writes the files (each only now, so a failed run leaves none).
void report(const std::string& sum, const std::string& tag, AtomicFile* csv, AtomicFile* md) {
  std::cout << sum;
  if (md) {
    md->stream() << "<!-- bodypoint work-precision" << tag << ", revision " << git_revision() << " -->\n" << sum;
    md->commit();
  }
  if (csv) csv->commit();
}

}  // namespace

int cmd_work_precision(int argc, char** argv) {
  WorkPrecisionArgs a;
  po::options_description desc("bodypoint work-precision");
  add_work_precision_options(desc, a);
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint work-precision [options]\n"
             "Final-position error against run time for every method on named scenes."))
    return 0;
  if (a.list_scenes) {
    for (const std::string& n : named_scene_names()) std::cout << n << "\n";
    return 0;
  }
  settle(vm, a);
  const std::vector<std::string> scene_names = a.scenes == "all" ? named_scene_names() : split_list(a.scenes);
  const std::vector<const MethodInfo*> ms = chosen_methods(a.methods);
  std::vector<NamedScene> scenes;
  for (const std::string& n : scene_names) scenes.push_back(named_scene(n));
  std::unique_ptr<AtomicFile> csv, md;
  if (!a.out.empty()) csv = std::make_unique<AtomicFile>(a.out);
  if (!a.summary.empty()) md = std::make_unique<AtomicFile>(a.summary);
  if (a.by_tol) {
    // Every tolerance is one the accuracy mode takes (finite, in [1e-13, 1)): a nan, 0 or 2 made nan rows.
    const std::vector<double> tols = parse_numbers(a.tols, "--tols");
    for (double tol : tols) {
      try {
        bodypoint::check_tolerance(tol);
      } catch (const Error& e) {
        throw Error("--tols: " + std::string(e.what()));
      }
    }
    std::ostringstream sum;
    run_by_tolerance(scenes, tols, a.o.timing, a.o.max_evals, csv ? &csv->stream() : nullptr, sum);
    report(sum.str(), " --by-tol", csv.get(), md.get());
    return 0;
  }
  std::vector<Row> rows;
  std::ostringstream refs;
  for (const NamedScene& ns : scenes) {
    const State ref = reference_of(ns, refs);
    const std::size_t first = rows.size();
    for (const MethodInfo* m : ms) run_ladder(ns, *m, ref, a.o, rows);
    std::cerr << "  " << ns.name << ": timing " << rows.size() - first << " configurations, interleaved\n";
    time_scene(rows, first, a.o.timing);
  }
  if (csv) write_rows(csv->stream(), rows, refs.str(), a.o);
  report(summary_table(scenes, rows), "", csv.get(), md.get());
  return 0;
}

}  // namespace bodypoint::cli

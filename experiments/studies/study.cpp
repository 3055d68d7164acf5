// `bodypoint study`: one recipe per study of the thesis (chapter 4, table 4.1, appendix 1), each
// writing its CSVs to a results folder. `--quick` runs the same recipes on coarser grids.
//
// Choices where the thesis is silent or ambiguous (also written into each CSV's header):
// - d sweep (fig. 4.1-4.2): the thesis gives the range 5..200 but no increment; we use 5.
// - h sweep (fig. 4.5-4.9): "T = h n = 25" with d = 50, L = 200; the thesis does not list its h values,
//   so we take 25 log-spaced values from 1e-4 to 0.5. The same runs give |K2|^2 against h (fig. 4.8-4.9).
// - Kx sweep (fig. 4.10-4.11): "the same parameters as the previous section" (d = 50, L = 200,
//   T = 25, h = 1e-4); the range of Kx is not given, we take -10..10 in steps of 0.5.
// - timing (fig. 4.12-4.13): table 3.1 (d = 10), h = 1e-4, n = 500..250000 in steps of 500, as printed.
// - appendix 1: symplectic Euler (thesis-euler), h = 1e-4, n = 250000; sets not printed in full take
//   the values common to the appendix (A = -0.5, m = 1, B = 0.7, J = 1, L = 200, d = 50, K1 = Kz = 5,
//   Kx = 2). Set P1.2 (J = 0.2) has D = mJ - B^2 = -0.29 < 0: its kinetic energy is not positive
//   definite, so it is recorded as skipped instead of integrated. Sets P1.4 and P1.5 are printed
//   with identical parameters; both are run.
#include "process.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/methods.hpp"
#include "bodypoint/threads.hpp"
#include "bodypoint/observables.hpp"
#include "cli.hpp"
#include "errata.hpp"
#include "long_time.hpp"
#include "orders.hpp"
#include "rows_file.hpp"
#include "scattering_study.hpp"
#include "stress.hpp"
#include "sweep.hpp"
#include "timing.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <unistd.h>

namespace bodypoint::cli {
namespace {

namespace fs = std::filesystem;

struct StudyContext {
  fs::path dir;
  bool quick = false;
  unsigned threads = 1;
  bool progress = false;
  /// Set by the "published" recipe: the thesis's code's force law and its seven methods, files
  /// prefixed "published_" (model.hpp, ForceLaw::thesis_code).
  bool published = false;
  /// --resume: sweeps continue from the journals of an interrupted run.
  bool resume = false;
  /// --no-simd: every trajectory alone (the scalar loop), for timing comparisons.
  bool no_simd = false;
  /// --periods: the long-time study's span in periods (0: its default).
  double periods = 0.0;
};

void write_sweep(const StudyContext& c, const std::string& name, SweepSpec spec, std::string note) {
  std::string file = name;
  if (c.published) {
    spec.base.law = ForceLaw::thesis_code;
    spec.methods = methods_named("thesis-euler,thesis-verlet,thesis-ruth3,thesis-fr4,thesis-y6,rk4,ab4");
    file = "published_" + name;
    note += "; as published: A = -0.5, the thesis code's force law F = -A R/|R|^1.5, third-kick slip and loop (n - 1 "
            "steps of n)";
  }
  const std::string path = (c.dir / file).string(), command = "bodypoint study" + std::string(c.quick ? " --quick" : "") + " (" + note + ")";
  AtomicFile f(path);
  validate_sweep(spec);
  RowJournal journal(path + ".journal", sweep_key(spec), task_count(spec), sweep_header(spec, command), c.resume);
  const auto rows = run_sweep(spec, SweepControl{c.threads, c.progress, 0, 1, &journal, !c.no_simd});
  write_sweep_csv(f.stream(), spec, rows, command);
  f.commit();
  journal.remove();
  std::cerr << "wrote " << (c.dir / file).string() << " (" << rows.size() << " rows)\n";
}

SweepSpec thesis_sweep(const std::string& param) {
  SweepSpec s;
  s.axes = {{param, {}}};
  s.methods = methods_named("fixed");
  s.h = 1e-4;
  s.steps = 250000;
  // Chapter 4 measures the invariants' errors, as the thesis did: no companion run (it would triple the
  // study's cost); its rows say they have no estimate.
  s.estimate_error = false;
  return s;
}

void study_d(const StudyContext& c) {
  SweepSpec s = thesis_sweep("d");
  s.axes[0].values = c.quick ? linear_range(5, 200, 39) : linear_range(5, 200, 5);
  write_sweep(c, "d_sweep.csv", s, "fig. 4.1-4.2: d = 5..200, h = 1e-4, n = 250000, table 3.1 otherwise");
}

void study_L(const StudyContext& c) {
  SweepSpec s = thesis_sweep("L");
  s.base.start.d = 50;
  s.axes[0].values = c.quick ? linear_range(5, 1000, 199) : linear_range(5, 1000, 5);
  write_sweep(c, "L_sweep.csv", s, "fig. 4.3-4.4: L = 5..1000 step 5, d = 50, h = 1e-4, n = 250000");
  write_L_cost(c.dir, c.quick);
}

void study_h(const StudyContext& c) {
  SweepSpec s = thesis_sweep("h");
  s.base.start.d = 50;
  s.steps = 0;
  s.t_end = 25;
  s.axes[0].values = c.quick ? log_range(1e-4, 0.5, 7) : log_range(1e-4, 0.5, 25);
  write_sweep(c, "h_sweep.csv", s, "fig. 4.5-4.9: T = h n = 25, d = 50, L = 200; h log-spaced (our choice)");
}

void study_Kx(const StudyContext& c) {
  SweepSpec s = thesis_sweep("Kx");
  s.base.start.d = 50;
  s.axes[0].values = c.quick ? linear_range(-10, 10, 5) : linear_range(-10, 10, 0.5);
  write_sweep(c, "Kx_sweep.csv", s, "fig. 4.10-4.11: d = 50, L = 200, h = 1e-4, n = 250000; Kx = -10..10 (our choice)");
}

// The (d, L) stability map : the d and L sweeps' ranges at once, every fixed-step method.
void study_dL_map(const StudyContext& c) {
  SweepSpec s = thesis_sweep("d");
  s.axes = {{"d", c.quick ? linear_range(5, 200, 65) : linear_range(5, 200, 5)},
            {"L", c.quick ? linear_range(5, 1000, 199) : linear_range(5, 1000, 5)}};
  write_sweep(c, "dL_map.csv", s,
              std::string("(d, L) map: d = 5..200 step ") + (c.quick ? "65" : "5") + " x L = 5..1000 step " + (c.quick ? "199" : "5") +
                  ", h = 1e-4, n = 250000, table 3.1 otherwise");
}

/// The timing study's run: n = 500..250000 (every 500; quick: 6 values, the published one every 5000).
void write_timing(const StudyContext& c, TimingSpec t, const std::string& file, const std::string& what) {
  t.h = 1e-4;
  t.repeats = kMinRepeats;  // the timing rules' fewest, in the quick build too (stopwatch.hpp)
  t.warmup = 1;
  const double every = c.quick ? 49900 : c.published ? 5000 : 500;
  for (double n : linear_range(500, 250000, every)) t.ns.push_back(static_cast<long>(n));
  AtomicFile f((c.dir / file).string());
  const auto rows = run_timing(t, c.progress);
  write_timing_csv(f.stream(), t, rows, what);
  f.commit();
  std::cerr << "wrote " << (c.dir / file).string() << " (" << rows.size() << " rows)\n";
}

void study_timing(const StudyContext& c) {
  TimingSpec t;
  t.methods = methods_named("fixed");
  write_timing(c, t, "timing.csv", "bodypoint study timing (fig. 4.12-4.13)");
}

/// Thesis table 4.1: right-hand-side evaluations per step of its seven methods, as printed.
const std::map<std::string, int> kThesisTable41 = {{"rk4", 4},          {"ab4", 4},         {"thesis-euler", 1},
                                                   {"thesis-verlet", 2}, {"thesis-ruth3", 3}, {"thesis-fr4", 3},
                                                   {"thesis-y6", 9}};

void study_evals(const StudyContext& c) {
  const Scene scene = thesis_scene(SceneParams{});
  AtomicFile f((c.dir / "force_evals.csv").string());
  std::ostream& os = f.stream();
  os << "method,order,stages,evals_per_step,measured_per_step,thesis_table_4_1\n"
     << "# bodypoint study evals (thesis table 4.1), revision " << git_revision() << "\n"
     << "# thesis_table_4_1: the thesis's count for its seven methods; its AB4 (4) recomputes the four past\n"
     << "# right-hand sides every step, odeint's adams_bashforth<4> keeps them and evaluates one\n"
     << "# evals_per_step: as listed by 'bodypoint methods'; measured_per_step: force evaluations of a\n"
     << "# 1000-step run on table 3.1 divided by 1000 (adaptive methods: per accepted step, tol 1e-10;\n"
     << "# time-transformed methods: per fictitious step of ds = 1e-3; ks: on table 3.1 with B = 0, and it\n"
     << "# evaluates no force at all: its regularised flow is exact)\n";
  SceneParams material;
  material.B = 0.0;
  const Scene material_scene = thesis_scene(material);
  for (const MethodInfo& m : methods()) {
    constexpr double h = 1e-3;
    constexpr long steps = 1000;
    const Advance how = advance_of(m, {.step = h, .steps = steps});
    const Scene& sc = refusal(m, scene.bodies.front(), scene.centres).empty() ? scene : material_scene;
    const RunResult r = run_or_throw(m, sc.bodies.front(), sc.centres, how, unobserved());
    const auto printed = kThesisTable41.find(m.name);
    os << CsvLine().text(m.name).count(m.order).count(m.stages).count(m.evals_per_step)
              .num(static_cast<double>(r.force_evals) / static_cast<double>(r.steps))
              .text(printed == kThesisTable41.end() ? std::string() : std::to_string(printed->second)).str()
       << '\n';
  }
  f.commit();
  std::cerr << "wrote " << (c.dir / "force_evals.csv").string() << "\n";
}

/// Appendix 1: the 30 parameter sets, as differences from the appendix's common values.
struct AppendixSet {
  int figure;
  std::map<std::string, double> changes;
};

std::vector<AppendixSet> appendix_sets() {
  return {{1, {{"A", -0.1}}},           {2, {{"J", 0.2}}},           {3, {{"J", 0.5}}},
          {4, {{"L", 50}}},             {5, {{"L", 50}}},            {6, {{"d", 0}}},
          {7, {{"d", 5}}},              {8, {{"d", 15}}},            {9, {{"d", 35}}},
          {10, {{"K1", 0.1}, {"Kz", 0.1}}}, {11, {{"K1", 1}, {"Kz", 1}}}, {12, {{"K1", 2}, {"Kz", 2}}},
          {13, {{"K1", 2.5}, {"Kz", 2.51}}}, {14, {{"Kx", 0}}},       {15, {}},
          {16, {{"Kx", -4.7}}},         {17, {{"Kx", -5}}},          {18, {{"Kx", 6.5}}},
          {19, {{"Kx", 6}}},            {20, {{"K1", 6.4}, {"Kz", 6.4}}}, {21, {{"K1", 10}, {"Kz", 10}}},
          {22, {{"K1", 20}, {"Kz", 20}}}, {23, {{"d", 100}}},         {24, {{"L", 500}}},
          {25, {{"L", 1500}}},          {26, {{"J", 2.5}}},          {27, {{"J", 50}}},
          {28, {{"A", -1}}},            {29, {{"A", -2}}},           {30, {{"A", -5}}}};
}

void study_errata(const StudyContext& c) {
  AtomicFile f((c.dir / "errata.csv").string());
  write_errata(f.stream());
  f.commit();
  std::cerr << "wrote " << (c.dir / "errata.csv").string() << "\n";
}

void study_orders(const StudyContext& c) {
  AtomicFile f((c.dir / "orders.csv").string());
  write_orders(f.stream());
  f.commit();
  std::cerr << "wrote " << (c.dir / "orders.csv").string() << "\n";
}

/// The d that puts the start at R0 = (-L, y, 0) (thesis_momenta: y = d - Kz/K1).
double harness_d(const SceneParams& p, double y) { return y + p.start.Kz / p.start.K1; }

/// The parameters of the thesis code's harnesses (its repository's ru/axothy/mechanics/tests:
/// AimingDistanceTest, FullDistanceTest, IntegrateStepTest, KxTest), which differ from table 3.1:
/// A = -0.5 and, except in KxTest, the literal start v0 = (7.058, 0, 6.86), w0 = (-2.941, 0, -9.8)
/// (table 3.1's velocities rounded) with R0 = (-L, y, 0). In the thesis's terms (model.hpp,
/// thesis_momenta) that start is K1 = 4.9993, Kx = 1.9996, Kz = 4.998 and d = y + Kz/K1.
SceneParams harness_params(bool rounded_start) {
  SceneParams p;
  p.A = -0.5;
  p.law = ForceLaw::thesis_code;
  if (rounded_start) {
    const BodyPoint bp{p.m, p.B, p.J};
    const Momenta k = to_momenta(bp, State{Vec3(-200.0, 49.0, 0.0), Vec3(7.058, 0.0, 6.86), Vec3(-2.941, 0.0, -9.8)});
    // K1 = m v + B w has no z-component in exact arithmetic (6.86 - 0.7 x 9.8); a rounding of it is dropped.
    constexpr double kRoundingOfZero = 1e-12;
    if (std::abs(k.K1.z()) > kRoundingOfZero || k.K1.y() != 0.0 || k.K2.y() != 0.0)
      throw Error("the harnesses' start is not of the thesis's form");
    p.start.K1 = k.K1.x();
    p.start.Kx = k.K2.x();
    p.start.Kz = -k.K2.z();
  }
  p.start.d = harness_d(p, 49.0);
  return p;
}

/// Chapter 4's sweeps as the thesis's code computed them, with its harnesses' parameters, force law,
/// slip and loop (n - 1 steps), beside the corrected ones (table 3.1 and the model).
void study_published(const StudyContext& c) {
  StudyContext pc = c;
  pc.published = true;
  const std::string harness = "the thesis code's harness ";
  {  // AimingDistanceTest: d = 5, 6, ..., 199 and R0 = (-200, d - 1, 0).
    SweepSpec s = thesis_sweep("d");
    s.base = harness_params(true);
    for (double d : linear_range(5, 199, c.quick ? 38 : 1)) s.axes[0].values.push_back(harness_d(s.base, d - 1.0));
    write_sweep(pc, "d_sweep.csv", s, harness + "AimingDistanceTest (fig. 4.1-4.2): R0 = (-200, d' - 1, 0), d' = 5..199");
  }
  {  // FullDistanceTest: R0 = (-L, 49, 0); its loop is commented out at L = 1500, the text gives 5..1000 step 5.
    SweepSpec s = thesis_sweep("L");
    s.base = harness_params(true);
    s.axes[0].values = c.quick ? linear_range(5, 1000, 199) : linear_range(5, 1000, 5);
    write_sweep(pc, "L_sweep.csv", s, harness + "FullDistanceTest (fig. 4.3-4.4): R0 = (-L, 49, 0), L = 5..1000 step 5 (the text's range)");
  }
  {  // IntegrateStepTest: h = 1e-4 halved while h > 5e-6, n = (int)(25/h); the coarse steps of fig. 4.5 are
     // not in the harness, so the corrected sweep's log-spaced ones are added.
    SweepSpec s = thesis_sweep("h");
    s.base = harness_params(true);
    s.steps = 0;
    s.t_end = 25;
    std::vector<double>& hs = s.axes[0].values;
    hs = c.quick ? log_range(1e-4, 0.5, 7) : log_range(1e-4, 0.5, 25);
    const int halvings = c.quick ? 1 : 4;  // 5e-5 (quick); 5e-5, 2.5e-5, 1.25e-5, 6.25e-6 (as the harness)
    for (int k = 1; k <= halvings; ++k) hs.push_back(0.0001 / std::ldexp(1.0, k));
    std::sort(hs.begin(), hs.end());
    write_sweep(pc, "h_sweep.csv", s,
                harness + "IntegrateStepTest (fig. 4.5-4.9): R0 = (-200, 49, 0), h = 1e-4 / 2^k while h > 5e-6 and the "
                          "corrected sweep's log-spaced h up to 0.5, n = (int)(25/h)");
  }
  {  // KxTest: table 3.1's K1 = Kz = 5 exactly, R0 = (-200, 49, 0), Kx = -10 then Kx += 0.1 while Kx < 10.1.
    SweepSpec s = thesis_sweep("Kx");
    s.base = harness_params(false);
    std::vector<double> kx;
    double x = -10;
    do {
      kx.push_back(x);
      x = x + 0.1;
    } while (x < 10.1);
    for (std::size_t i = 0; i < kx.size(); i += c.quick ? 50 : 1) s.axes[0].values.push_back(kx[i]);
    write_sweep(pc, "Kx_sweep.csv", s, harness + "KxTest (fig. 4.10-4.11): R0 = (-200, 49, 0), Kx = -10, -9.9, ..., 10.1 accumulated as it did");
  }
  {  // The cost of the seven under the code's force law (chapter 4.6's claims as published).
    TimingSpec t;
    // The thesis's AB4 is its code's (ab4-thesis: four evaluations per step), not odeint's.
    t.methods = methods_named("thesis-euler,thesis-verlet,thesis-ruth3,thesis-fr4,thesis-y6,rk4,ab4-thesis");
    t.base = harness_params(true);
    t.base.law = ForceLaw::thesis_code;
    write_timing(pc, t, "published_timing.csv",
                 "bodypoint study published timing (fig. 4.12-4.13 under the thesis code's force law, its harness's start)");
  }
}

void study_appendix(const StudyContext& c) {
  const fs::path dir = c.dir / "appendix1";
  fs::create_directories(dir);
  const long steps = 250000, every = c.quick ? 2500 : 250;
  AtomicFile index((dir / "index.csv").string());
  std::ostream& ix = index.stream();
  ix << "figure,A,m,B,J,L,d,K1,Kz,Kx,outcome,file,max_rel_dE,max_rel_dK2sq\n"
     << "# bodypoint study appendix (thesis appendix 1): thesis-euler, h = 1e-4, n = 250000, every "
     << every << "-th step written; revision " << git_revision() << "\n";
  for (const AppendixSet& set : appendix_sets()) {
    SceneParams p;
    p.A = -0.5;
    p.start.d = 50;
    for (const auto& [k, v] : set.changes) scene_field(p, k) = v;
    CsvLine row;
    row.count(set.figure);
    for (const char* k : {"A", "m", "B", "J", "L", "d", "K1", "Kz", "Kx"}) row.num(scene_field(p, k));
    if (std::string why = why_invalid(p); !why.empty()) {
      ix << row.quoted("skipped: " + why).str() << ",,,\n";
      continue;
    }
    const Scene scene = thesis_scene(p);
    const std::string name = "P1." + std::to_string(set.figure) + ".csv";
    AtomicFile f((dir / name).string());
    std::ostream& os = f.stream();
    const TrajectoryWriter writer(os, select_observables(scene.centres), false);
    writer.header();  // the names first (numpy's genfromtxt(names=True)), the description after them
    os << "# thesis appendix 1, fig. P1." << set.figure << "; thesis-euler h=1e-4 n=250000\n";
    const BodyPoint& bp = scene.bodies.front().p;
    SampleSink sink = [&writer, &bp](const Sample& s) { writer.row(0, s, bp); };
    Options o;
    o.every = every;
    o.sink = &sink;
    const BodyResult br = integrate_body(scene.bodies.front(), scene.centres, &method_or_throw("thesis-euler"),
                                         FixedSteps{1e-4, steps}, o);
    if (!ran(br.outcome)) throw Error(br.reason);
    const RunResult& r = br.run;
    f.commit();
    // The thesis's run as it made it, written whatever its flags; the outcome says what they are.
    ix << row.text(std::string(outcome_name(br.outcome))).text(name).num(r.invariants->max_rel_dE).num(r.invariants->max_rel_dK2sq).str() << '\n';
  }
  index.commit();
  std::cerr << "wrote " << dir.string() << "/ (30 sets)\n";
}

/// Hostile scenes for one method of each family: not part of "all" (the thesis's studies).
void study_stress(const StudyContext& c) {
  AtomicFile csv((c.dir / "stress.csv").string()), md((c.dir / "stress.md").string());
  const auto rows = run_stress(c.quick, [&](const StressRow& r) {
    if (c.progress) std::cerr << "  " << r.case_name << " / " << r.method << ": " << outcome_name(r.outcome) << "\n";
  });
  write_stress(csv.stream(), md.stream(), rows);
  csv.commit();
  md.commit();
  std::size_t ok = 0, refused = 0, flagged = 0;
  for (const StressRow& r : rows) (r.outcome == Outcome::ok ? ok : r.outcome == Outcome::refused ? refused : flagged)++;
  std::cerr << "wrote " << (c.dir / "stress.csv").string() << " and stress.md: " << rows.size() << " runs, " << ok
            << " ok, " << refused << " refused with a reason, " << flagged << " flagged (diverged, unresolved, inaccurate or collided)\n";
}

void study_scattering(const StudyContext& c) { write_scattering_study(c.dir, c.quick, c.threads); }

void study_long_time(const StudyContext& c) { write_long_time_study(c.dir, {c.quick, c.periods, c.threads, c.resume}); }

const std::vector<std::pair<std::string, void (*)(const StudyContext&)>>& recipes() {
  static const std::vector<std::pair<std::string, void (*)(const StudyContext&)>> r = {
      {"d", study_d},         {"L", study_L},          {"h", study_h},         {"Kx", study_Kx},
      {"timing", study_timing}, {"evals", study_evals}, {"appendix", study_appendix}, {"errata", study_errata}, {"orders", study_orders},
      {"published", study_published}, {"stress", study_stress}, {"dL-map", study_dL_map},
      {"scattering", study_scattering}, {"long-time", study_long_time}};
  return r;
}

}  // namespace

int cmd_study(int argc, char** argv) {
  std::string which = "all", results = "results";
  bool quick = false;
  StudyContext c;
  long threads = 0;
  po::options_description desc("bodypoint study");
  desc.add_options()
      ("name", defaulted(&which), "recipe: d, L, h, Kx, timing, evals, appendix, errata, orders, published (chapter 4 with the thesis code's force "
       "law), all (these), stress (hostile scenes), dL-map (the (d, L) stability map), scattering "
       "(the deflection function theta(b) against Rutherford's, spinning bodies, cross-sections) or long-time "
       "(bound orbits over 10^5 periods: invariants and phase errors)")
      ("results", defaulted(&results), "folder for the CSVs (created if missing)")
      ("quick", po::bool_switch(&quick), "coarser grids, same recipes (under two minutes on 2 cores)")
      ("threads", po::value(&threads)->default_value(0), "worker threads for the sweeps and the long-time study's runs (0: all cores)")
      ("resume", po::bool_switch(&c.resume), "finish the sweeps (and the long-time study) of an interrupted run from their journals (<csv>.journal)")
      ("no-simd", po::bool_switch(&c.no_simd), "sweeps run every trajectory alone, not in batches of vector lanes (same numbers, slower)")
      ("periods", po::value(&c.periods), "long-time: the span in periods of each orbit (default 10^5, --quick 10^3; "
       "the reference lp-kl8 costs about 7 million force evaluations per 10^3 periods and scene; 10^7 periods take "
       "hours: run them in sittings with --max-seconds and --resume)");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint study [--name d|L|h|Kx|timing|evals|appendix|errata|orders|published|all|stress|dL-map|scattering|long-time] [--results DIR] [--quick]\n"
             "Regenerates the thesis's studies for its methods and ours side by side."))
    return 0;
  if (vm.count("periods") && which != "long-time") throw Error("--periods applies to --name long-time only");
  c.dir = results;
  c.quick = quick;
  c.threads = thread_count(threads);
  c.progress = ::isatty(2) == 1;
  std::vector<std::string> names{"all"};
  for (const auto& [name, fn] : recipes()) names.push_back(name);
  if (std::find(names.begin(), names.end(), which) == names.end()) throw Error(unknown_name("study", which, names));
  std::error_code ec;
  fs::create_directories(c.dir, ec);
  if (ec || !fs::is_directory(c.dir)) throw Error("cannot create results folder '" + results + "'");
  for (const auto& [name, fn] : recipes())
    if ((which == "all" && name != "stress" && name != "dL-map" && name != "scattering" && name != "long-time") ||
        which == name)
      fn(c);
  return 0;
}

}  // namespace bodypoint::cli

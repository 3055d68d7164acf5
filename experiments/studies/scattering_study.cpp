// `bodypoint study --name scattering` (scattering_study.hpp).
//
// Every run is the thesis's scene (table 3.1: A = -2, m = J = 1, K1 = 5; L = max(200, 4b)) with the coupling B
// and the spin (Kx, Kz) of its series, given by its asymptotic data: d solved so that the incoming
// asymptote has impact parameter b, the start phase so that the helix has the arrival phase psi when
// the guiding centre reaches its periapsis (scattering.hpp, with_asymptotic_data). A spinning body's
// deflection depends on psi as much as on b, so each b is run at kPhases phases; a material point's
// does not (one phase). Each encounter runs in the accuracy mode until the body has left (encounter()).
// Written:
//   scattering.csv              one row per (series, b, psi): theta, its asymptotes' model error, r_min, ...
//   scattering_rainbows.csv     per (series, psi): every extremum of theta(b), located by golden-section
//                               search on b between the grid points that bracket it (not read off the grid)
//   scattering_cross_section.csv  per (series, theta bin): dsigma/dOmega of a beam uniform in b (over the
//                               grid's range) and in psi, summed over every branch of b(theta), with its
//                               quadrature error, beside Rutherford's for the guiding centre's mass |K1|/u
//   scattering_summary.csv      one row per series
// and, for `study --name L`, L_cost.csv (write_L_cost).
#include "process.hpp"
#include "scattering_study.hpp"

#include "bodypoint/bodypoint.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "bodypoint/threads.hpp"
#include "encounter_parts.hpp"
#include "sweep.hpp"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint::cli {
namespace {

/// The accuracy asked of every run: the final state to 1e-12 relative, so that the deflection, a
/// function of the conserved quantities at the two ends, is known to ~1e-12 as well.
constexpr double kStudyTolerance = 1e-12;
/// A run whose tolerance is out of reach is repeated this much looser, up to kRetries times (to 1e-9:
/// round-off amplified by a close pass reaches 5e-10 at B = 0.5); the row records the tolerance.
constexpr double kRetryLooser = 10.0;
constexpr int kRetries = 3;
/// Golden-section steps that locate a rainbow: the bracket (two grid intervals) shrinks 0.618^30 ~ 5e-7,
/// about where theta's own 1e-12 accuracy stops telling b apart (theta - theta_max ~ (db)^2).
constexpr int kGoldenSteps = 30;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = std::numbers::pi;

struct Series {
  std::string name;
  double B, Kx, Kz;
  const char* method = "auto";
};

/// B = 0 (Rutherford; auto chooses ks there, exact in its fictitious time, so lp-kl8 too), then the
/// thesis's spin (Kx, Kz) = (2, 5) at B = 0.2 .. 0.9, and at B = 0.7 a spin along K1 (Kz = 0: the
/// guiding centre drifts back along -K1 after a close pass) and one perpendicular to it (Kx = 0).
std::vector<Series> series() {
  return {{"B=0", 0.0, 2, 5},         {"B=0 lp-kl8", 0.0, 2, 5, "lp-kl8"}, {"B=0.2", 0.2, 2, 5},          {"B=0.5", 0.5, 2, 5},
          {"B=0.7", 0.7, 2, 5},       {"B=0.9", 0.9, 2, 5},          {"B=0.7 spin along K1", 0.7, 5, 0},
          {"B=0.7 spin across K1", 0.7, 0, 5}};
}

/// The helix's phase matters only where it moves the body about its guiding centre (B != 0, Kz != 0).
bool phased(const Series& s) { return s.B != 0.0 && s.Kz != 0.0; }

struct Point {
  double b_target = 0.0, psi = 0.0, d = 0.0;
  Scattering sc;
  double r_min = kNaN, t_min = kNaN, t_end = 0.0, tol = kStudyTolerance, asymptote_error = kNaN;
  /// The finite start distance's part of the deflection's error and the deflection's total error
  /// (bodypoint.hpp, add_start_distance_error): the same (b, arrival phase) again from 2L.
  double start_distance_error = kNaN, deflection_error = kNaN;
  long force_evals = 0;
  std::string method, failure;
  [[nodiscard]] bool ok() const { return failure.empty() && std::isfinite(sc.deflection); }
};

/// A run starts at least this many impact parameters away (L = max(200, kStartOverImpact b)): the guiding
/// centre must come within half its start distance of the centre for the asymptotes' model error to be
/// measured (encounter(): the deflection at half the start distance against at the ends), which a pass at
/// b = 316 or 1000 from L = 200 never does (42 rows of the study had no total error).
constexpr double kStartOverImpact = 4.0;

SceneParams series_params(const Series& s, double b) {
  SceneParams params;
  params.start.L = std::max(params.start.L, kStartOverImpact * b);
  params.B = s.B;
  params.start.Kx = s.Kx;
  params.start.Kz = s.Kz;
  return params;
}

Point run_point(const Series& s, double b, double psi) {
  Point p;
  p.b_target = b;
  p.psi = psi;
  const double arrival = phased(s) ? psi : kNaN;
  const Expected<SceneParams> solved = solve_asymptotic_data(series_params(s, b), b, kNaN, arrival);
  if (!solved) {  // no start distance gives b (the row says why)
    p.failure = solved.error();
    return p;
  }
  const SceneParams& params = *solved;
  p.d = params.start.d;
  const Expected<Scene> scene = valid_thesis_scene(params);
  if (!scene) {
    p.failure = scene.error();
    return p;
  }
  const Body& body = scene->bodies.front();
  Options o;
  o.track_invariants = false;
  const MethodInfo* method = std::string_view(s.method) == "auto" ? nullptr : &method_or_throw(s.method);
  const std::function<Expected<Scene>()> far = [&] { return thesis_scene_twice_as_far(params, b, kNaN, arrival); };
  const auto run = [&](std::optional<TwiceAsFar>& twice) {
    twice = twice_as_far_beside(far, answers_at_limit(b, kNaN), body, scene->centres, p.tol, o);
    return encounter_beside(body, scene->centres, method, p.tol, o, twice ? &*twice : nullptr);
  };
  std::optional<TwiceAsFar> twice;
  EncounterResult r = run(twice);
  for (int k = 0; k < kRetries && r.run.outcome == Outcome::failed && r.run.reason.find("out of reach") != std::string::npos; ++k) {
    p.tol *= kRetryLooser;
    r = run(twice);
  }
  p.force_evals = r.run.total_force_evals();
  p.t_end = r.run.run.t_end;
  if (r.run.method) p.method = r.run.method->name;
  if (r.encounter.outcome != Outcome::ok) {
    p.failure = r.encounter.reason;
    return p;
  }
  p.force_evals += add_start_distance(r.encounter, body, far, p.tol, r.run.error.for_orbit(), "", o, answers_at_limit(b, kNaN),
                                      &r.run, twice ? &*twice : nullptr);
  p.sc = r.encounter.scattering;
  p.asymptote_error = r.encounter.asymptote_error;
  p.start_distance_error = r.encounter.start_distance_error;
  p.deflection_error = r.encounter.deflection_error;
  p.r_min = r.encounter.r_min;
  p.t_min = r.encounter.t_min;
  return p;
}

double rutherford(double A, double mu, double v_inf, double b) { return 2.0 * std::atan(std::abs(A) / (mu * v_inf * v_inf * b)); }

/// The study's grid: per series its phases, per phase every b.
struct Grid {
  std::vector<Series> all;
  std::vector<double> bs, phases;
  std::vector<Point> points;  ///< series-major, then phase, then b
  [[nodiscard]] std::size_t phases_of(const Series& s) const { return phased(s) ? phases.size() : 1; }
  [[nodiscard]] std::size_t first(std::size_t series) const {
    std::size_t at = 0;
    for (std::size_t k = 0; k < series; ++k) at += phases_of(all[k]) * bs.size();
    return at;
  }
  [[nodiscard]] const Point* row(std::size_t series, std::size_t phase) const { return &points[first(series) + phase * bs.size()]; }
};

Grid run_grid(bool quick, unsigned threads) {
  Grid g{series(), log_range(1e-3, 1e3, quick ? 13 : 61), {}, {}};
  const std::size_t n_phases = quick ? 4 : 8;
  for (std::size_t j = 0; j < n_phases; ++j) g.phases.push_back(2.0 * kPi * static_cast<double>(j) / static_cast<double>(n_phases));
  struct Task {
    std::size_t series;
    double b, psi;
  };
  std::vector<Task> tasks;
  for (std::size_t k = 0; k < g.all.size(); ++k)
    for (std::size_t j = 0; j < g.phases_of(g.all[k]); ++j)
      for (double b : g.bs) tasks.push_back({k, b, g.phases[j]});
  g.points.resize(tasks.size());
  parallel_for(tasks.size(), threads, [&](std::size_t i) { g.points[i] = run_point(g.all[tasks[i].series], tasks[i].b, tasks[i].psi); });
  return g;
}

// --- rainbows ---

struct Rainbow {
  std::size_t series = 0;
  double psi = 0.0, b = kNaN, theta = kNaN;
  bool maximum = true;
  long runs = 0;
};

/// The extremum of theta(b) at phase psi inside [lo, hi] (log b), by golden-section search; none (NaN b
/// and theta, no runs counted) where a point on the way fails.
Rainbow locate_rainbow(const Series& s, std::size_t series, double psi, double lo, double hi, bool maximum) {
  const Rainbow none{series, psi, kNaN, kNaN, maximum, 0};
  Rainbow r = none;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  auto f = [&](double x) -> std::optional<double> {
    ++r.runs;
    const Point p = run_point(s, std::exp(x), psi);
    if (!p.ok()) return std::nullopt;
    return maximum ? p.sc.deflection : -p.sc.deflection;
  };
  double a = std::log(lo), c = std::log(hi);
  double x1 = c - g * (c - a), x2 = a + g * (c - a);
  std::optional<double> y1 = f(x1), y2 = y1 ? f(x2) : std::nullopt;
  for (int i = 0; i < kGoldenSteps && y1 && y2; ++i) {
    if (*y1 > *y2) {
      c = x2;
      x2 = x1;
      y2 = y1;
      x1 = c - g * (c - a);
      y1 = f(x1);
    } else {
      a = x1;
      x1 = x2;
      y1 = y2;
      x2 = a + g * (c - a);
      y2 = f(x2);
    }
  }
  if (!y1 || !y2) return none;
  r.b = std::exp(*y1 > *y2 ? x1 : x2);
  r.theta = maximum ? std::max(*y1, *y2) : -std::max(*y1, *y2);
  return r;
}

std::vector<Rainbow> find_rainbows(const Grid& g, unsigned threads) {
  struct Bracket {
    std::size_t series, phase, i;
    bool maximum;
  };
  std::vector<Bracket> brackets;
  for (std::size_t k = 0; k < g.all.size(); ++k)
    for (std::size_t j = 0; j < g.phases_of(g.all[k]); ++j) {
      const Point* row = g.row(k, j);
      for (std::size_t i = 1; i + 1 < g.bs.size(); ++i) {
        if (!row[i - 1].ok() || !row[i].ok() || !row[i + 1].ok()) continue;
        const double left = row[i].sc.deflection - row[i - 1].sc.deflection, right = row[i + 1].sc.deflection - row[i].sc.deflection;
        if (left * right < 0.0) brackets.push_back({k, j, i, left > 0.0});
      }
    }
  std::vector<Rainbow> out(brackets.size());
  parallel_for(brackets.size(), threads, [&](std::size_t n) {
    const Bracket& br = brackets[n];
    out[n] = locate_rainbow(g.all[br.series], br.series, g.phases_of(g.all[br.series]) > 1 ? g.phases[br.phase] : 0.0,
                            g.bs[br.i - 1], g.bs[br.i + 1], br.maximum);
  });
  return out;
}

// --- the beam's cross-section ---

/// Bins of theta (log-spaced from kThetaMin to pi).
constexpr double kThetaMin = 1e-4;

struct Bins {
  std::vector<double> edges;
  explicit Bins(std::size_t n) {
    for (std::size_t i = 0; i <= n; ++i)
      edges.push_back(kThetaMin * std::pow(kPi / kThetaMin, static_cast<double>(i) / static_cast<double>(n)));
  }
  [[nodiscard]] std::size_t size() const { return edges.size() - 1; }
  [[nodiscard]] double solid_angle(std::size_t k) const { return 2.0 * kPi * (std::cos(edges[k]) - std::cos(edges[k + 1])); }
};

/// dsigma/dOmega per bin of a beam uniform in b over the grid's range and in the phases: each interval
/// [b_i, b_i+step] of each phase carries its annulus' area pi (b_{i+step}^2 - b_i^2) / phases, spread
/// over the angles it sweeps with theta a power of b, so every branch of b(theta) adds where it lands and
/// a rainbow's narrow sweep gives its peak. `step` 2 and every other phase: the coarser quadrature whose
/// difference is the error estimate.
std::vector<double> cross_section(const Grid& g, std::size_t k, const Bins& bins, std::size_t step) {
  std::vector<double> sigma(bins.size(), 0.0);
  const std::size_t phases = g.phases_of(g.all[k]);
  const std::size_t phase_step = phases > 1 ? step : 1;
  const double weight = static_cast<double>(phase_step) / static_cast<double>(phases);
  for (std::size_t j = 0; j < phases; j += phase_step) {
    const Point* row = g.row(k, j);
    for (std::size_t i = 0; i + step < g.bs.size(); i += step) {
      const Point &p = row[i], &q = row[i + step];
      if (!p.ok() || !q.ok()) continue;
      // theta is a power of b inside the interval (exact for Rutherford's small angles): b(theta) =
      // b_p (theta/theta_p)^(1/s), and the angles [x, y] of a bin get the area pi |b(y)^2 - b(x)^2|.
      const double tp = p.sc.deflection, tq = q.sc.deflection, bp = p.sc.b, bq = q.sc.b;
      const double lo = std::min(tp, tq), hi = std::max(tp, tq);
      const auto b_at = [&](double t) { return bp * std::pow(t / tp, std::log(bq / bp) / std::log(tq / tp)); };
      for (std::size_t n = 0; n < bins.size(); ++n) {
        if (hi == lo) {
          if (lo >= bins.edges[n] && lo < bins.edges[n + 1]) sigma[n] += kPi * (bq * bq - bp * bp) * weight;
          continue;
        }
        const double x = std::max(lo, bins.edges[n]), y = std::min(hi, bins.edges[n + 1]);
        if (y > x) sigma[n] += kPi * std::abs(std::pow(b_at(y), 2) - std::pow(b_at(x), 2)) * weight;
      }
    }
  }
  for (std::size_t n = 0; n < bins.size(); ++n) sigma[n] /= bins.solid_angle(n);
  return sigma;
}

/// The smallest angle the beam covers at every phase: below it, b beyond the grid's range would add.
double covered_from(const Grid& g, std::size_t k) {
  double theta = 0.0;
  for (std::size_t j = 0; j < g.phases_of(g.all[k]); ++j) {
    const Point& last = g.row(k, j)[g.bs.size() - 1];
    if (last.ok()) theta = std::max(theta, last.sc.deflection);
  }
  return theta;
}

/// The same beam scattered by Rutherford's law: each point's deflection replaced by Rutherford's for its
/// own Kepler particle (mass mu = p_inf / v_inf, B != 0: the guiding centre's) at its own b and v_inf.
/// The study solves d for b at the scene's K1, so v_inf is not one speed over the beam (5.00200 at b =
/// 1e-3 to 5.00039 at b = 1000 for the material point): against one Rutherford law for the whole beam,
/// the small angles stood 1.3e-3 off (a^2, a ~ 1/v_inf^2) at 1,057 times their quadrature error.
Grid rutherford_beam(const Grid& g) {
  const double A = SceneParams{}.A;
  Grid r = g;
  for (Point& p : r.points)
    if (p.ok() && p.sc.in) p.sc.deflection = rutherford(A, p.sc.in->p_inf / p.sc.v_inf, p.sc.v_inf, p.sc.b);
  return r;
}

void write_cross_sections(std::ostream& os, const Grid& g, bool quick) {
  const Bins bins(quick ? 24 : 48);
  const Grid ruth_beam = rutherford_beam(g);
  for (std::size_t k = 0; k < g.all.size(); ++k) {
    const std::vector<double> fine = cross_section(g, k, bins, 1), coarse = cross_section(g, k, bins, 2);
    const std::vector<double> reference = cross_section(ruth_beam, k, bins, 1);
    const double from = covered_from(g, k);
    for (std::size_t n = 0; n < bins.size(); ++n) {
      const double mid = std::sqrt(bins.edges[n] * bins.edges[n + 1]);
      const double ruth = reference[n];
      CsvLine line;
      line.quoted(g.all[k].name).num(g.all[k].B).num(bins.edges[n]).num(bins.edges[n + 1]).num(mid).num(fine[n]);
      line.num(std::abs(fine[n] - coarse[n])).count(bins.edges[n] >= from ? 1 : 0).num(ruth);
      os << line.str() << "\n";
    }
  }
}

// --- outputs ---

void write_points(std::ostream& os, const Grid& g) {
  const double A = SceneParams{}.A, m = SceneParams{}.m;
  for (std::size_t k = 0; k < g.all.size(); ++k) {
    const Series& s = g.all[k];
    for (std::size_t j = 0; j < g.phases_of(s); ++j)
      for (std::size_t i = 0; i < g.bs.size(); ++i) {
        const Point& p = g.row(k, j)[i];
        const bool ok = p.ok();
        const double th_r = ok && s.B == 0.0 ? rutherford(A, m, p.sc.v_inf, p.sc.b) : kNaN;
        CsvLine line;
        line.quoted(s.name).num(s.B).num(s.Kx).num(s.Kz).num(ok ? p.sc.b : p.b_target).num_if(phased(s), p.psi).num(p.d);
        line.num(p.sc.v_inf).num(p.sc.deflection).num(p.asymptote_error).num_if(s.B == 0.0 && ok, th_r);
        line.num_if(s.B == 0.0 && ok, std::abs(p.sc.deflection / th_r - 1.0)).num(p.sc.out_of_plane).num(p.r_min).num(p.t_min);
        line.num(p.t_end).num(p.sc.spin_turn).num(p.sc.K1_turn).num(p.sc.time_delay).quoted(p.sc.asymptotes).text(p.method);
        line.num(p.tol).count(p.force_evals).quoted(p.failure).num(p.start_distance_error).num(p.deflection_error);
        os << line.str() << "\n";
      }
  }
}

void write_rainbows(std::ostream& os, const Grid& g, const std::vector<Rainbow>& rainbows) {
  for (const Rainbow& r : rainbows) {
    CsvLine line;
    line.quoted(g.all[r.series].name).num(g.all[r.series].B).num_if(phased(g.all[r.series]), r.psi).num(r.b).num(r.theta);
    line.text(r.maximum ? "max" : "min").count(r.runs);
    os << line.str() << "\n";
  }
}

void write_summary(std::ostream& ss, const Grid& g, const std::vector<Rainbow>& rainbows) {
  const double A = SceneParams{}.A, m = SceneParams{}.m;
  for (std::size_t k = 0; k < g.all.size(); ++k) {
    const Series& s = g.all[k];
    long points = 0, failed = 0, evals = 0;
    double max_rel = 0.0, max_oop = 0.0, min_r = kNaN, max_asym = 0.0, max_start = 0.0, th_lo = kNaN, th_hi = kNaN;
    for (std::size_t j = 0; j < g.phases_of(s); ++j)
      for (std::size_t i = 0; i < g.bs.size(); ++i) {
        const Point& p = g.row(k, j)[i];
        ++points;
        evals += p.force_evals;
        if (!p.ok()) {
          ++failed;
          continue;
        }
        if (s.B == 0.0) max_rel = std::max(max_rel, std::abs(p.sc.deflection / rutherford(A, m, p.sc.v_inf, p.sc.b) - 1.0));
        max_oop = std::max(max_oop, std::abs(p.sc.out_of_plane));
        if (!(p.r_min >= min_r)) min_r = p.r_min;
        if (std::isfinite(p.asymptote_error)) max_asym = std::max(max_asym, p.asymptote_error);
        if (std::isfinite(p.start_distance_error)) max_start = std::max(max_start, p.start_distance_error);
        if (i == 0) {
          th_lo = std::isnan(th_lo) ? p.sc.deflection : std::min(th_lo, p.sc.deflection);
          th_hi = std::isnan(th_hi) ? p.sc.deflection : std::max(th_hi, p.sc.deflection);
        }
      }
    long n_rainbows = 0;
    double rb_lo = kNaN, rb_hi = kNaN;
    for (const Rainbow& r : rainbows)
      if (r.series == k && r.maximum && std::isfinite(r.theta)) {
        ++n_rainbows;
        rb_lo = std::isnan(rb_lo) ? r.theta : std::min(rb_lo, r.theta);
        rb_hi = std::isnan(rb_hi) ? r.theta : std::max(rb_hi, r.theta);
      }
    const Point& first = g.row(k, 0)[0];
    const double p_inf = first.sc.in ? first.sc.in->p_inf : kNaN;
    CsvLine line;
    line.quoted(s.name).num(s.B).num(s.Kx).num(s.Kz).count(static_cast<long>(g.phases_of(s))).count(points).count(failed);
    line.num_if(s.B == 0.0, max_rel).num(th_lo).num(th_hi).num(rutherford(A, m, p_inf / m, first.sc.b)).num(max_oop);
    line.count(n_rainbows).num(rb_lo).num(rb_hi).num(min_r).num(max_asym).count(evals).num(max_start);
    ss << line.str() << "\n";
  }
}

std::string header_line(bool quick, const Grid& g) {
  return "# bodypoint study --name scattering" + std::string(quick ? " --quick" : "") + ", revision " + git_revision() +
         ": thesis table 3.1 with B and spin (Kx, Kz) per series, d solved for the incoming impact parameter b, the "
         "start phase for the arrival phase psi (" + std::to_string(g.phases.size()) +
         " phases per spinning series), the accuracy mode at tol " + fmt(kStudyTolerance) + " (" + fmt(kRetryLooser) +
         "x looser where out of reach; column tol) until the body has left\n";
}

}  // namespace

void write_scattering_study(const std::filesystem::path& dir, bool quick, unsigned threads) {
  const Grid g = run_grid(quick, threads);
  const std::vector<Rainbow> rainbows = find_rainbows(g, threads);
  AtomicFile csv((dir / "scattering.csv").string()), summary((dir / "scattering_summary.csv").string()),
      rb((dir / "scattering_rainbows.csv").string()), xs((dir / "scattering_cross_section.csv").string());
  const std::string header = header_line(quick, g);
  csv.stream() << "series,B,Kx,Kz,b,arrival_phase,d,v_inf,theta,asymptote_error,theta_rutherford,rel_diff_rutherford,"
                  "out_of_plane,r_min,t_min,t_end,spin_turn,K1_turn,time_delay,asymptotes,method,tol,force_evals,failure,"
                  "start_distance_error,deflection_error\n"
               << header;
  write_points(csv.stream(), g);
  rb.stream() << "series,B,arrival_phase,b,theta,kind,runs\n" << header
              << "# every extremum of theta(b) at fixed arrival phase, located by golden-section search on ln b\n";
  write_rainbows(rb.stream(), g, rainbows);
  xs.stream() << "series,B,theta_lo,theta_hi,theta,dsigma_domega,quadrature_error,covered,dsigma_rutherford_gc\n" << header
              << "# a beam uniform in b over [" << fmt(g.bs.front()) << ", " << fmt(g.bs.back())
              << "] and in the arrival phase, every branch summed; quadrature_error = |this - the same on every other b and "
                 "phase|; covered = 0 below the largest deflection at the largest b (larger b would add there); "
                 "dsigma_rutherford_gc = the same beam (each b at its own v_inf) under Rutherford's law for the guiding centre's "
                 "mass |K1|/u, by the same quadrature\n";
  write_cross_sections(xs.stream(), g, quick);
  summary.stream() << "series,B,Kx,Kz,phases,points,failed,max_rel_diff_rutherford,theta_min_at_smallest_b,"
                      "theta_max_at_smallest_b,theta_material_point_at_smallest_b,max_abs_out_of_plane,rainbows,"
                      "rainbow_theta_min,rainbow_theta_max,min_r_min,max_asymptote_error,force_evals,max_start_distance_error\n"
                   << header << "# one row per series; rainbows: maxima of theta(b) over every phase\n";
  write_summary(summary.stream(), g, rainbows);
  csv.commit();
  summary.commit();
  rb.commit();
  xs.commit();
  std::cerr << "wrote " << (dir / "scattering.csv").string() << ", scattering_summary.csv, scattering_rainbows.csv and "
            << "scattering_cross_section.csv (" << g.points.size() << " runs on the grid)\n";
}

namespace {

/// The L cost study's accuracy: the (#79) TOL, where a run from L = 200 costs about 47,000
/// evaluations with its start distance's run.
constexpr double kLCostTol = 1e-8;
/// The thesis's step (table 3.1) and its cheapest method's evaluations a step (symplectic Euler: one).
constexpr double kThesisStep = 1e-4;

/// One start distance of the L cost study: the encounter by auto to its departure and its start
/// distance's run (observables at the limit), every evaluation counted.
struct LCost {
  double L = 0.0, t_end = kNaN, deflection = kNaN, deflection_error = kNaN;
  long force_evals = 0;
  bool legs = false;
  std::string failure;
};

LCost l_cost(double L) {
  LCost c;
  c.L = L;
  SceneParams p;
  p.start.L = L;
  const SceneParams solved = with_asymptotic_data(p, 3.0, kNaN, 1.0);
  const Scene scene = thesis_scene(solved);
  const Body& body = scene.bodies.front();
  Options o;
  o.track_invariants = false;
  const std::function<Expected<Scene>()> far = [&] { return thesis_scene_twice_as_far(solved, 3.0, kNaN, 1.0); };
  std::optional<TwiceAsFar> twice = twice_as_far_beside(far, true, body, scene.centres, kLCostTol, o);
  EncounterResult r = encounter_beside(body, scene.centres, nullptr, kLCostTol, o, twice ? &*twice : nullptr);
  c.force_evals = r.run.total_force_evals();
  c.legs = r.run.chosen.find("far legs") != std::string::npos;
  if (r.encounter.outcome != Outcome::ok) {
    c.failure = r.encounter.reason;
    return c;
  }
  c.force_evals += add_start_distance(r.encounter, body, far, kLCostTol, r.run.error.for_orbit(), "", o, true, &r.run,
                                      twice ? &*twice : nullptr);
  c.t_end = r.run.run.t_end;
  c.deflection = r.encounter.scattering.deflection;
  c.deflection_error = r.encounter.deflection_error;
  return c;
}

}  // namespace

void write_L_cost(const std::filesystem::path& dir, bool quick) {
  AtomicFile f((dir / "L_cost.csv").string());
  f.stream() << "# bodypoint study" << (quick ? " --quick" : "") << " --name L: table 3.1 given by b = 3 and arrival phase 1, "
             << "started at L, run to its departure by auto at tol " << fmt(kLCostTol)
             << " with its observables at the limit L -> infinity (its run from 2L counted); fixed_step_evals: the thesis's "
             << "step h = " << fmt(kThesisStep) << " to the same departure, one evaluation a step\n"
             << "L,force_evals,far_legs,t_end,deflection,deflection_error,fixed_step_evals,failure\n";
  for (const double L : log_range(50.0, 1e5, quick ? 7 : 19)) {
    const LCost c = l_cost(L);
    CsvLine line;
    line.num(c.L).count(c.force_evals).count(c.legs ? 1 : 0).num(c.t_end).num(c.deflection).num(c.deflection_error);
    line.count(std::isfinite(c.t_end) ? std::lround(c.t_end / kThesisStep) : 0).quoted(c.failure);
    f.stream() << line.str() << '\n';
  }
  f.commit();
  std::cerr << "wrote " << (dir / "L_cost.csv").string() << "\n";
}

}  // namespace bodypoint::cli

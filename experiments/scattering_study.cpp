// `bodypoint study --name scattering` (scattering_study.hpp).
//
// Every run is the thesis's scene (table 3.1: A = -2, m = J = 1, K1 = 5, L = 200) with the coupling B
// and the spin (Kx, Kz) of its series, d solved so that the incoming asymptote has impact parameter b
// (scattering.hpp, d_for_impact_parameter), integrated by the accuracy mode (--method auto) to twice
// the time the body needs to cross L, so that it ends as far from the centre as it started. Per run:
// the deflection between the asymptotes and its part out of the incoming plane, the closest approach
// (located on the method's own steps) and the angle the spin turned. Per series: the differential
// cross-section dsigma/dOmega = b/sin(theta) |db/dtheta| from neighbouring b (centred differences),
// rainbows (where dtheta/db changes sign), and for B = 0 the largest relative difference from
// Rutherford's tan(theta/2) = |A|/(m v_inf^2 b) and its cross-section (|A|/(2 m v_inf^2))^2/sin^4(theta/2).
#include "process.hpp"
#include "scattering_study.hpp"

#include "bodypoint/bodypoint.hpp"
#include "bodypoint/threads.hpp"
#include "bodypoint/io.hpp"
#include "sweep.hpp"

#include <algorithm>
#include <atomic>
#include <limits>
#include <cmath>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace bodypoint::cli {
namespace {

/// The accuracy asked of every run: the final state to 1e-12 relative, so that the deflection, a
/// function of the conserved quantities at the two ends, is known to ~1e-12 as well.
constexpr double kStudyTolerance = 1e-12;

/// A run whose tolerance is out of reach (finer runs stop agreeing better than the round-off floor the
/// encounter amplifies: B = 0.9, b = 1..2 differ by ~4e-12)
/// is repeated this much looser; the row records the tolerance delivered.
constexpr double kRetryLooser = 10.0;

struct Series {
  std::string name;
  double B, Kx, Kz;
  const char* method = "auto";
};

/// B = 0 (Rutherford; auto chooses ks there, exact in its fictitious time, so lp-kl8 too), then the thesis's spin (Kx, Kz) = (2, 5) at B = 0.2 .. 0.9, and at B = 0.7 a
/// spin along K1 (Kz = 0) and one perpendicular to it (Kx = 0).
std::vector<Series> series() {
  return {{"B=0", 0.0, 2, 5},         {"B=0 lp-kl8", 0.0, 2, 5, "lp-kl8"}, {"B=0.2", 0.2, 2, 5},          {"B=0.5", 0.5, 2, 5},
          {"B=0.7", 0.7, 2, 5},       {"B=0.9", 0.9, 2, 5},          {"B=0.7 spin along K1", 0.7, 5, 0},
          {"B=0.7 spin across K1", 0.7, 0, 5}};
}

struct Point {
  double b_target = 0.0, d = 0.0;
  Scattering sc;
  double r_min = kNaN, t_min = kNaN, t_end = 0.0, r_end = kNaN, tol = kStudyTolerance, asymptote_error = kNaN;
  long force_evals = 0;
  std::string method, failure;
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
};

Point run_point(const Series& s, double b) {
  Point p;
  p.b_target = b;
  SceneParams params;
  params.B = s.B;
  params.start.Kx = s.Kx;
  params.start.Kz = s.Kz;
  try {
    p.d = d_for_impact_parameter(params, b);
    params.start.d = p.d;
    const Scene scene = thesis_scene(params);
    const Body& body = scene.bodies.front();
    Options o;
    o.track_invariants = false;
    const MethodInfo* method = std::string_view(s.method) == "auto" ? nullptr : &method_or_throw(s.method);
    EncounterResult r = encounter(body, scene.centres, method, p.tol, Scattering::kNaN, o);
    if (r.run.outcome == Outcome::failed && r.run.reason.find("out of reach") != std::string::npos) {
      p.tol *= kRetryLooser;
      r = encounter(body, scene.centres, method, p.tol, Scattering::kNaN, o);
    }
    const BodyResult& br = r.run;
    p.force_evals = br.total_force_evals();
    p.t_end = br.run.t_end;
    if (br.method) p.method = br.method->name;
    if (r.encounter.outcome != Outcome::ok) {
      p.failure = r.encounter.reason;
      return p;
    }
    p.sc = r.encounter.scattering;
    p.asymptote_error = r.encounter.asymptote_error;
    p.r_end = (br.run.final.R - scene.centres.front().c).norm();
    p.r_min = r.encounter.r_min;
    p.t_min = r.encounter.t_min;
  } catch (const Error& e) {
    p.failure = e.what();
  }
  return p;
}

double rutherford(double A, double mu, double v_inf, double b) { return 2.0 * std::atan(std::abs(A) / (mu * v_inf * v_inf * b)); }

}  // namespace

namespace {

/// Every (series, b) point, on `threads` threads.
std::vector<Point> run_points(const std::vector<Series>& all, const std::vector<double>& bs, unsigned threads) {
  std::vector<Point> points(all.size() * bs.size());
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i; (i = next++) < points.size();) points[i] = run_point(all[i / bs.size()], bs[i % bs.size()]);
  };
  {
    const WorkerThreads pool(std::max(1u, threads) - 1, worker);  // joined before points is read
    worker();
  }
  return points;
}

/// What a series' summary row gathers from its points.
struct SeriesTotals {
  double max_rel = 0.0, max_oop = 0.0, min_r = Point::kNaN, first_rainbow = Point::kNaN;
  long evals = 0, rainbows = 0, failed = 0;
};

/// One series' n points as rows of scattering.csv; returns what its summary row needs.
SeriesTotals write_series_rows(std::ostream& os, const Series& s, const Point* row, std::size_t n) {
  const double A = SceneParams{}.A, m = SceneParams{}.m;
  SeriesTotals t;
  for (std::size_t i = 0; i < n; ++i) {
    const Point& p = row[i];
    t.evals += p.force_evals;
    const bool ok = p.failure.empty() && std::isfinite(p.sc.deflection);
    t.failed += ok ? 0 : 1;
    const double th_r = ok && s.B == 0.0 ? rutherford(A, m, p.sc.v_inf, p.sc.b) : Point::kNaN;
    const double rel = ok && s.B == 0.0 ? std::abs(p.sc.deflection / th_r - 1.0) : Point::kNaN;
    if (rel > t.max_rel) t.max_rel = rel;
    if (ok) t.max_oop = std::max(t.max_oop, std::abs(p.sc.out_of_plane));
    if (ok && !(p.r_min >= t.min_r)) t.min_r = p.r_min;
    // dsigma/dOmega = b/sin(theta) |db/dtheta| from the neighbours (centred differences)
    double dsigma = Point::kNaN, dsigma_r = Point::kNaN;
    bool rainbow = false;
    if (ok && i > 0 && i + 1 < n && row[i - 1].failure.empty() && row[i + 1].failure.empty()) {
      const double dtheta_db = (row[i + 1].sc.deflection - row[i - 1].sc.deflection) / (row[i + 1].sc.b - row[i - 1].sc.b);
      dsigma = p.sc.b / std::sin(p.sc.deflection) / std::abs(dtheta_db);
      if (s.B == 0.0) {
        const double a = std::abs(A) / (2.0 * m * p.sc.v_inf * p.sc.v_inf);
        dsigma_r = a * a / std::pow(std::sin(0.5 * th_r), 4);
      }
      // a rainbow between i-1 and i+1: theta(b) has an extremum at i
      const double left = p.sc.deflection - row[i - 1].sc.deflection, right = row[i + 1].sc.deflection - p.sc.deflection;
      if (left * right < 0.0) {
        rainbow = true;
        ++t.rainbows;
        if (!std::isfinite(t.first_rainbow)) t.first_rainbow = p.sc.b;
      }
    }
    CsvLine line;
    line.quoted(s.name).num(s.B).num(s.Kx).num(s.Kz).num(ok ? p.sc.b : p.b_target).num(p.d).num(p.sc.v_inf).num(p.sc.deflection);
    line.num_if(s.B == 0.0 && ok, th_r).num_if(s.B == 0.0 && ok, rel).num(p.sc.out_of_plane).num_if(std::isfinite(dsigma), dsigma);
    line.num_if(std::isfinite(dsigma_r), dsigma_r).count(rainbow ? 1 : 0).num(p.r_min).num(p.t_min).num(p.r_end).num(p.sc.spin_turn).num(p.sc.K1_turn);
    line.num(p.sc.time_delay).quoted(p.sc.asymptotes).text(p.method).num(p.tol).count(p.force_evals).quoted(p.failure);
    os << line.str() << "\n";
  }
  return t;
}

/// One series' row of scattering_summary.csv.
void write_series_summary(std::ostream& ss, const Series& s, const Point& first, std::size_t n, const SeriesTotals& t) {
  const double A = SceneParams{}.A, m = SceneParams{}.m;
  CsvLine line;
  line.quoted(s.name).num(s.B).num(s.Kx).num(s.Kz).count(static_cast<long>(n)).count(t.failed);
  line.num_if(s.B == 0.0, t.max_rel).num(first.sc.deflection);
  // a material point of mass m with the same momentum at infinity and impact parameter
  const double p_inf = first.sc.in ? first.sc.in->p_inf : Point::kNaN;
  line.num(rutherford(A, m, p_inf / m, first.sc.b)).num(t.max_oop).count(t.rainbows);
  line.num_if(std::isfinite(t.first_rainbow), t.first_rainbow).num(t.min_r).count(t.evals);
  ss << line.str() << "\n";
}

}  // namespace

void write_scattering_study(const std::filesystem::path& dir, bool quick, unsigned threads) {
  const std::vector<double> bs = log_range(1e-3, 1e3, quick ? 13 : 61);
  const std::vector<Series> all = series();
  const std::vector<Point> points = run_points(all, bs, threads);
  AtomicFile csv((dir / "scattering.csv").string()), summary((dir / "scattering_summary.csv").string());
  std::ostream& os = csv.stream();
  os << "series,B,Kx,Kz,b,d,v_inf,theta,theta_rutherford,rel_diff_rutherford,out_of_plane,dsigma_domega,"
        "dsigma_rutherford,rainbow,r_min,t_min,r_end,spin_turn,K1_turn,time_delay,asymptotes,method,tol,force_evals,failure\n"
     << "# bodypoint study --name scattering" << (quick ? " --quick" : "") << ", revision " << git_revision()
     << ": thesis table 3.1 with B and spin (Kx, Kz) per series, d solved for the incoming impact parameter b, "
        "the accuracy mode at tol " << fmt(kStudyTolerance) << " (" << fmt(kRetryLooser)
     << "x looser where out of reach; column tol) to t_end = 2 L / v_inf; no asymptotes where the body does not "
        "drift away along K1\n";
  std::ostream& ss = summary.stream();
  ss << "series,B,Kx,Kz,points,failed,max_rel_diff_rutherford,theta_at_smallest_b,theta_material_point_at_smallest_b,"
        "max_abs_out_of_plane,rainbows,first_rainbow_b,min_r_min,force_evals\n"
     << "# bodypoint study --name scattering" << (quick ? " --quick" : "") << ", revision " << git_revision()
     << ": one row per series; rainbows where dtheta/db changes sign (b of the extremum between grid points)\n";
  for (std::size_t si = 0; si < all.size(); ++si) {
    const Point* row = &points[si * bs.size()];
    const SeriesTotals t = write_series_rows(os, all[si], row, bs.size());
    write_series_summary(ss, all[si], row[0], bs.size(), t);
  }
  csv.commit();
  summary.commit();
  std::cerr << "wrote " << (dir / "scattering.csv").string() << " and scattering_summary.csv (" << points.size()
            << " runs)\n";
}

}  // namespace bodypoint::cli

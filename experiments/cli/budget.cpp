#include "budget.hpp"

#include "bodypoint/bodypoint.hpp"
#include "checked.hpp"
#include "bodypoint/io.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <limits>
#include <utility>
#include <variant>
#include <unistd.h>

namespace bodypoint::cli {
namespace {

/// Runs longer than this many steps are calibrated first (10^7 steps take 0.3..3 s).
constexpr long kCalibrateAbove = 10'000'000;
/// Steps of the calibration run: long enough for a stable time per step (several ms), at most 1 % of
/// a run worth calibrating.
constexpr long kCalibrationSteps = 100'000;
/// Time-transformed runs to an end time first take this many fictitious steps to see how much
/// physical time they cover: a run that is shorter than that is not calibrated further.
constexpr long kProbeSteps = 1'000;
/// A bar is drawn only for runs expected to take longer than this.
constexpr double kBarSeconds = 2.0;

std::string duration(double s) {
  char buf[64];
  if (s < 120) std::snprintf(buf, sizeof buf, "%.3g s", s);
  else if (s < 7200) std::snprintf(buf, sizeof buf, "%.3g min", s / 60);
  else if (s < 2 * 86400) std::snprintf(buf, sizeof buf, "%.3g h", s / 3600);
  else std::snprintf(buf, sizeof buf, "%.3g days", s / 86400);
  return buf;
}

}  // namespace

std::optional<WorkEstimate> estimate_work(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                          const Advance& requested, const Options& options) {
  const Advance how = forwards(requested);  // a run backwards costs what its forward run does
  const auto* fixed = std::get_if<FixedSteps>(&how);
  const auto* fictitious = std::get_if<FictitiousSteps>(&how);
  if (!fixed && !fictitious) return std::nullopt;
  // A calibration without an end time can run away (ks's physical step grows with r): no estimate
  // then; the run's own checks still bound it.
  auto calibrate = [&](long steps) -> std::optional<RunResult> {
    Options cal;
    cal.track_invariants = options.track_invariants;
    cal.omega_c = options.omega_c;
    cal.max_energy_error = std::numeric_limits<double>::infinity();
    cal.estimate_error = false;
    const Advance a = fixed ? Advance(FixedSteps{fixed->h, steps}) : Advance(FictitiousSteps{fictitious->ds, StepCount{steps}});
    BodyResult r = detail::integrate_checked(body, centres, &m, a, cal);
    if (!ran(r.outcome)) return std::nullopt;
    return std::move(r.run);
  };
  const double t_end = fictitious ? fictitious->t_end() : 0.0;
  double steps = static_cast<double>(fixed ? fixed->steps : fictitious->steps());
  if (t_end > 0.0) {
    // How much physical time do kProbeSteps fictitious steps cover? A run shorter than the probe, or
    // than kCalibrateAbove steps at the probe's rate, is not calibrated further.
    const auto probe = calibrate(kProbeSteps);
    if (!probe || probe->t_end >= t_end) return std::nullopt;
    steps = probe->t_end > 0.0 ? kProbeSteps * t_end / probe->t_end : HUGE_VAL;
  }
  if (steps <= static_cast<double>(kCalibrateAbove)) return std::nullopt;
  const auto r = calibrate(kCalibrationSteps);
  if (!r) return std::nullopt;
  if (t_end > 0.0) steps = r->t_end > 0.0 ? kCalibrationSteps * t_end / r->t_end : HUGE_VAL;
  const double companion = options.estimate_error ? ErrorEstimate::kTypicalCost : 0.0;  // its steps, at the same pace
  return WorkEstimate{steps, (1.0 + companion) * r->wall_s * steps / kCalibrationSteps};
}

double estimated_seconds(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, double step,
                         double steps, double runs) {
  if (!(steps > 0.0) || !(runs > 0.0) || takes_tolerance_per_step(m)) return 0.0;
  // A calibration of kCalibrationSteps: asked for as a long run, so that estimate_work measures it.
  constexpr long kAsLong = 2 * kCalibrateAbove;
  const Advance how = advance_of(m, {.step = step, .steps = kAsLong});
  Options quiet;
  quiet.track_invariants = false;
  quiet.estimate_error = false;  // the caller counts the runs
  const auto e = estimate_work(m, body, centres, how, quiet);
  if (!e || !(e->steps > 0.0)) return 0.0;
  return e->seconds / e->steps * steps * runs;
}

namespace {

std::string work_text(const WorkEstimate& e) {
  char steps[32];
  std::snprintf(steps, sizeof steps, "%.3g", e.steps);
  return std::string(steps) + " steps, about " + duration(e.seconds) + " (calibrated on " +
         std::to_string(kCalibrationSteps) + " steps)";
}

}  // namespace

std::string over_budget(const WorkEstimate& e, double max_seconds) {
  if (!(e.seconds > max_seconds)) return {};
  return "the run would take " + work_text(e) + ", above --max-seconds " + fmt(max_seconds) +
         ": shorten it, take a larger step, or raise --max-seconds";
}

void check_budget(const WorkEstimate& e, double max_seconds, bool quiet) {
  if (std::string why = over_budget(e, max_seconds); !why.empty()) throw Error(why);
  if (!quiet && e.seconds > kAnnounceSeconds) std::cerr << "bodypoint: " << work_text(e) << "\n";
}

bool progress_wanted(bool quiet) { return !quiet && ::isatty(2) == 1 && std::getenv("CI") == nullptr; }

bool notice_wanted(bool quiet) { return !quiet && std::getenv("CI") == nullptr; }

WorkingNotice::WorkingNotice(const std::string& what, bool enabled) {
  if (!enabled) return;
  const std::time_t started = std::time(nullptr);
  thread_ = std::thread([this, what, started] {
    std::unique_lock<std::mutex> lock(mutex_);
    if (done_cv_.wait_for(lock, std::chrono::duration<double>(kNoticeSeconds), [this] { return done_; })) return;
    char at[16] = "";
    std::strftime(at, sizeof at, "%H:%M:%S", std::localtime(&started));
    std::fprintf(stderr, "bodypoint %s: working (started %s); its output follows when it is done\n", what.c_str(), at);
    std::fflush(stderr);
  });
}

WorkingNotice::~WorkingNotice() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    done_ = true;
  }
  done_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

ProgressBar::ProgressBar(const std::optional<WorkEstimate>& e, bool enabled) {
  if (!enabled || !e || e->seconds < kBarSeconds) return;
  const double expected = e->seconds;
  thread_ = std::thread([this, expected] {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    while (!stop_.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      const double el = std::chrono::duration<double>(Clock::now() - t0).count();
      const double f = std::min(el / expected, 0.99);
      const int filled = static_cast<int>(f * 30);
      std::fprintf(stderr, "\r[%.*s%*s] %3d%%  %s left ", filled, "##############################", 30 - filled, "",
                   static_cast<int>(100 * f), duration(std::max(expected - el, 0.0)).c_str());
      std::fflush(stderr);
    }
    std::fprintf(stderr, "\r%60s\r", "");
    std::fflush(stderr);
  });
}

ProgressBar::ProgressBar(const std::string& label, bool enabled) {
  if (!enabled) return;
  thread_ = std::thread([this, label] {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    bool drawn = false;
    while (!stop_.load()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
      const double el = std::chrono::duration<double>(Clock::now() - t0).count();
      if (el < kBarSeconds) continue;
      std::fprintf(stderr, "\r%s: %s so far ", label.c_str(), duration(el).c_str());
      std::fflush(stderr);
      drawn = true;
    }
    if (drawn) {
      std::fprintf(stderr, "\r%*s\r", static_cast<int>(label.size()) + 24, "");
      std::fflush(stderr);
    }
  });
}

ProgressBar::~ProgressBar() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

}  // namespace bodypoint::cli

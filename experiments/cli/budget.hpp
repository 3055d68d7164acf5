// bodypoint: a work estimate before a long run, a budget it must fit, and a progress bar.
//
// A run of more than kCalibrateAbove steps (a time-transformed run to an end time: when a short probe
// says it needs that many) is first calibrated on kCalibrationSteps steps of the same method and body; the estimate (steps and seconds)
// is printed when it is long, refused when it exceeds the budget, and drives a progress bar on a
// terminal (never under CI, with --quiet, or when standard error is not a terminal); elsewhere a command
// at work for more than kNoticeSeconds says so in one line (WorkingNotice).
#pragma once

#include "bodypoint/bodypoint.hpp"
#include "bodypoint/run.hpp"

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace bodypoint::cli {

struct WorkEstimate {
  double steps = 0.0;    ///< steps (fictitious steps for time-transformed methods)
  double seconds = 0.0;  ///< of the step loop, extrapolated from the calibration
};

/// The estimate for a run that may be long, or nothing when the run is short (or adaptive: those are
/// bounded by their own step cap).
/// `options` are the run's (the calibration observes as it will; an error estimate's companion costs
/// ErrorEstimate::kTypicalCost runs more). The request was checked by the caller (check_request, or the
/// scene by validate and the rest by check_run): the calibration runs it unchecked.
std::optional<WorkEstimate> estimate_work(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                                          const Advance& how, const Options& options);

/// Estimates above this are announced on stderr before the run (or study) starts.
inline constexpr double kAnnounceSeconds = 10.0;

/// Every command's budget of wall-clock time unless --max-seconds says otherwise (0: none): a day, so
/// that no command runs on without end by default (simulate's own default is an hour).
inline constexpr double kDefaultMaxSeconds = 86400.0;

/// No step of any method takes this long (the slowest, a Kepler-split or Kahan-Li 8 step, takes a few
/// microseconds; a sanitizer build some tens): below steps x this, a budget cannot be exceeded and the
/// calibration is skipped.
inline constexpr double kMaxSecondsPerStep = 1e-4;

/// The calibrated seconds of `runs` runs of `m` for `steps` steps (or fictitious steps) of `step`
/// each: the time per step of a short calibration run times the steps. Never below zero.
double estimated_seconds(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, double step,
                         double steps, double runs);

/// Why a run of this estimate is refused (it exceeds max_seconds: the message names both), or "".
std::string over_budget(const WorkEstimate& e, double max_seconds);
/// Throws over_budget's Error when the estimate exceeds max_seconds; prints it on stderr when it exceeds
/// kAnnounceSeconds and `quiet` is false.
void check_budget(const WorkEstimate& e, double max_seconds, bool quiet);

/// True when a progress bar may be drawn: stderr is a terminal, CI is unset and not quiet.
bool progress_wanted(bool quiet);

/// True when a command says on stderr that it is still working (WorkingNotice): not quiet, CI unset.
bool notice_wanted(bool quiet);

/// One line on stderr once a command has worked kNoticeSeconds, from a thread while alive, so that a long
/// call is not taken for a hang where no progress bar is drawn (a script's log, a pipe): "bodypoint
/// sweep: working (started 10:19:34); its output follows when it is done".
class WorkingNotice {
 public:
  WorkingNotice(const std::string& what, bool enabled);
  ~WorkingNotice();
  WorkingNotice(const WorkingNotice&) = delete;
  WorkingNotice& operator=(const WorkingNotice&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
  std::thread thread_;
};
/// Seconds of work after which WorkingNotice speaks (the progress bar's too).
inline constexpr double kNoticeSeconds = 2.0;

/// Draws elapsed/expected time on stderr from a thread while alive (when enabled and the run is long).
class ProgressBar {
 public:
  ProgressBar(const std::optional<WorkEstimate>& e, bool enabled);
  /// A search whose length is not known beforehand (the accuracy mode): past kBarSeconds, "<label>: N s"
  /// (the time so far) instead of a bar (a kep-y4 search at 1e-12 ran 600 s without a sign).
  ProgressBar(const std::string& label, bool enabled);
  ~ProgressBar();
  ProgressBar(const ProgressBar&) = delete;
  ProgressBar& operator=(const ProgressBar&) = delete;

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace bodypoint::cli

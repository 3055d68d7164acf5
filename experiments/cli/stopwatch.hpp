// bodypoint: one timing discipline for every timed number of the commands (work-precision and its
// --by-tol view, the timing study; bench/ follows the same rules with Google Benchmark's own options).
//
//   * warm-up: every configuration runs untimed before any is timed (caches, page faults, the clock);
//   * interleaved repeats: repeat k times every configuration compared once, in turn, so that a
//     slow period of the machine lands on all of them, not on one;
//   * a repeat of a configuration shorter than kMinRepeatSeconds is a batch of identical calls
//     (their count fixed in the warm-up), its time divided by the count: a 2 us run is not timed by
//     one reading of the clock;
//   * wall time (steady clock) and this thread's CPU time (CLOCK_THREAD_CPUTIME_ID) of the same calls;
//   * median and spread over the repeats: the interquartile range over the median (robust to the
//     one slow repeat a virtual machine's host gives now and then; the slowest and fastest are kept);
//   * a contention check: a configuration whose median wall time exceeds its CPU time by more than
//     kMaxWaitShare (the thread waited: another process had the core) or whose repeats spread beyond
//     kMaxSpread is flagged, and paper/make_macros.py prints no flagged time as a result.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace bodypoint::cli {

/// Wall above CPU time by more than this share: the thread was not running for part of the call.
/// Quiet, the 2-core virtual machine measures 0.01-0.07 % here (median 0.04 %, largest 3 % over the 286
/// configurations of `work-precision --by-tol --scenes close,thesis --tols 1e-4,1e-7,1e-10`).
constexpr double kMaxWaitShare = 0.05;
/// Repeats spreading by more than this share of their median (interquartile range): the machine's speed
/// changed during the measurement. Quiet, the same 286 configurations measure a median spread of
/// 1.6-2.3 % and 90 % of them below 6-14 % (two runs); a parallel build on the other core pushes it past
/// this bound.
constexpr double kMaxSpread = 0.10;
/// A timed repeat is at least this long (a batch of identical calls when one call is shorter).
constexpr double kMinRepeatSeconds = 2e-3;
/// The fewest timed repeats a timing counts with (the project's timing rules).
constexpr long kMinRepeats = 5;

struct TimingRules {
  long warmup = 1;  ///< calls of every configuration before the first timed repeat (at least one: it sizes the batch)
  long repeats = kMinRepeats;
  double min_repeat_s = kMinRepeatSeconds;
};

/// Medians and spread of one configuration's repeats (per call).
struct Timing {
  double wall_s = 0.0, cpu_s = 0.0;    ///< medians over the repeats, per call
  double min_wall_s = 0.0, max_wall_s = 0.0;
  double q1_wall_s = 0.0, q3_wall_s = 0.0;  ///< quartiles of the repeats' wall times
  long repeats = 0, calls_per_repeat = 1;

  [[nodiscard]] double spread() const { return wall_s > 0.0 ? (q3_wall_s - q1_wall_s) / wall_s : 0.0; }
  [[nodiscard]] double wait_share() const { return cpu_s > 0.0 ? wall_s / cpu_s - 1.0 : 0.0; }
  /// "" when the timing counts; otherwise why not ("contended: wall 1.31x CPU", "spread 22 %",
  /// "3 repeats (< 5)").
  [[nodiscard]] std::string flag() const;
};

/// Throws Error unless the rules can be followed: 1 <= repeats <= 1e6 (each repeat keeps its time for
/// the median: 1e15 of them ran, and allocated, without end), warmup >= 0. The commands check their
/// options with it before any work; time_interleaved checks again.
void check_rules(const TimingRules& rules);

/// The median of v (the mean of the middle two for an even count).
double median(std::vector<double> v);

/// Runs each configuration rules.warmup times, then rules.repeats rounds each timing every
/// configuration once, in order; returns one Timing per configuration.
std::vector<Timing> time_interleaved(const std::vector<std::function<void()>>& configs, const TimingRules& rules);

/// Whether a is the better pick than b (nullptr: none yet) for "the fastest configuration": a time that
/// counts beats a flagged one, whatever their medians (a flagged median is not a result); then the shorter.
bool faster_pick(const Timing& a, const Timing* b);

/// A summary table's time cell: the median in ms (3 digits), or "flagged (t)" when it does not count.
std::string time_cell(const Timing& t);
/// A summary table's speed-up cell, theirs / ours: "2.31x", "flagged" when either time does not count,
/// "-" when either is missing.
std::string ratio_cell(const Timing* ours, const Timing* theirs);

/// The CSV header's lines that state the rules the times were taken under ("# " prefixed).
std::string timing_rules_note(const TimingRules& rules);

}  // namespace bodypoint::cli

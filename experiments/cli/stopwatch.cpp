// bodypoint: the timing discipline of the commands (stopwatch.hpp).
#include "stopwatch.hpp"

#include "bodypoint/model.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iomanip>
#include <utility>
#include <sstream>

namespace bodypoint::cli {
namespace {

/// A batch never exceeds this many calls (a call of 10 ns would otherwise make 2e5).
constexpr long kMaxCallsPerRepeat = 10000;

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Reading {
  double wall_s, cpu_s;
};

Reading time_calls(const std::function<void()>& f, long calls) {
  const auto w0 = std::chrono::steady_clock::now();
  const double c0 = thread_cpu_seconds();
  for (long i = 0; i < calls; ++i) f();
  const double c1 = thread_cpu_seconds();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  return {wall / static_cast<double>(calls), (c1 - c0) / static_cast<double>(calls)};
}

/// The q-quantile of v (0 <= q <= 1), interpolated between order statistics.
double quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double x = q * static_cast<double>(v.size() - 1);
  const auto i = static_cast<std::size_t>(x);
  return i + 1 < v.size() ? v[i] + (x - static_cast<double>(i)) * (v[i + 1] - v[i]) : v[i];
}

}  // namespace

double median(std::vector<double> v) { return quantile(std::move(v), 0.5); }

void check_rules(const TimingRules& rules) {
  if (rules.repeats < 1) throw Error("--repeats must be >= 1");
  if (rules.repeats > 1'000'000) throw Error("--repeats must be at most 1e6");
  if (rules.warmup < 0) throw Error("--warmup must be >= 0");
}

namespace {

std::string percent(double share) {
  std::ostringstream os;
  os << std::fixed << std::setprecision(share >= 0.1 ? 0 : 1) << share * 100.0 << " %";
  return os.str();
}

}  // namespace

std::string Timing::flag() const {
  std::vector<std::string> why;
  if (repeats < kMinRepeats)
    why.push_back(std::to_string(repeats) + " repeat" + (repeats == 1 ? "" : "s") + " (< " +
                  std::to_string(kMinRepeats) + ")");
  if (wait_share() > kMaxWaitShare) why.push_back("contended: wall " + percent(wait_share()) + " above CPU");
  if (spread() > kMaxSpread) why.push_back("spread " + percent(spread()));
  std::string out;
  for (const std::string& w : why) out += (out.empty() ? "" : "; ") + w;
  return out;
}

bool faster_pick(const Timing& a, const Timing* b) {
  if (!b) return true;
  const bool a_counts = a.flag().empty(), b_counts = b->flag().empty();
  if (a_counts != b_counts) return a_counts;
  return a.wall_s < b->wall_s;
}

std::vector<Timing> time_interleaved(const std::vector<std::function<void()>>& configs, const TimingRules& rules) {
  check_rules(rules);
  std::vector<long> calls(configs.size(), 1);
  for (std::size_t i = 0; i < configs.size(); ++i) {
    // The last warm-up call (at least one) is timed: the batch size, calls reaching min_repeat_s.
    for (long w = 1; w < rules.warmup; ++w) configs[i]();
    const Reading one = time_calls(configs[i], 1);
    if (one.wall_s > 0.0 && one.wall_s < rules.min_repeat_s)
      calls[i] = std::min(kMaxCallsPerRepeat, static_cast<long>(std::ceil(rules.min_repeat_s / one.wall_s)));
  }
  std::vector<std::vector<double>> wall(configs.size()), cpu(configs.size());
  for (long r = 0; r < rules.repeats; ++r)
    for (std::size_t i = 0; i < configs.size(); ++i) {
      const Reading x = time_calls(configs[i], calls[i]);
      wall[i].push_back(x.wall_s);
      cpu[i].push_back(x.cpu_s);
    }
  std::vector<Timing> out(configs.size());
  for (std::size_t i = 0; i < configs.size(); ++i) {
    Timing& t = out[i];
    t.wall_s = median(wall[i]);
    t.cpu_s = median(cpu[i]);
    t.q1_wall_s = quantile(wall[i], 0.25);
    t.q3_wall_s = quantile(wall[i], 0.75);
    t.min_wall_s = *std::min_element(wall[i].begin(), wall[i].end());
    t.max_wall_s = *std::max_element(wall[i].begin(), wall[i].end());
    t.repeats = rules.repeats;
    t.calls_per_repeat = calls[i];
  }
  return out;
}

std::string time_cell(const Timing& t) {
  std::ostringstream os;
  os.precision(3);
  os << t.wall_s * 1e3;
  return t.flag().empty() ? os.str() : "flagged (" + os.str() + ")";
}

std::string ratio_cell(const Timing* ours, const Timing* theirs) {
  if (!ours || !theirs) return "-";
  if (!ours->flag().empty() || !theirs->flag().empty()) return "flagged";
  std::ostringstream os;
  os.precision(3);
  os << theirs->wall_s / ours->wall_s << "x";
  return os.str();
}

std::string timing_rules_note(const TimingRules& rules) {
  std::ostringstream os;
  os << "# timing: " << std::max(rules.warmup, 1L) << " warm-up call(s) of every configuration, then " << rules.repeats
     << " repeats interleaved across the configurations; a repeat is one call or a batch of calls lasting >= "
     << rules.min_repeat_s * 1e3 << " ms; wall_s/cpu_s = medians per call of wall and thread CPU time; "
     << "spread = interquartile range/median of the wall times\n"
     << "# flag: why a time does not count (fewer than " << kMinRepeats << " repeats; wall above CPU by more than "
     << kMaxWaitShare * 100 << " %: contended; spread above " << kMaxSpread * 100 << " %); empty: it counts\n";
  return os.str();
}

}  // namespace bodypoint::cli

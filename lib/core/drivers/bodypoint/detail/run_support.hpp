// bodypoint: the pieces every run loop shares: the invariant/sample observer, the timing wrapper
// that picks a null observer when nothing is asked for, and the once-per-run choice of field type
// and spin. Used by lib/core/drivers/bodypoint/run.cpp and adaptive/.
#pragma once

#include "bodypoint/field.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "bodypoint/run.hpp"
#include "bodypoint/splitting/composition.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <limits>
#include <optional>
#include <type_traits>
#include <vector>

namespace bodypoint::detail {

using Clock = std::chrono::steady_clock;

/// Step-size-controlled runs (Boost.Odeint, GSL): more than kMaxAdaptiveSteps accepted steps (a
/// minute or more of work) means the tolerance or the end time is out of proportion.
constexpr long kMaxAdaptiveSteps = 200'000'000L;

/// Checked every 2^20 accepted steps: throws when the rate so far would need more than
/// kMaxAdaptiveSteps to reach t_end (odeint-dopri5 to t_end = 1e12 spent 68 s before its cap).
inline void check_adaptive_rate(long steps, double t, double t_end) {
  constexpr long kEvery = 1L << 20;
  if (steps == 0 || steps % kEvery != 0 || !(t > 0.0)) return;
  const double needed = static_cast<double>(steps) * t_end / t;
  if (needed > static_cast<double>(kMaxAdaptiveSteps))
    throw Error("at its rate so far (t = " + short_number(t) + " after " + std::to_string(steps) +
                " accepted steps) the run needs about " + short_number(needed) + " steps to reach t_end = " +
                short_number(t_end) + ", more than the budget of 2e8; loosen the tolerance tol or shorten t_end");
}

/// False when a step from t_before to t did not move time by more than a few of its last bits: such
/// steps would repeat forever (a tolerance below double precision, a fall onto a centre).
inline bool time_advances(double t_before, double t) {
  constexpr double kUlps = 16.0;
  return t - t_before > kUlps * std::numeric_limits<double>::epsilon() * std::abs(t);
}


/// The time grid the observer needs: fixed steps h (step i ends at i h; the last is `steps`), and
/// the output interval of a driver that makes its own output times (fictitious steps; 0: none).
struct Grid {
  double h = 0.0;
  long steps = 0;
  double dt_out = 0.0;
};
inline Grid grid_of(const FixedSteps& f) { return {f.h, f.steps, 0.0}; }
inline Grid grid_of(const ControlledSteps&) { return {}; }
inline Grid grid_of(const FictitiousSteps& f) { return {0.0, f.steps(), f.dt_out}; }

/// Throws Error(kStoppedOnRequest) (out of line: the loops keep only the poll's load and branch).
[[noreturn]] void stop_on_request();

/// The poll of RunOptions::cancel that every step loop makes through its observer (`obs.poll(i)`).
/// A cancelled run is no result: it leaves by Error(kStoppedOnRequest), which the run's caller reports.
struct CancelPoll {
  const std::atomic<bool>* cancel = nullptr;
  void poll(long i) const {
    if (cancel && i % kPollStride == 0 && cancel->load(std::memory_order_relaxed)) [[unlikely]]
      stop_on_request();
  }
};

/// The observer of a run that observes nothing but may be cancelled: it never ends a loop early.
struct Unobserved : splitting::NullObserver {
  CancelPoll cancel;
  bool poll(long i) const {
    cancel.poll(i);
    return true;
  }
};

/// Where a sink said Flow::stop: the run ends at the state it was handed.
struct SinkStop {
  long step;
  double t;
  State s;
};

/// Observer that tracks the invariants at every step and hands every `every`-th state to a sink.
template <class Field, class ToPhysical>
class Monitor {
 public:
  static constexpr bool active = true;

  Monitor(const BodyPoint& p, const Field& f, const State& s0, const RunOptions& options, Grid grid,
          ToPhysical to_physical)
      : inv_(p, f, s0), grid_(grid), every_(options.every), sink_(options.sink),
        inside_(options.sink && options.inside_steps), cancel_{options.cancel},
        to_physical_(std::move(to_physical)) {
    hand(Sample{0, 0.0, s0, 0.0, 0.0, 0.0});
  }

  /// Fixed steps: step i ends at time i h and was h long.
  template <class X>
  void operator()(long i, const X& x) {
    stepped(i, static_cast<double>(i) * grid_.h, grid_.h, x, i == grid_.steps);
  }

  /// For methods with their own time grid: step i ends at time t; `last` marks the final state.
  template <class X>
  void observe(long i, double t, const X& x, bool last) {
    stepped(i, t, t - t_, x, last);
    t_ = t;
  }

  /// With grid.dt_out > 0: a state at a requested output time t (made by a side step).
  void emit(long i, double t, const State& s) {
    if (stop_) return;  // the run ended where the sink said stop: nothing after it is observed
    inv_.update(s);
    hand(Sample{i, t, s, inv_.last_rel_dE(), inv_.last_rel_dK2sq(), inv_.last_abs_dK2Q()});
  }
  /// A state inside step i at time t (RunOptions::inside_steps), handed before that step's end.
  [[nodiscard]] bool wants_inside() const { return inside_ && !stop_; }
  void inside(long i, double t, const State& s) {
    if (wants_inside()) hand(Sample{i, t, s, inv_.last_rel_dE(), inv_.last_rel_dK2sq(), inv_.last_abs_dK2Q(), true});
  }
  [[nodiscard]] bool wants_times() const { return sink_ && grid_.dt_out > 0.0; }
  /// After step i: false once the sink said Flow::stop (the loop then ends).
  bool poll(long i) const {
    cancel_.poll(i);
    return !stop_;
  }
  /// Where the sink said Flow::stop, if it did.
  [[nodiscard]] const std::optional<SinkStop>& stop() const { return stop_; }

  [[nodiscard]] const InvariantStats& stats() const { return inv_.stats(); }

 private:
  template <class X>
  void stepped(long i, double t, double dt, const X& x, bool last) {
    if (stop_) return;
    const State s = to_physical_(x);
    inv_.step(s, dt);
    if (sink_ && grid_.dt_out <= 0.0 && (i % every_ == 0 || last))
      hand(Sample{i, t, s, inv_.last_rel_dE(), inv_.last_rel_dK2sq(), inv_.last_abs_dK2Q()});
  }
  /// Hands x to the sink until it says Flow::stop; the states after that are not handed.
  void hand(const Sample& x) {
    if (sink_ && !stop_ && (*sink_)(x) == Flow::stop) stop_ = SinkStop{x.step, x.t, x.s};
  }

  InvariantMonitor<Field> inv_;
  double t_ = 0.0;  ///< observe(): where the last step ended
  Grid grid_;
  long every_;
  const SampleSink* sink_;
  bool inside_;
  CancelPoll cancel_;
  ToPhysical to_physical_;
  std::optional<SinkStop> stop_;
};

/// Accepted steps of a variable-step run: count, smallest and largest physical step.
struct StepStats {
  long steps = 0;
  double min_dt = std::numeric_limits<double>::infinity(), max_dt = 0.0;
  void add(double dt) {
    ++steps;
    min_dt = std::min(min_dt, dt);
    max_dt = std::max(max_dt, dt);
  }
  /// Fills r.steps, r.t_end (unless a sink stopped the run: observe set them), r.min_step and r.max_step.
  void record(RunResult& r, double t_end) const {
    if (!r.stopped) {
      r.steps = steps;
      r.t_end = t_end;
    }
    r.min_step = steps ? min_dt : 0.0;
    r.max_step = max_dt;
  }
};

/// How controlled_loop words the failures of a C library's stepper (GSL, SUNDIALS), each message prefixed with
/// the library's name: `Library::name` ("gsl", "cvode").
template <class Library>
struct LibrarySays {
  static std::string stalled(double t, double /*taken*/) {
    return std::string(Library::name) + ": the step size collapsed at t = " + std::to_string(t) +
           " (tolerance too tight?)";
  }
  static std::string too_many(double /*t*/, double /*t_end*/) {
    return std::string(Library::name) + ": more than 2e8 steps before t_end";
  }
  static std::string collapsed(double t) { return stalled(t, 0.0); }
};

/// The one driver of step-size-controlled runs (Boost.Odeint's controlled steppers, GSL's evolve, CVODE):
/// from t = 0 with first trial step h0 to exactly t_end. `try_step(x, t, dt)` attempts one step from
/// t and says whether it was accepted, leaving t and dt as its controller does (it lands on t_end
/// itself). The driver refuses accepted steps that do not move t (they would repeat forever), caps
/// the accepted steps and their rate (check_adaptive_rate), stops after 1000 rejections in a row, and
/// hands every accepted step to the observer. `Says` words the three failures for its stepper
/// (stalled(t, taken), too_many(t, t_end), collapsed(t)). Inlined into its caller, with the caller's
/// try_step inlined into it, as the two loops it replaces were written: out of line, odeint-dopri5 on
/// the material point took 252 ns per step against 190 (bench_steps, BM_Step).
template <class Says, class X, class TryStep, class Observer>
[[gnu::always_inline]] inline X controlled_loop(X x, double h0, double t_end, StepStats& st, Observer& obs,
                                                TryStep&& try_step) {
  double t = 0.0, dt = std::min(h0, t_end);
  long rejected_in_a_row = 0;
  while (t < t_end) {
    const double t_before = t;
    if (!try_step(x, t, dt)) {
      if (++rejected_in_a_row > 1000 || !(dt > 0.0)) throw Error(Says::collapsed(t));
      continue;
    }
    const double taken = t - t_before;
    if (!time_advances(t_before, t)) throw Error(Says::stalled(t, taken));
    if (st.steps >= kMaxAdaptiveSteps) throw Error(Says::too_many(t, t_end));
    st.add(taken);
    rejected_in_a_row = 0;
    check_adaptive_rate(st.steps, t, t_end);
    if constexpr (Observer::active) obs.observe(st.steps, t, x, t >= t_end);
    if (!splitting::poll(obs, st.steps)) break;
    if (!std::isfinite(x[0])) break;
  }
  return x;
}

/// Runs `loop(observer)` with a null observer or a monitor, timing the loop only. A sink that says
/// Flow::stop ends the loop: the run ends at the state it was handed.
template <class Field, class ToPhysical, class Loop>
RunResult observe(const BodyPoint& p, const Field& field, const State& s0, const RunOptions& options, Grid grid,
                  ToPhysical to_physical, Loop&& loop) {
  RunResult r;
  r.steps = grid.steps;
  r.t_end = static_cast<double>(grid.steps) * grid.h;
  if (options.track_invariants || options.sink) {
    Monitor<Field, ToPhysical> mon(p, field, s0, options, grid, to_physical);
    const auto t0 = Clock::now();
    if (!mon.stop()) r.final = loop(mon);
    if (const std::optional<SinkStop>& stop = mon.stop()) {
      r.final = stop->s;
      r.steps = stop->step;
      r.t_end = stop->t;
      r.stopped = true;
    }
    r.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
    r.invariants = mon.stats();
  } else {
    Unobserved none;
    none.cancel.cancel = options.cancel;
    const auto t0 = Clock::now();
    r.final = loop(none);
    r.wall_s = std::chrono::duration<double>(Clock::now() - t0).count();
  }
  return r;
}

/// Calls f(field, std::bool_constant<Spin>) with the field and spin decided once.
template <class F>
RunResult dispatch(const Body& body, const std::vector<Centre>& centres, F&& f) {
  return visit_field(centres, [&](const auto& field) {
    if (body.p.B == 0.0) return f(field, std::false_type{});
    return f(field, std::true_type{});
  });
}

}  // namespace bodypoint::detail

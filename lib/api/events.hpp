// bodypoint: locating events along a run (bodypoint.hpp, Event). Internal to the API layer.
//
// A run with events observes every step (or every dt_out) through an EventWatch: it keeps the last
// observed state and, for each event whose function g changes sign between two observed states,
// the bracketing pair. After the run, locate() solves g = 0 in each bracket on the method's own
// steps: `advance(s, tau)` integrates the state s at the bracket's start for a time tau with the
// run's configuration.
#pragma once

#include "bodypoint/bodypoint.hpp"
#include "bodypoint/field.hpp"

#include <functional>
#include <limits>
#include <vector>

namespace bodypoint::detail {

/// Throws Error for an event that does not fit the scene (a centre index out of range, a radius that
/// is not a finite number > 0, a plane normal that is zero or not finite, an offset not finite).
void validate_events(const std::vector<Event>& events, const std::vector<Centre>& centres);

/// The guiding centre G = R + K1 x K2/|K1|^2 of a state (B = 0: R).
Vec3 guiding_centre(const BodyPoint& p, const State& s);

/// The events with their values fixed by the run's start (a departure through the start's distance).
std::vector<Event> resolved(std::vector<Event> events, const BodyPoint& p, const std::vector<Centre>& centres,
                            const State& start);

/// Of the hits of each closest_approach event only the nearest is kept (the run's closest approach).
void keep_closest(std::vector<EventHit>& hits, const std::vector<Event>& events);

/// The function whose sign change is the event.
double event_function(const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, const State& s);
/// Its rate along the motion, dg/dt at s: |v|^2 + (R - c).dv/dt for an approach, (R - c).v/|R - c| for a radius,
/// n.v for a plane; NaN for a departure or an arrival (the guiding centre's, not needed).
double event_rate(const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, const State& s);

class EventWatch {
 public:
  struct Bracket {
    std::size_t event;
    double t_a, t_b, g_a, g_b;
    State s_a, s_b;
    /// A long span (kHiddenSpin) whose g may cross zero more often than its ends show: locate() halves it.
    bool open = false;
  };
  EventWatch(const std::vector<Event>& events, const BodyPoint& p, const std::vector<Centre>& centres)
      : events_(events), p_(p), centres_(centres), field_{centres}, g_(events.size()),
        nearest_(centres.size(), std::numeric_limits<double>::infinity()) {}
  void observe(double t, const State& s);
  [[nodiscard]] const std::vector<Bracket>& brackets() const { return brackets_; }
  /// Spans between two observed states where g kept its sign but may have changed it twice in between:
  /// a step that turns the spin or the direction to a centre by much (may_hide_roots), over which g's rate
  /// could have taken it to zero and back. locate() samples them inside.
  [[nodiscard]] const std::vector<Bracket>& hidden() const { return hidden_; }
  /// The least distance to centre c observed so far (a closest approach below it is worth looking for).
  [[nodiscard]] double nearest(std::size_t c) const { return nearest_[c]; }

 private:
  const std::vector<Event>& events_;
  const BodyPoint& p_;
  const std::vector<Centre>& centres_;
  CentreList field_;  ///< the force that bounds an approach's rate (may_hide_roots)
  std::vector<double> g_;
  std::vector<double> nearest_;
  bool started_ = false;
  double t_ = 0.0;
  State s_;
  std::vector<Bracket> brackets_, hidden_;
};

/// A step longer than this share of a turn of the spin (radians), or one that turns the direction to a
/// centre by more than kHiddenTurn, can hold two sign changes of an event's function that the step's ends
/// do not show (a helix wiggle: the steps of far-ip between its inner points, logh-bs's extrapolated macro
/// steps). Shorter steps sample a turn at four points or more: a sign change and its return lie in
/// different steps.
inline constexpr double kHiddenSpin = 3.14159265358979323846 / 2.0;
inline constexpr double kHiddenTurn = 3.14159265358979323846 / 4.0;
/// The bound on |dg/dt| over such a step is this many times the larger of its values at the two ends
/// (the helix keeps the size of the gyroscopic acceleration; the Coulomb part changes with r).
inline constexpr double kRateMargin = 2.0;
/// A hidden span is halved at most this many times (2^6 pieces) before it is taken to hold no root.
inline constexpr int kMaxHalvings = 6;

/// Integrates a state for a time tau > 0 with the run's method and configuration; adds the force
/// evaluations it made to `evals`.
using Advancer = std::function<State(const State& s, double tau, long& evals)>;

/// The events of the brackets, located, in time order.
std::vector<EventHit> locate(const EventWatch& watch, const std::vector<Event>& events, const BodyPoint& p,
                             const std::vector<Centre>& centres, const Advancer& advance, long& evals);

}  // namespace bodypoint::detail

// bodypoint: locating events along a run (bodypoint.hpp, Event). Internal to the API layer.
//
// A run with events observes every step (or every dt_out) through an EventWatch: it keeps the last
// observed state and, for each event whose function g changes sign between two observed states,
// the bracketing pair. After the run, locate() solves g = 0 in each bracket on the method's own
// steps: `advance(s, tau)` integrates the state s at the bracket's start for a time tau with the
// run's configuration.
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <functional>
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

class EventWatch {
 public:
  struct Bracket {
    std::size_t event;
    double t_a, t_b, g_a, g_b;
    State s_a, s_b;
  };
  EventWatch(const std::vector<Event>& events, const BodyPoint& p, const std::vector<Centre>& centres)
      : events_(events), p_(p), centres_(centres), g_(events.size()) {}
  void observe(double t, const State& s);
  [[nodiscard]] const std::vector<Bracket>& brackets() const { return brackets_; }

 private:
  const std::vector<Event>& events_;
  const BodyPoint& p_;
  const std::vector<Centre>& centres_;
  std::vector<double> g_;
  bool started_ = false;
  double t_ = 0.0;
  State s_;
  std::vector<Bracket> brackets_;
};

/// Integrates a state for a time tau > 0 with the run's method and configuration; adds the force
/// evaluations it made to `evals`.
using Advancer = std::function<State(const State& s, double tau, long& evals)>;

/// The events of the brackets, located, in time order.
std::vector<EventHit> locate(const EventWatch& watch, const std::vector<Event>& events, const BodyPoint& p,
                             const std::vector<Centre>& centres, const Advancer& advance, long& evals);

}  // namespace bodypoint::detail

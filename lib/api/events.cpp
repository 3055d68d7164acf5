// bodypoint: locating events along a run (events.hpp).
#include "events.hpp"

#include "bodypoint/io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace bodypoint {

std::string Event::label() const {
  std::ostringstream os;
  const auto at_centre = [&] {
    if (centre) os << "(" << centre << ")";
  };
  switch (kind) {
    case Kind::closest_approach: os << "closest"; at_centre(); break;
    case Kind::local_minimum: os << "local-min"; at_centre(); break;
    case Kind::radius: os << "r"; at_centre(); os << "=" << fmt(value); break;
    case Kind::departure:
    case Kind::arrival:
      os << (kind == Kind::departure ? "departure" : "arrival");
      at_centre();
      if (value != 0.0) os << "=" << fmt(value);
      break;
    case Kind::plane:
      if (normal == Vec3::UnitX()) os << "x";
      else if (normal == Vec3::UnitY()) os << "y";
      else if (normal == Vec3::UnitZ()) os << "z";
      else os << "plane(" << fmt(normal.x()) << "," << fmt(normal.y()) << "," << fmt(normal.z()) << ")";
      os << "=" << fmt(value);
      break;
  }
  return os.str();
}

namespace {

/// The grammar's forms, for the message that refuses a text.
/// Every form an event takes (K: a centre's index), listed by the message for an unknown one.
std::vector<std::string> event_forms() {
  return {"closest", "closest:K", "local-min", "local-min:K", "r=RADIUS", "r:K=RADIUS", "x=X", "y=Y", "z=Z",
          "plane=nx,ny,nz,offset", "departure", "departure=R", "arrival=R"};
}

double event_number(std::string_view text, const std::string& value) {
  const std::optional<double> x = read_double(value);
  if (!x || !std::isfinite(*x)) throw Error("event '" + std::string(text) + "': '" + value + "' is not a finite number");
  return *x;
}

std::size_t event_centre(std::string_view text, const std::string& index) {
  if (index.empty() || index.find_first_not_of("0123456789") != std::string::npos || index.size() > 6)
    throw Error("event '" + std::string(text) + "': the centre must be an index 0, 1, ...");
  return static_cast<std::size_t>(std::stoul(index));
}

Event parse_plane(std::string_view text, const std::string& value) {
  double n[4];
  std::size_t from = 0;
  for (int i = 0; i < 4; ++i) {
    const std::size_t comma = i < 3 ? value.find(',', from) : value.size();
    if (comma == std::string::npos) throw Error("event '" + std::string(text) + "': give plane=nx,ny,nz,offset");
    n[i] = event_number(text, value.substr(from, comma - from));
    from = comma + 1;
  }
  Event e{Event::Kind::plane, 0, n[3], Vec3(n[0], n[1], n[2])};
  if (e.normal == Vec3::Zero()) throw Error("event '" + std::string(text) + "': the plane's normal must not be zero");
  // A normal whose length underflows (plane=1e-320,0,0,0) is a plane all the same: n.R = offset scaled
  // by its largest component.
  if (const double s = e.normal.cwiseAbs().maxCoeff(); !(e.normal.norm() > 0.0)) {
    e.normal /= s;
    e.value /= s;
    if (!std::isfinite(e.value))
      throw Error("event '" + std::string(text) + "': the plane's offset over its normal's length overflows; scale them alike");
  }
  if (!std::isfinite(e.normal.norm()))
    throw Error("event '" + std::string(text) + "': the plane's normal is too long (its length overflows); scale it down");
  return e;
}

}  // namespace

Event parse_event(std::string_view text_view) {
  const std::string text(text_view);
  const std::size_t eq = text.find('=');
  const bool valued = eq != std::string::npos;
  const std::string key = text.substr(0, eq), value = valued ? text.substr(eq + 1) : "";
  const std::string name = key.substr(0, key.find(':'));
  const bool indexed = key.find(':') != std::string::npos;
  const std::size_t centre = event_centre(text_view, indexed ? key.substr(key.find(':') + 1) : "0");
  if ((name == "closest" || name == "local-min") && !valued)
    return Event{name == "closest" ? Event::Kind::closest_approach : Event::Kind::local_minimum, centre};
  if (name == "departure" && !valued) return Event{Event::Kind::departure, centre};
  if ((name == "r" || name == "departure" || name == "arrival") && valued) {
    const Event::Kind kind = name == "r" ? Event::Kind::radius : name == "departure" ? Event::Kind::departure : Event::Kind::arrival;
    Event e{kind, centre, event_number(text_view, value)};
    if (!(e.value > 0.0)) throw Error("event '" + text + "': the distance must be > 0");
    return e;
  }
  if (!indexed && valued && (key == "x" || key == "y" || key == "z"))
    return Event{Event::Kind::plane, 0, event_number(text_view, value),
                 key == "x" ? Vec3::UnitX() : key == "y" ? Vec3::UnitY() : Vec3::UnitZ()};
  if (!indexed && valued && key == "plane") return parse_plane(text_view, value);
  throw Error(unknown_name("event", text, event_forms()) + " (K: a centre's index)");
}

std::vector<Event> closest_approaches(std::size_t centres) {
  std::vector<Event> out;
  for (std::size_t c = 0; c < centres; ++c) out.push_back(Event{Event::Kind::closest_approach, c, 0.0, Vec3::UnitX(), false});
  return out;
}

const EventHit* nearest_approach(const std::vector<EventHit>& hits, const std::vector<Event>& events) {
  const EventHit* nearest = nullptr;
  for (const EventHit& h : hits)
    if ((events[h.event].kind == Event::Kind::closest_approach || events[h.event].kind == Event::Kind::local_minimum) &&
        (!nearest || h.r < nearest->r || (std::isnan(nearest->r) && !std::isnan(h.r))))
      nearest = &h;
  return nearest;
}

namespace detail {

/// The root finder stops when the bracket is this many ulps of the time wide: t is then known to
/// round-off (a few ulps, the accuracy of the state's own time).
constexpr double kBracketUlps = 4.0;
/// Illinois regula falsi converges superlinearly; bisection every third step guarantees that the
/// bracket halves at least that often, so a 2^-52 bracket needs at most ~160 evaluations.
constexpr int kMaxIterations = 200;

void validate_events(const std::vector<Event>& events, const std::vector<Centre>& centres) {
  using K = Event::Kind;
  for (const Event& e : events) {
    if (e.kind != K::plane && e.centre >= centres.size())
      throw Error("event " + e.label() + ": the scene has " + std::to_string(centres.size()) + " centre(s)");
    if ((e.kind == K::radius || e.kind == K::arrival) && !(std::isfinite(e.value) && e.value > 0.0))
      throw Error("event " + e.label() + ": the distance must be a finite number > 0");
    if (e.kind == K::departure && !(std::isfinite(e.value) && e.value >= 0.0))
      throw Error("event " + e.label() + ": the distance must be a finite number > 0 (0: the start's)");
    if (e.kind == K::plane &&
        !(std::isfinite(e.value) && e.normal.allFinite() && e.normal.norm() > 0.0 && std::isfinite(e.normal.norm())))
      throw Error("event " + e.label() + ": a plane needs a finite non-zero normal and a finite offset");
  }
}

Vec3 guiding_centre(const BodyPoint& p, const State& s) {
  if (p.B == 0.0) return s.R;
  const Momenta q = to_momenta(p, s);
  const double K1sq = q.K1.squaredNorm();
  return K1sq > 0.0 ? Vec3(s.R + q.K1.cross(q.K2) / K1sq) : s.R;
}

namespace {
/// The point a departure or arrival measures the guiding centre's distance from: Event::about, or its centre.
Vec3 origin(const Event& e, const std::vector<Centre>& centres) { return e.about ? *e.about : centres[e.centre].c; }
}  // namespace

std::vector<Event> resolved(std::vector<Event> events, const BodyPoint& p, const std::vector<Centre>& centres,
                            const State& start) {
  for (Event& e : events)
    if (e.kind == Event::Kind::departure && e.value == 0.0)
      e.value = (guiding_centre(p, start) - origin(e, centres)).norm();
  return events;
}

void keep_closest(std::vector<EventHit>& hits, const std::vector<Event>& events) {
  std::vector<const EventHit*> nearest(events.size(), nullptr);
  for (const EventHit& h : hits)
    if (events[h.event].kind == Event::Kind::closest_approach &&
        (!nearest[h.event] || h.r < nearest[h.event]->r))
      nearest[h.event] = &h;
  std::vector<EventHit> kept;
  for (const EventHit& h : hits)
    if (events[h.event].kind != Event::Kind::closest_approach || nearest[h.event] == &h) kept.push_back(h);
  hits = std::move(kept);
}

double event_function(const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, const State& s) {
  switch (e.kind) {
    case Event::Kind::closest_approach:
    case Event::Kind::local_minimum: return (s.R - centres[e.centre].c).dot(s.v);
    case Event::Kind::radius: return (s.R - centres[e.centre].c).norm() - e.value;
    case Event::Kind::departure:
    case Event::Kind::arrival: return (guiding_centre(p, s) - origin(e, centres)).norm() - e.value;
    case Event::Kind::plane: return e.normal.dot(s.R) - e.value;
  }
  return 0.0;
}

namespace {

bool crosses(const Event& e, double g_a, double g_b) {
  using K = Event::Kind;
  if (e.kind == K::closest_approach || e.kind == K::local_minimum || e.kind == K::departure) return g_a < 0.0 && g_b >= 0.0;
  if (e.kind == K::arrival) return g_a > 0.0 && g_b <= 0.0;
  return (g_a < 0.0 && g_b >= 0.0) || (g_a > 0.0 && g_b <= 0.0);
}

double distance_for(const Event& e, const std::vector<Centre>& centres, const State& s) {
  const std::size_t c = e.kind == Event::Kind::plane ? 0 : e.centre;
  if (e.about) return (s.R - *e.about).norm();
  return centres.empty() ? s.R.norm() : (s.R - centres[c].c).norm();
}

}  // namespace

namespace {

/// A run that starts on an event (g = 0 to round-off, e.g. a Stepper continuing from a stop) does
/// not report it again: a first g within kStartUlps of its own scale counts as zero, which no sign
/// change starts from.
constexpr double kStartUlps = 64.0;

double event_scale(const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, const State& s) {
  switch (e.kind) {
    case Event::Kind::closest_approach:
    case Event::Kind::local_minimum: return (s.R - centres[e.centre].c).norm() * s.v.norm();
    case Event::Kind::departure:
    case Event::Kind::arrival: return std::max((guiding_centre(p, s) - centres[e.centre].c).norm(), e.value);
    case Event::Kind::radius: return std::max((s.R - centres[e.centre].c).norm(), e.value);
    case Event::Kind::plane: return e.normal.norm() * s.R.norm() + std::abs(e.value);
  }
  return 0.0;
}

/// The body's acceleration dv/dt at s (docs/physics.md, equations of motion: D dv/dt = J F - B^2 (w x v)).
Vec3 acceleration(const BodyPoint& p, const CentreList& field, const State& s) {
  return (p.J * field.force(s.R) - p.B * p.B * s.w.cross(s.v)) / p.D();
}

/// An upper bound on |dg/dt| at state s (before kRateMargin): d/dt (R - c).v = |v|^2 + (R - c).a for an
/// approach, |v| for a radius, |n||v| for a plane; the guiding centre of an arrival or departure moves
/// smoothly (0: it hides no root).
double rate_bound(const Event& e, const BodyPoint& p, const CentreList& field, const State& s) {
  switch (e.kind) {
    case Event::Kind::closest_approach:
    case Event::Kind::local_minimum:
      return s.v.squaredNorm() + (s.R - field.centres[e.centre].c).norm() * acceleration(p, field, s).norm();
    case Event::Kind::radius: return s.v.norm();
    case Event::Kind::plane: return e.normal.norm() * s.v.norm();
    case Event::Kind::departure:
    case Event::Kind::arrival: return 0.0;
  }
  return 0.0;
}

}  // namespace

double event_rate(const Event& e, const BodyPoint& p, const std::vector<Centre>& centres, const State& s) {
  switch (e.kind) {
    case Event::Kind::closest_approach:
    case Event::Kind::local_minimum: {
      const Vec3 d = s.R - centres[e.centre].c;
      return s.v.squaredNorm() + d.dot(acceleration(p, CentreList{centres}, s));
    }
    case Event::Kind::radius: {
      const Vec3 d = s.R - centres[e.centre].c;
      return d.dot(s.v) / d.norm();
    }
    case Event::Kind::plane: return e.normal.dot(s.v);
    case Event::Kind::departure:
    case Event::Kind::arrival: break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

namespace {

/// Whether the span from a to b (dt long) is one that can hide two sign changes (kHiddenSpin, kHiddenTurn).
bool long_span(const BodyPoint& p, const std::vector<Centre>& centres, const State& a, const State& b, double dt) {
  const double spin = std::abs(p.B) / p.D() * std::max(to_momenta(p, a).K1.norm(), to_momenta(p, b).K1.norm()) * dt;
  if (spin > kHiddenSpin) return true;
  for (const Centre& k : centres) {
    const Vec3 da = a.R - k.c, db = b.R - k.c;
    if (std::atan2(da.cross(db).norm(), da.dot(db)) > kHiddenTurn) return true;
  }
  return false;
}

/// Whether g can have crossed zero between the states a and b (g_a, g_b, dt apart) more often than its ends
/// show (twice more, or at all where they have one sign): a long span (long_span) over which, at the rate
/// bound, g can travel |g_a| + |g_b| and more.
bool may_hide_roots(const Event& e, const BodyPoint& p, const CentreList& field, const State& a, const State& b,
                    double g_a, double g_b, double dt) {
  if (!long_span(p, field.centres, a, b, dt)) return false;
  const double rate = std::max(rate_bound(e, p, field, a), rate_bound(e, p, field, b));
  return std::abs(g_a) + std::abs(g_b) < kRateMargin * rate * dt;
}

}  // namespace

void EventWatch::observe(double t, const State& s) {
  for (std::size_t k = 0; k < events_.size(); ++k) {
    const Event& e = events_[k];
    double g = event_function(e, p_, centres_, s);
    if (!started_ && std::abs(g) <= kStartUlps * std::numeric_limits<double>::epsilon() * event_scale(e, p_, centres_, s))
      g = 0.0;
    const bool stepped = started_ && t > t_;
    const bool crossed = stepped && crosses(e, g_[k], g);
    const bool open = stepped && may_hide_roots(e, p_, field_, s_, s, g_[k], g, t - t_);
    if (crossed) brackets_.push_back({k, t_, t, g_[k], g, s_, s, open});
    else if (open) hidden_.push_back({k, t_, t, g_[k], g, s_, s, true});
    g_[k] = g;
  }
  for (std::size_t c = 0; c < centres_.size(); ++c) nearest_[c] = std::min(nearest_[c], (s.R - centres_[c].c).norm());
  started_ = true;
  t_ = t;
  s_ = s;
}

namespace {

/// The sign changes inside a hidden span, as brackets: the span is halved on the run's own configuration
/// until a half shows a change, or its halves hide none (may_hide_roots), or kMaxHalvings. An approach
/// whose span cannot come nearer the centre than the run already was (its ends less the distance its speed
/// covers) is the run's closest approach no more and is not looked into.
void open_hidden(const EventWatch::Bracket& span, int depth, const EventWatch& watch, const std::vector<Event>& events,
                 const BodyPoint& p, const CentreList& field, const Advancer& advance, long& evals,
                 std::vector<EventWatch::Bracket>& out) {
  const std::vector<Centre>& centres = field.centres;
  const Event& e = events[span.event];
  const double dt = span.t_b - span.t_a;
  if (e.kind == Event::Kind::closest_approach) {
    const double ra = (span.s_a.R - centres[e.centre].c).norm(), rb = (span.s_b.R - centres[e.centre].c).norm();
    const double vmax = kRateMargin * std::max(span.s_a.v.norm(), span.s_b.v.norm());
    if (0.5 * (ra + rb - vmax * dt) >= watch.nearest(e.centre)) {
      if (crosses(e, span.g_a, span.g_b)) out.push_back(span);  // a minimum, not the least
      return;
    }
  }
  const State mid = advance(span.s_a, 0.5 * dt, evals);
  const double t_mid = span.t_a + 0.5 * dt, g_mid = event_function(e, p, centres, mid);
  const EventWatch::Bracket halves[2] = {{span.event, span.t_a, t_mid, span.g_a, g_mid, span.s_a, mid},
                                         {span.event, t_mid, span.t_b, g_mid, span.g_b, mid, span.s_b}};
  for (const EventWatch::Bracket& h : halves) {
    const bool open = depth + 1 < kMaxHalvings && may_hide_roots(e, p, field, h.s_a, h.s_b, h.g_a, h.g_b, h.t_b - h.t_a);
    if (open) open_hidden(h, depth + 1, watch, events, p, field, advance, evals, out);
    else if (crosses(e, h.g_a, h.g_b)) out.push_back(h);
  }
}

}  // namespace

std::vector<EventHit> locate(const EventWatch& watch, const std::vector<Event>& events, const BodyPoint& p,
                             const std::vector<Centre>& centres, const Advancer& advance, long& evals) {
  std::vector<EventHit> hits;
  std::vector<EventWatch::Bracket> brackets;
  const CentreList field{centres};
  for (const EventWatch::Bracket& b : watch.brackets()) {
    if (b.open) open_hidden(b, 0, watch, events, p, field, advance, evals, brackets);
    else brackets.push_back(b);
  }
  for (const EventWatch::Bracket& span : watch.hidden())
    open_hidden(span, 0, watch, events, p, field, advance, evals, brackets);
  for (const EventWatch::Bracket& b : brackets) {
    const Event& e = events[b.event];
    // g(tau) on [lo, hi] within [0, t_b - t_a]; g(lo) < 0 <= g(hi) after orienting the sign.
    const double sign = b.g_a < 0.0 ? 1.0 : -1.0;
    double lo = 0.0, hi = b.t_b - b.t_a, g_lo = sign * b.g_a, g_hi = sign * b.g_b;
    // The state reported is the one evaluated closest to the root (an end of the bracket if the
    // root is there).
    const bool b_closer = std::abs(b.g_b) < std::abs(b.g_a);
    State best = b_closer ? b.s_b : b.s_a;
    double best_tau = b_closer ? hi : 0.0, best_g = std::min(std::abs(b.g_a), std::abs(b.g_b));
    int side = 0;  // Illinois: which end was kept last time
    const double width_min = kBracketUlps * std::numeric_limits<double>::epsilon() * std::max(std::abs(b.t_b), 1e-300);
    for (int it = 0; it < kMaxIterations && hi - lo > width_min && g_hi != 0.0; ++it) {
      double tau = (it % 3 == 2) ? 0.5 * (lo + hi) : lo - g_lo * (hi - lo) / (g_hi - g_lo);
      if (!(tau > lo && tau < hi)) tau = 0.5 * (lo + hi);
      const State s = tau > 0.0 ? advance(b.s_a, tau, evals) : b.s_a;
      const double g = sign * event_function(e, p, centres, s);
      if (std::abs(g) <= best_g) {
        best = s;
        best_tau = tau;
        best_g = std::abs(g);
      }
      if (g < 0.0) {
        lo = tau;
        g_lo = g;
        if (side == -1) g_hi *= 0.5;
        side = -1;
      } else {
        hi = tau;
        g_hi = g;
        if (side == 1) g_lo *= 0.5;
        side = 1;
      }
    }
    EventHit h;
    h.event = b.event;
    h.t = b.t_a + best_tau;
    h.s = best;
    h.r = distance_for(e, centres, best);
    hits.push_back(h);
  }
  std::stable_sort(hits.begin(), hits.end(), [](const EventHit& x, const EventHit& y) { return x.t < y.t; });
  return hits;
}

}  // namespace detail
}  // namespace bodypoint

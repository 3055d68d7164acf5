// bodypoint: integrate() and Stepper, the public API's runs (bodypoint.hpp).
#include "bodypoint/bodypoint.hpp"

#include "bodypoint/adaptive/methods.hpp"
#include "bodypoint/adaptive/tolerance.hpp"

#include <cmath>
#include <limits>
#include <type_traits>
#include <utility>

namespace bodypoint {

std::string_view outcome_name(Outcome o) {
  switch (o) {
    case Outcome::ok: return "ok";
    case Outcome::diverged: return "diverged";
    case Outcome::collision: return "collision";
    case Outcome::refused: return "refused";
    case Outcome::failed: return "failed";
  }
  return "?";
}

long BodyResult::total_force_evals() const {
  return accuracy ? accuracy->force_evals : run.force_evals;
}

RunSpec run_spec(const MethodInfo& method, const Advance& how, const Options& options) {
  RunSpec s;
  s.track_invariants = options.track_invariants;
  s.every = options.every;
  s.omega_c = options.omega_c;
  std::visit(
      [&](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, FixedSteps>) {
          if (is_step_controlled(method) || is_time_transformed(method))
            throw Error(method.name + " does not take fixed steps (" +
                        (is_time_transformed(method) ? "it takes FictitiousSteps)" : "it takes ControlledSteps)"));
          s.h = a.h;
          s.steps = a.steps;
        } else if constexpr (std::is_same_v<A, FictitiousSteps>) {
          if (!is_time_transformed(method)) throw Error(method.name + " does not take fictitious steps");
          s.h = a.ds;
          s.t_end = a.t_end;
          s.steps = a.t_end > 0.0 ? 0 : a.steps;
          s.dt_out = a.dt_out;
        } else if constexpr (std::is_same_v<A, ControlledSteps>) {
          if (!is_step_controlled(method))
            throw Error(method.name + " does not control its step (give it FixedSteps, FictitiousSteps or Accuracy)");
          s.h = a.h0;
          s.t_end = a.t_end;
          s.tol = a.tol;
          s.steps = 1;
        } else {
          throw Error("the accuracy mode chooses its own step: it has no run specification");
        }
      },
      how);
  (void)advance_of(method, s);  // every number checked, in one place (run.cpp)
  return s;
}

namespace {

/// The outcome of a finished run, from its health (run.hpp, assess).
void judge(BodyResult& r) {
  const Health h = assess(r.run);
  if (h.status == "ok") return;
  r.outcome = h.status == "collision" ? Outcome::collision : Outcome::diverged;
  r.reason = h.why;
}

/// The accuracy mode: the step search, whose delivered run carries the observers.
void run_accurately(BodyResult& r, const Body& body, const std::vector<Centre>& centres, const Accuracy& a,
                    const Options& options) {
  adaptive::Delivery delivery;
  delivery.track_invariants = options.track_invariants;
  delivery.every = options.every;
  delivery.dt_out = a.dt_out;
  delivery.sink = options.sink;
  adaptive::ToleranceResult t = adaptive::run_to_tolerance(*r.method, body, centres, a.tol, a.t_end, delivery);
  r.accuracy = AccuracyReport{a.tol, t.err_estimate, t.h, t.omega_c, t.runs, t.total_force_evals, t.total_wall_s};
  r.run = std::move(t.result);
}

/// integrate_body for a body and centres already validated.
BodyResult integrate_valid_body(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                                const Advance& how, const Options& options) {
  BodyResult r;
  const auto* accuracy = std::get_if<Accuracy>(&how);
  if (accuracy) {
    adaptive::check_tolerance(accuracy->tol);
    if (!(std::isfinite(accuracy->t_end) && accuracy->t_end > 0.0))
      throw Error("the accuracy mode needs an end time t_end that is a finite number > 0");
    if (options.every < 1) throw Error("every must be >= 1");
    if (non_coulomb(centres)) {
      r.method = method;
      r.outcome = Outcome::refused;
      r.reason = adaptive::kNeedsCoulomb;
      return r;
    }
    r.method = method ? method : &choose_method(body, centres, accuracy->tol, &r.chosen);
  } else {
    if (!method) throw Error("only the accuracy mode chooses a method by itself; name one");
    r.method = method;
  }
  if (std::string why = refusal(*r.method, body, centres); !why.empty()) {
    r.outcome = Outcome::refused;
    r.reason = std::move(why);
    return r;
  }
  const RunSpec spec = accuracy ? RunSpec{} : run_spec(*r.method, how, options);
  try {
    if (accuracy) run_accurately(r, body, centres, *accuracy, options);
    else r.run = r.method->run(body, centres, spec, options.sink);
  } catch (const Error& e) {
    r.outcome = Outcome::failed;
    r.reason = e.what();
    return r;
  }
  judge(r);
  return r;
}

}  // namespace

BodyResult integrate_body(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method,
                          const Advance& how, const Options& options) {
  validate(Scene{centres, {body}});
  return integrate_valid_body(body, centres, method, how, options);
}

Result integrate(const Scene& scene, const MethodInfo* method, const Advance& how, const Options& options) {
  validate(scene);
  Result all;
  for (const Body& body : scene.bodies) {
    BodyResult b = integrate_valid_body(body, scene.centres, method, how, options);
    all.force_evals += b.total_force_evals();
    all.wall_s += (b.accuracy ? b.accuracy->wall_s : b.run.wall_s);
    if (all.outcome == Outcome::ok && b.outcome != Outcome::ok) {
      all.outcome = b.outcome;
      all.reason = (body.name.empty() ? std::string("body") : body.name) + ": " + b.reason;
    }
    all.bodies.push_back(std::move(b));
  }
  return all;
}

Result integrate(const Scene& scene, std::string_view method, const Advance& how, const Options& options) {
  const bool automatic = method == "auto";
  if (automatic && !std::holds_alternative<Accuracy>(how))
    throw Error("method auto needs the accuracy mode (Accuracy: the tolerance to deliver)");
  return integrate(scene, automatic ? nullptr : &method_or_throw(method), how, options);
}

// --- Stepper ---

Stepper::Stepper(const MethodInfo& method, Body body, std::vector<Centre> centres, double step, Options options)
    : method_(&method), body_(std::move(body)), centres_(std::move(centres)), step_(step), options_(options) {
  validate(Scene{centres_, {body_}});
  if (!(std::isfinite(step_) && step_ > 0.0)) throw Error("the step must be a finite number > 0");
  // The time-step constant of a time-transformed method is fixed once, from the starting state, so
  // that every segment integrates the same transformed system.
  if (is_time_transformed(method) && options_.omega_c < 0.0)
    options_.omega_c = adaptive::automatic_omega_c(body_, centres_, step_);
}

Stepper::Stepper(std::string_view method, Body body, std::vector<Centre> centres, double step, Options options)
    : Stepper(method_or_throw(method), std::move(body), std::move(centres), step, options) {}

Outcome Stepper::advance_to(double t) {
  if (!(std::isfinite(t) && t > t_))
    throw Error("advance_to needs a finite time after the current one (" + std::to_string(t_) + ")");
  const double span = t - t_;
  Advance how;
  if (is_time_transformed(*method_)) how = FictitiousSteps{step_, span, 0, 0.0};
  else if (is_step_controlled(*method_)) how = ControlledSteps{std::min(1e-3, span), span, step_};
  else how = fixed_steps_to(span, step_);
  // Samples carry absolute times (the segment's run starts at 0); a later segment's first sample is
  // the state the previous one ended with, already handed on.
  const double t0 = t_;
  const bool first = steps_ == 0;
  SampleSink shifted;
  Options opt = options_;
  if (options_.sink) {
    shifted = [this, t0, first](const Sample& s) {
      if (s.step == 0 && !first) return;
      (*options_.sink)(Sample{s.step, t0 + s.t, s.s, s.rel_dE, s.rel_dK2sq, s.abs_dK2Q});
    };
    opt.sink = &shifted;
  }
  const BodyResult r = integrate_body(body_, centres_, method_, how, opt);
  if (r.outcome == Outcome::refused || r.outcome == Outcome::failed) {
    reason_ = r.reason;
    return r.outcome;
  }
  body_.s0 = r.run.final;
  t_ = t;
  force_evals_ += r.run.force_evals;
  steps_ += r.run.steps;
  if (r.outcome != Outcome::ok) reason_ = r.reason;
  return r.outcome;
}

}  // namespace bodypoint

// bodypoint's Python module (`import bodypoint`): the public API (bodypoint.hpp, sweep.hpp) with numpy
// arrays. Results are plain dicts of numbers and arrays (a sweep's is a dict of equal-length 1-D
// columns, which pandas.DataFrame takes as it is); errors are bodypoint.Error (a ValueError) with the
// library's one-line reason; the GIL is released while integrating. The Python-side docs and the
// keyword interface are in bodypoint/__init__.py; this file holds only the conversions.
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/record.hpp"
#include "bodypoint/sweep.hpp"
#include "bodypoint/threads.hpp"
#include "checked.hpp"
#include "encounter_parts.hpp"
#include "bodypoint/detail/run_parts.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <functional>
#include <condition_variable>
#include <csignal>
#include <mutex>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace py = pybind11;
using namespace bodypoint;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

py::array_t<double> vec(const Vec3& x) {
  py::array_t<double> a(3);
  auto m = a.mutable_unchecked<1>();
  for (py::ssize_t i = 0; i < 3; ++i) m(i) = x[static_cast<Eigen::Index>(i)];
  return a;
}

/// A keyword's number: an int, a float or a numpy number, never a bool or a text (Error naming it).
double number_of(const py::handle& v, const std::string& name) {
  if (PyBool_Check(v.ptr()) || !PyNumber_Check(v.ptr()) || PyUnicode_Check(v.ptr()) || PyBytes_Check(v.ptr()))
    throw Error(name + " must be a number, got " + std::string(py::str(py::type::of(v).attr("__name__"))));
  try {
    return py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>();
  } catch (const py::error_already_set&) {  // an int beyond a double's range
    throw Error(name + " must be a finite number, got " + std::string(py::str(v)).substr(0, 40));
  }
}

/// Three numbers (a list, tuple or array) as a vector; Error naming it otherwise.
Vec3 vec3_of(const py::handle& v, const std::string& name) {
  if (PyUnicode_Check(v.ptr()) || PyBytes_Check(v.ptr()) || !PySequence_Check(v.ptr()) || py::len(v) != 3)
    throw Error(name + " must be a sequence of 3 numbers");
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(v);
  return Vec3(number_of(seq[0], name), number_of(seq[1], name), number_of(seq[2], name));
}

/// A keyword's text (Error naming it otherwise).
std::string text_of(const py::handle& v, const std::string& name) {
  if (!PyUnicode_Check(v.ptr())) throw Error(name + " must be a text, got " + std::string(py::str(py::type::of(v).attr("__name__"))));
  return v.cast<std::string>();
}

py::dict centre_dict(const Centre& c) {
  py::dict d;
  d["position"] = vec(c.c);
  d["A"] = c.A;
  d["law"] = force_law_name(c.law);
  return d;
}

py::dict body_dict(const Body& b) {
  py::dict d;
  d["name"] = b.name;
  d["m"] = b.p.m;
  d["B"] = b.p.B;
  d["J"] = b.p.J;
  d["R"] = vec(b.s0.R);
  d["v"] = vec(b.s0.v);
  d["w"] = vec(b.s0.w);
  return d;
}

/// A scene from the Python module's lists of dicts: written as a scene file's text (bodypoint/__init__.py,
/// _scene_toml) and read by the library's one reader (scene_file.hpp), so the keys, their checks and
/// the messages are the scene files'.
Scene scene_from(const py::object& centres, const py::object& bodies) {
  const auto text = py::module_::import("bodypoint").attr("_scene_toml")(centres, bodies).cast<std::string>();
  return parse_scene(text, "bodypoint.Scene");
}

/// The names thesis_scene() takes: the scene parameters, the asymptotic data and the force law.
std::vector<std::string> thesis_keywords() {
  std::vector<std::string> names;
  for (const SceneParameter& p : scene_parameters()) names.emplace_back(p.name);
  for (const char* extra : {"b", "v_inf", "arrival_phase", "force_law"}) names.emplace_back(extra);
  return names;
}

/// The thesis's parameters from thesis_scene()'s keywords (model.hpp scene_parameters(); b, v_inf and
/// arrival_phase: asymptotic data), the asymptotic data given among them solved in.
struct ThesisParams {
  SceneParams solved;
  AsymptoticData data;
};

ThesisParams thesis_params_from(const py::dict& kw) {
  SceneParams sp;
  AsymptoticData data;
  std::vector<std::string> given;
  const std::vector<std::string> valid = thesis_keywords();
  for (const auto& [k, v] : kw) {
    const auto key = k.cast<std::string>();
    if (std::find(valid.begin(), valid.end(), key) == valid.end()) throw Error("thesis_scene: " + unknown_name("keyword", key, valid));
    if (key == "force_law") {
      sp.law = parse_force_law(text_of(v, key));
      continue;
    }
    const double x = number_of(v, key);
    if (key == "b") data.b = x;
    else if (key == "v_inf") data.v_inf = x;
    else if (key == "arrival_phase") data.arrival_phase = x;
    else {
      scene_field(sp, key) = x;
      given.push_back(key);
    }
  }
  return {with_asymptotic_data(sp, data, given), data};
}

/// The thesis's scene from thesis_scene()'s keywords.
Scene thesis_from(const py::dict& kw) { return thesis_scene(thesis_params_from(kw).solved); }

/// What stops a call into the library early: Ctrl-C (SIGINT, in the main thread: the handler in place
/// is put back after the call) and a budget of max_seconds of wall-clock time (a watchdog thread). Both
/// set the flag the runs poll (RunOptions::cancel, every kPollStride steps); raise() then turns a
/// stopped call into KeyboardInterrupt or bodypoint.Error, with the GIL held.
class Interruptible {
 public:
  explicit Interruptible(double max_seconds) : max_seconds_(max_seconds) {
    if (!(max_seconds > 0.0)) throw Error("max_seconds must be a number > 0 (inf: no budget), got " + fmt(max_seconds));
    const bool main_thread =
        py::module_::import("threading").attr("current_thread")().is(py::module_::import("threading").attr("main_thread")());
    if (main_thread && g_target.load() == nullptr) {
      g_target.store(&flag_);
      struct sigaction mine {};
      mine.sa_handler = [](int) {
        g_interrupted.store(true);
        if (std::atomic<bool>* f = g_target.load()) f->store(true);
      };
      sigemptyset(&mine.sa_mask);
      installed_ = ::sigaction(SIGINT, &mine, &previous_) == 0;
      if (!installed_) g_target.store(nullptr);
    }
    if (std::isfinite(max_seconds))
      watchdog_ = std::thread([this] {
        std::unique_lock<std::mutex> lock(mutex_);
        if (!done_cv_.wait_for(lock, std::chrono::duration<double>(max_seconds_), [this] { return done_; })) {
          timed_out_ = true;
          flag_.store(true);
        }
      });
  }
  ~Interruptible() { finish(); }
  Interruptible(const Interruptible&) = delete;
  Interruptible& operator=(const Interruptible&) = delete;

  [[nodiscard]] const std::atomic<bool>* flag() const { return &flag_; }

  /// Ends the guard (the handler back, the watchdog joined) and raises what stopped the call, if anything.
  void raise() {
    finish();
    if (interrupted_) {
      PyErr_SetNone(PyExc_KeyboardInterrupt);
      throw py::error_already_set();
    }
    if (timed_out_)
      throw Error("stopped after max_seconds = " + fmt(max_seconds_) + " s of wall-clock time (the call's budget)");
  }

 private:
  void finish() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    done_cv_.notify_all();
    if (watchdog_.joinable()) watchdog_.join();
    if (installed_) {
      ::sigaction(SIGINT, &previous_, nullptr);
      installed_ = false;
      interrupted_ = g_interrupted.exchange(false);
      g_target.store(nullptr);
    }
  }

  static inline std::atomic<std::atomic<bool>*> g_target{nullptr};
  static inline std::atomic<bool> g_interrupted{false};
  double max_seconds_;
  std::atomic<bool> flag_{false};
  struct sigaction previous_ {};
  bool installed_ = false, interrupted_ = false, timed_out_ = false, done_ = false;
  std::mutex mutex_;
  std::condition_variable done_cv_;
  std::thread watchdog_;
};

/// A record of the library's (record.hpp) as a dict: the keys of `simulate --json`, numbers that are
/// not finite as None, vectors as numpy arrays.
py::object to_py(const Value& v);
py::dict to_py(const Record& r) {
  py::dict d;
  for (const Field& f : r.fields) d[py::str(f.key)] = to_py(f.value);
  return d;
}
py::object to_py(const Value& v) {
  switch (v.kind) {
    case Value::Kind::null: return py::none();
    case Value::Kind::number: return std::isfinite(v.number) ? py::object(py::float_(v.number)) : py::object(py::none());
    case Value::Kind::count: return py::int_(v.count);
    case Value::Kind::text: return py::str(v.text);
    case Value::Kind::vector: return vec(v.vector);
    case Value::Kind::texts: return py::cast(v.texts);
    case Value::Kind::record: return to_py(v.records.front());
    case Value::Kind::records: {
      py::list l;
      for (const Record& r : v.records) l.append(to_py(r));
      return l;
    }
  }
  return py::none();
}

py::dict body_result(const Body& body, const BodyResult& r, const Advance& how, const std::vector<Event>& events) {
  return to_py(Record().text("name", body.name).append(body_record(r, how, events)));
}

/// The Advance the keywords ask for: the library's one mapping (advance_for, bodypoint.hpp).
Advance advance_of_keywords(const MethodInfo* m, std::optional<double> h, std::optional<long> steps,
                            std::optional<double> t_end, std::optional<double> tol, bool code_loop) {
  StepRequest request{h, steps, t_end, tol, 0.0, code_loop};
  return advance_for(m, with_default_end(request, m));  // the command line's defaults
}

/// Events by the library's one parser (parse_event): `events` located, `stop_at` ending a run.
std::vector<Event> events_of(const std::vector<std::string>& events, const std::vector<std::string>& stop_at) {
  std::vector<Event> out;
  for (const std::string& e : events) out.push_back(parse_event(e));
  for (const std::string& e : stop_at) {
    out.push_back(parse_event(e));
    out.back().stop = true;
  }
  return out;
}

py::dict integrate_py(const Scene& scene, const std::string& method, std::optional<double> h,
                      std::optional<long> steps, std::optional<double> t_end, std::optional<double> tol,
                      bool invariants, std::optional<double> omega_c, const std::vector<std::string>& event_names,
                      const std::vector<std::string>& stop_at, double max_energy_error, bool estimate_error,
                      double max_error, double max_seconds) {
  const MethodInfo* m = method == "auto" ? nullptr : &method_or_throw(method);
  const bool code_loop = std::any_of(scene.centres.begin(), scene.centres.end(),
                                     [](const Centre& c) { return c.law == ForceLaw::thesis_code; });
  const Advance how = advance_of_keywords(m, h, steps, t_end, tol, code_loop);
  Options o;
  o.track_invariants = invariants;
  if (omega_c) check_time_step_constant(*omega_c, m, std::holds_alternative<Accuracy>(how));
  o.omega_c = omega_c.value_or(-1.0);
  o.max_energy_error = max_energy_error;
  o.estimate_error = estimate_error;
  o.max_error = max_error;
  o.events = events_of(event_names, stop_at);
  Interruptible stop(max_seconds);
  o.cancel = stop.flag();
  Result r;
  {
    py::gil_scoped_release free;
    r = integrate(scene, m, how, o);
  }
  stop.raise();
  py::dict d;
  d["outcome"] = std::string(outcome_name(r.outcome));
  d["reason"] = r.reason;
  d["force_evals"] = r.force_evals;
  d["wall_s"] = r.wall_s;
  py::list bodies;
  for (std::size_t i = 0; i < r.bodies.size(); ++i) bodies.append(body_result(scene.bodies[i], r.bodies[i], how, o.events));
  d["bodies"] = bodies;
  return d;
}

/// One body followed through the given times by a Stepper (invariants tracked: each segment's steps are
/// judged, a step that turns the spin by more than pi flagged). After a segment that is not ok
/// ("unresolved" and "inaccurate" keep the state computed) the rows hold NaN.
struct Followed {
  std::vector<State> states;
  std::vector<double> E;
  Outcome outcome = Outcome::ok;
  std::string reason;
  double max_rel_dE = 0.0;
  long force_evals = 0, steps = 0;
};
/// A Python callable told (done, in all) of a long call from its C++ threads (bodypoint's _Progress):
/// at most every kProgressSeconds and at the end, under the GIL; its errors are dropped, so a display
/// never stops the work. None: nothing is told.
class ProgressHook {
 public:
  static constexpr double kProgressSeconds = 0.25;
  explicit ProgressHook(py::object f) : f_(std::move(f)) {}
  void operator()(std::size_t done, std::size_t total) {
    if (f_.is_none()) return;
    const auto now = std::chrono::steady_clock::now();
    if (done < total && std::chrono::duration<double>(now - last_).count() < kProgressSeconds) return;
    last_ = now;
    py::gil_scoped_acquire gil;
    try {
      f_(done, total);
    } catch (const py::error_already_set&) {  // dropped with its Python error (a display only)
    }
  }

 private:
  py::object f_;
  std::chrono::steady_clock::time_point last_{};
};

Followed follow(const Body& body, const std::vector<Centre>& centres, const MethodInfo& m, double h, double c,
                const std::vector<double>& times, const std::atomic<bool>* cancel,
                const std::function<void(std::size_t)>& at_time = {}) {
  Options o;
  o.omega_c = c;
  o.cancel = cancel;
  Stepper s(m, body, centres, h, o);
  const CentreList field{centres};
  const State none{Vec3::Constant(kNaN), Vec3::Constant(kNaN), Vec3::Constant(kNaN)};
  Followed f;
  f.states.assign(times.size(), none);
  f.E.assign(times.size(), kNaN);
  const double E0 = energy(body.p, field, body.s0), scale = energy_scale(body.p, field, body.s0);
  for (std::size_t k = 0; k < times.size(); ++k) {
    if (f.outcome == Outcome::ok && times[k] > s.time()) f.outcome = s.advance_to(times[k]);
    if (f.outcome != Outcome::ok && f.outcome != Outcome::unresolved && f.outcome != Outcome::inaccurate) break;
    f.states[k] = s.state();
    f.E[k] = energy(body.p, field, s.state());
    f.max_rel_dE = std::max(f.max_rel_dE, std::abs(f.E[k] - E0) / scale);
    if (at_time) at_time(k + 1);
    if (f.outcome != Outcome::ok) break;
  }
  if (f.outcome != Outcome::ok) f.reason = s.reason();
  f.force_evals = s.force_evals();
  f.steps = s.steps();
  return f;
}

/// An (n, 3) array of one vector of each state.
py::array_t<double> rows_of(const std::vector<State>& states, Vec3 State::*part) {
  py::array_t<double> a({static_cast<py::ssize_t>(states.size()), py::ssize_t{3}});
  auto m = a.mutable_unchecked<2>();
  for (std::size_t k = 0; k < states.size(); ++k)
    for (py::ssize_t j = 0; j < 3; ++j) m(static_cast<py::ssize_t>(k), j) = (states[k].*part)[static_cast<Eigen::Index>(j)];
  return a;
}

void check_times(const std::vector<double>& times) {
  if (times.empty()) throw Error("times is empty");
  for (std::size_t k = 0; k < times.size(); ++k)
    if (!std::isfinite(times[k]) || times[k] < 0.0 || (k > 0 && !(times[k] > times[k - 1])))
      throw Error("times must be finite, >= 0 and increasing");
}

/// Each body's state at the given times (increasing, >= 0), by a Stepper landing on every one. With a
/// tolerance (method auto or any method the accuracy mode takes) the method, its step and its
/// time-step constant are the accuracy mode's for a run to the last time, whose estimate is reported.
py::list trajectory_py(const Scene& scene, const std::string& method, std::optional<double> step,
                       const std::vector<double>& times, std::optional<double> omega_c, std::optional<double> tol,
                       double max_seconds, const py::object& progress) {
  check_times(times);
  ProgressHook told(progress);
  const std::size_t total = times.size() * scene.bodies.size();
  std::size_t before = 0;  // the times of the bodies followed already
  if (tol && step) throw Error("give a step or a tolerance tol, not both (tol chooses the step)");
  if (!tol && !step) throw Error("give a step (h, ds or a peer's tolerance per step) or a tolerance tol");
  const MethodInfo* named = method == "auto" ? nullptr : &method_or_throw(method);
  if (!tol && !named) throw Error("method auto needs a tolerance tol");
  if (omega_c) check_time_step_constant(*omega_c, named, tol.has_value());
  Interruptible stop(max_seconds);
  py::list out;
  for (const Body& body : scene.bodies) {
    py::dict d;
    d["name"] = body.name;
    const MethodInfo* m = named;
    double h = step.value_or(0.0), c = omega_c.value_or(-1.0);
    if (tol) {
      Options o;
      o.track_invariants = false;
      o.cancel = stop.flag();
      BodyResult r;
      {
        py::gil_scoped_release free;
        r = integrate_body(body, scene.centres, named, Accuracy{*tol, times.back() > 0.0 ? times.back() : 1.0}, o);
      }
      stop.raise();
      if (!r.accuracy) throw Error((body.name.empty() ? std::string("body") : body.name) + ": " + r.reason);
      m = r.method;
      h = r.accuracy->h_chosen;
      c = r.accuracy->omega_c;
      d["tol"] = *tol;
      d["h_chosen"] = h;
      d["err_estimate"] = r.accuracy->err_estimate;
      d["search_force_evals"] = r.accuracy->force_evals;
    }
    Followed f;
    {
      py::gil_scoped_release free;
      f = follow(body, scene.centres, *m, h, c, times, stop.flag(), [&](std::size_t k) { told(before + k, total); });
    }
    before += times.size();
    stop.raise();
    d["method"] = m->name;
    d["outcome"] = std::string(outcome_name(f.outcome));
    d["reason"] = f.reason;
    d["t"] = py::array_t<double>(static_cast<py::ssize_t>(times.size()), times.data());
    d["R"] = rows_of(f.states, &State::R);
    d["v"] = rows_of(f.states, &State::v);
    d["w"] = rows_of(f.states, &State::w);
    d["E"] = py::array_t<double>(static_cast<py::ssize_t>(f.E.size()), f.E.data());
    d["max_rel_dE"] = f.max_rel_dE;
    d["force_evals"] = f.force_evals;
    d["steps"] = f.steps;
    out.append(d);
  }
  return out;
}

/// The rows' records (record.hpp: the columns of `bodypoint sweep`'s CSV) as columns: numbers as float
/// arrays (NaN where there is none), counts as int arrays, texts as lists.
py::dict sweep_columns(const SweepSpec& spec, const std::vector<SweepRow>& rows) {
  const Record keys = sweep_record(spec);
  const auto n = static_cast<py::ssize_t>(rows.size());
  std::vector<py::array_t<double>> numbers(keys.fields.size());
  std::vector<py::array_t<long>> counts(keys.fields.size());
  std::vector<py::list> texts(keys.fields.size());
  for (std::size_t c = 0; c < keys.fields.size(); ++c) {
    if (keys.fields[c].value.kind == Value::Kind::number) numbers[c] = py::array_t<double>(n);
    if (keys.fields[c].value.kind == Value::Kind::count) counts[c] = py::array_t<long>(n);
  }
  for (py::ssize_t i = 0; i < n; ++i) {
    const Record r = sweep_record(spec, rows[static_cast<std::size_t>(i)]);
    for (std::size_t c = 0; c < r.fields.size(); ++c) {
      const Value& v = r.fields[c].value;
      if (v.kind == Value::Kind::number) numbers[c].mutable_at(i) = v.number;
      else if (v.kind == Value::Kind::count) counts[c].mutable_at(i) = v.count;
      else texts[c].append(v.text);
    }
  }
  py::dict cols;
  for (std::size_t c = 0; c < keys.fields.size(); ++c) {
    const Value::Kind kind = keys.fields[c].value.kind;
    cols[py::str(keys.fields[c].key)] = kind == Value::Kind::number  ? py::object(numbers[c])
                                        : kind == Value::Kind::count ? py::object(counts[c])
                                                                     : py::object(texts[c]);
  }
  return cols;
}

/// A sweep or grid of the thesis's scene as columns (sweep.hpp).
py::dict sweep_py(const std::vector<std::pair<std::string, std::vector<double>>>& axes,
                  const std::vector<std::string>& methods, const py::dict& base, double h, long steps, double t_end,
                  double tol, long threads, double max_energy_error, bool estimate_error, double max_error,
                  bool scattering, const std::string& force_law, std::optional<double> accuracy, double max_seconds,
                  const std::optional<std::pair<std::string, std::string>>& scene, const py::object& progress) {
  SweepSpec s;
  s.max_energy_error = max_energy_error;
  s.estimate_error = estimate_error;
  s.max_error = max_error;
  for (const auto& [param, values] : axes) s.axes.push_back({param, values});
  for (const std::string& list : methods)
    for (const MethodInfo* m : sweep_methods_named(list)) s.methods.push_back(m);
  // A datum swept beside the parameter it solves would silently replace it (the command line's rule).
  std::vector<std::string> swept, given;
  for (const Axis& a : s.axes) swept.push_back(a.param);
  for (const auto& [k, v] : base) {
    const auto key = k.cast<std::string>();
    const double x = number_of(v, key);
    if (key == "b" || key == "v_inf" || key == "arrival_phase") {
      fix_asymptotic_datum(s, key, x, key);  // as sweep --b, --v-inf, --arrival-phase
      continue;
    }
    scene_field(s.base, key) = x;
    given.push_back(key);
  }
  for (std::size_t a = swept.size(); a < s.axes.size(); ++a) swept.push_back(s.axes[a].param);
  check_data_beside_solved(swept, given);
  s.base.law = parse_force_law(force_law);
  s.scattering = scattering;
  s.accuracy = accuracy;
  s.h = h;
  s.steps = t_end > 0.0 ? 0 : steps;
  s.t_end = t_end;
  s.tol = tol;
  settle_auto(s);
  if (scene) {  // a scene file's text and name: its keys are the axes (with_scene_file)
    if (!base.empty()) throw Error("with a scene, set the scene's numbers in it or sweep its keys (centre2.A, body.B)");
    s = with_scene_file(std::move(s), scene->first, scene->second);
  }
  const unsigned workers = thread_count(threads);
  Interruptible stop(max_seconds);
  s.cancel = stop.flag();
  std::vector<SweepRow> rows;
  ProgressHook told(progress);  // made and destroyed holding the GIL; it takes the GIL to call
  try {
    py::gil_scoped_release free;
    rows = run_sweep_rows(s, workers, [&told](std::size_t done, std::size_t total) { told(done, total); });
  } catch (const Error&) {
    stop.raise();  // stopped: KeyboardInterrupt or the budget's error
    throw;
  }
  return sweep_columns(s, rows);
}

/// The scene of thesis_scene()'s keywords `kw` from twice its start distance (thesis_scene_twice_as_far:
/// the data given solved for again, the rest kept, the arrival phase the scene's own where none is given),
/// or why there is none.
constexpr double kNotGiven = std::numeric_limits<double>::quiet_NaN();
Expected<Scene> twice_as_far(const ThesisParams& t) {
  return thesis_scene_twice_as_far(t.solved, t.data.b.value_or(kNotGiven), t.data.v_inf.value_or(kNotGiven),
                                   t.data.arrival_phase.value_or(kNotGiven));
}

/// The encounter's record with its run's (`run`: method, steps, t_end, err_estimate, force_evals, ...).
py::dict encounter_py(const Scene& scene, const std::string& method, double tol, double t_end, double max_seconds,
                      const std::optional<py::dict>& thesis) {
  const MethodInfo* m = method == "auto" ? nullptr : &method_or_throw(method);
  Options o;
  o.track_invariants = false;
  Interruptible stop(max_seconds);
  o.cancel = stop.flag();
  const Body& body = scene.bodies.front();
  // The start distance's part of the error (bodypoint.hpp, add_start_distance_error): the thesis's scene
  // again from 2L, run beside this one where far legs serve both; a scene given by its states has no L to
  // double. The far scene is made here, under the GIL (from the thesis's parameters, a Python dict).
  std::optional<Expected<Scene>> far_scene;
  bool at_limit = false;
  if (thesis) {
    const ThesisParams t = thesis_params_from(*thesis);  // solves the asymptotic data: once
    far_scene = twice_as_far(t);
    at_limit = answers_at_limit(t.data.b.value_or(kNotGiven), t.data.v_inf.value_or(kNotGiven));
  }
  std::function<Expected<Scene>()> far;
  if (far_scene) far = [&far_scene] { return *far_scene; };
  std::optional<TwiceAsFar> twice = std::isnan(t_end) ? twice_as_far_beside(far, at_limit, body, scene.centres, tol, o) : std::nullopt;
  EncounterResult r;
  {
    py::gil_scoped_release free;
    r = twice ? encounter_beside(body, scene.centres, m, tol, o, &*twice) : encounter(body, scene.centres, m, tol, t_end, o);
  }
  stop.raise();
  if (r.run.outcome != Outcome::ok) throw Error(r.run.reason);
  if (r.encounter.outcome == Outcome::ok) {
    {
      py::gil_scoped_release free;
      r.run.encounter_force_evals = add_start_distance(r.encounter, body, far, tol, r.run.error.for_orbit(),
                         "the scene gives states, not the thesis's start distance L (thesis_scene() does)", o, at_limit, &r.run,
                         twice ? &*twice : nullptr);
    }
    stop.raise();
  }
  const Advance how = Accuracy{tol, r.run.run.t_end};
  return to_py(encounter_record(r.encounter).record("run", body_record(r.run, how, r.events)));
}

/// A Stepper of one body of a scene, with its events' labels kept for the hits' records.
struct PyStepper {
  PyStepper(const Scene& scene, std::size_t body, const std::string& method, std::optional<double> step,
            const std::vector<std::string>& events, const std::vector<std::string>& stop_at, std::optional<double> omega_c,
            std::optional<double> tol, std::optional<double> t_end, bool invariants, double max_seconds)
      : labels(events_of(events, stop_at)),
        stepper(made(scene, body, method, step, labels, omega_c, tol, t_end, invariants, max_seconds)) {}
  /// make(), under Ctrl-C and max_seconds, without the GIL: with a tolerance it searches (a search of rk4
  /// at tol 1e-11 over t_end = 5000 ran 113 s and went on after SIGINT).
  static Stepper made(const Scene& scene, std::size_t body, const std::string& method, std::optional<double> step,
                      std::vector<Event> events, std::optional<double> omega_c, std::optional<double> tol,
                      std::optional<double> t_end, bool invariants, double max_seconds) {
    Interruptible stop(max_seconds);
    std::optional<Stepper> s;
    try {
      py::gil_scoped_release free;
      s.emplace(make(scene, body, method, step, std::move(events), omega_c, tol, t_end, invariants, stop.flag()));
    } catch (const Error&) {
      stop.raise();  // what stopped the search, if anything: KeyboardInterrupt or the budget's Error
      throw;
    }
    s->cancel_with(nullptr);  // the flag dies with this call; advance_to() sets its own
    stop.raise();
    return std::move(*s);
  }
  /// With a step: the method's steps; with tol (and t_end): the accuracy mode's method and step for
  /// that span. Invariants tracked as integrate() tracks them, so one segment is integrate()'s run.
  static Stepper make(const Scene& scene, std::size_t body, const std::string& method, std::optional<double> step,
                      std::vector<Event> events, std::optional<double> omega_c, std::optional<double> tol,
                      std::optional<double> t_end, bool invariants, const std::atomic<bool>* cancel) {
    if (body >= scene.bodies.size())
      throw Error("body must be an index 0.." + std::to_string(scene.bodies.size() - 1) + ", got " + std::to_string(body));
    Options o;
    o.track_invariants = invariants;
    o.events = std::move(events);
    o.cancel = cancel;
    if (tol) {
      if (step) throw Error("give a step or a tolerance tol, not both (the accuracy mode chooses the step)");
      if (!t_end) throw Error("a Stepper with a tolerance needs the end time t_end the accuracy is searched for");
      if (omega_c) check_time_step_constant(*omega_c, nullptr, true);
      return Stepper(method, scene.bodies[body], scene.centres, Accuracy{*tol, *t_end}, o);
    }
    if (t_end) throw Error("t_end is the span a tolerance is searched for: give tol too, or leave t_end out");
    if (!step) throw Error("give a step (h, ds or a tolerance per step) or a tolerance tol with t_end");
    if (method == "auto") throw Error("method auto needs a tolerance: give tol and t_end");
    const MethodInfo& m = method_or_throw(method);
    if (omega_c) check_time_step_constant(*omega_c, &m, false);
    o.omega_c = omega_c.value_or(-1.0);
    return Stepper(m, scene.bodies[body], scene.centres, *step, o);
  }
  /// `s` with the entries R, v, w of d written over it (`what`: "state" or "error", for the messages); the
  /// keys in `passed` are read elsewhere or not at all, any other is refused.
  static State written(State s, const py::dict& d, const std::string& what, std::initializer_list<std::string_view> passed) {
    for (const auto& [k, v] : d) {
      const std::string key = k.cast<std::string>();
      if (key == "R") s.R = vec3_of(v, what + " R");
      else if (key == "v") s.v = vec3_of(v, what + " v");
      else if (key == "w") s.w = vec3_of(v, what + " w");
      else if (std::find(passed.begin(), passed.end(), key) == passed.end()) {
        std::vector<std::string> known{"R", "v", "w"};
        if (what == "state") known.insert(known.begin(), passed.begin(), passed.end());
        throw Error(unknown_name(what + " key", key, known));
      }
    }
    return s;
  }
  static py::dict state_dict(const State& s, double t) {
    py::dict d;
    d["t"] = t;
    d["R"] = vec(s.R);
    d["v"] = vec(s.v);
    d["w"] = vec(s.w);
    return d;
  }
  void set_state(const py::dict& d) {
    const State s = written(stepper.state(), d, "state", {"t"});
    const double t = d.contains("t") ? number_of(d["t"], "state t") : stepper.time();
    write(s, t, std::nullopt);
  }
  /// The write f (a state dict to a dict of the entries it writes) applied to the state and the companion's.
  void apply(const py::function& f) {
    const auto of = [&](const State& x) {
      const py::object out = f(state_dict(x, stepper.time()));
      if (!py::isinstance<py::dict>(out)) throw Error("apply's function must return a dict of R, v, w");
      return written(x, out.cast<py::dict>(), "state", {});
    };
    const State s = of(stepper.state());
    if (!stepper.carries_error()) return write(s, stepper.time(), std::nullopt);
    write(s, stepper.time(), of(stepper.companion_state()));
  }
  void write(const State& s, double t, const std::optional<State>& companion) {
    // A stepper with a tolerance searches again from the state written: under Ctrl-C, without the GIL.
    Interruptible stop(std::numeric_limits<double>::infinity());
    stepper.cancel_with(stop.flag());
    try {
      py::gil_scoped_release free;
      if (companion) stepper.set_state(s, t, *companion);
      else stepper.set_state(s, t);
    } catch (const Error&) {
      stepper.cancel_with(nullptr);
      stop.raise();
      throw;
    }
    stepper.cancel_with(nullptr);
    stop.raise();
  }
  py::object accuracy() const {
    if (!stepper.accuracy()) return py::none();
    const AccuracyReport& a = *stepper.accuracy();
    py::dict d;
    d["tol"] = a.tol;
    d["t_end"] = stepper.accuracy_t_end();
    d["err_estimate"] = a.err_estimate;
    d["h_chosen"] = a.h_chosen;
    if (takes_time_step_constant(stepper.method())) d["omega_c"] = a.omega_c;
    d["basis"] = a.basis;
    d["force_evals"] = a.force_evals;
    return d;
  }
  py::dict error() const {
    const ErrorEstimate e = stepper.error();
    const State x = stepper.error_state();
    py::dict d;
    d["t"] = stepper.time();
    d["estimate"] = e.known() ? py::cast(e.value) : py::none();
    d["basis"] = e.basis;
    d["R"] = vec(x.R);
    d["v"] = vec(x.v);
    d["w"] = vec(x.w);
    d["force_evals"] = e.force_evals;
    return d;
  }
  void carry_error(const py::dict& d) {
    // A Stepper's `error` dict is taken as it is: its other entries say what the vector is.
    stepper.carry_error(written(State{}, d, "error", {"t", "estimate", "basis", "force_evals"}));
  }
  std::string advance_to(double t, double max_seconds) {
    Interruptible stop(max_seconds);
    stepper.cancel_with(stop.flag());
    Outcome o{};
    {
      py::gil_scoped_release free;
      o = stepper.advance_to(t);
    }
    stepper.cancel_with(nullptr);
    stop.raise();
    return std::string(outcome_name(o));
  }
  py::dict state() const { return state_dict(stepper.state(), stepper.time()); }
  py::list hits() const {
    py::list l;
    for (const EventHit& h : stepper.events()) l.append(to_py(event_record(h, labels)));
    return l;
  }
  std::vector<Event> labels;  // before stepper: it is made from them
  Stepper stepper;
};

/// The Scene class and the functions that make scenes or list the catalogue.
void bind_scenes(py::module_& mod) {
  py::class_<Scene>(mod, "Scene", "Fixed Coulomb centres and independent body-points (docs/physics.md).", py::dynamic_attr())
      .def(py::init(&scene_from), py::arg("centres"), py::arg("bodies"))
      .def_property_readonly("centres", [](const Scene& s) {
        py::list l;
        for (const Centre& c : s.centres) l.append(centre_dict(c));
        return l;
      })
      .def_property_readonly("bodies", [](const Scene& s) {
        py::list l;
        for (const Body& b : s.bodies) l.append(body_dict(b));
        return l;
      })
      .def("__repr__", [](const Scene& s) {
        return "<bodypoint.Scene: " + std::to_string(s.centres.size()) + " centre(s), " + std::to_string(s.bodies.size()) +
               " body-point(s)>";
      });
  mod.def("_thesis_scene", &thesis_from, py::arg("params"));
  mod.def("_read_scene", &read_scene_file, py::arg("path"));
  mod.def("_parse_scene", [](const std::string& text, const std::string& origin) { return parse_scene(text, origin); },
          py::arg("text"), py::arg("origin") = "<string>");
  mod.def("_read_scene_text", &read_scene_text, py::arg("path"));
  mod.def("_arrival_phase", [](const py::dict& kw) {
    SceneParams sp;
    for (const auto& [k, v] : kw) scene_field(sp, k.cast<std::string>()) = number_of(v, k.cast<std::string>());
    return arrival_phase(sp);
  });
  mod.def("_scene_parameters", [] {
    std::vector<std::string> names;
    for (const SceneParameter& p : scene_parameters()) names.emplace_back(p.name);
    return names;
  });
  mod.def("_methods", [] {
    py::list l;
    for (const MethodInfo& m : methods()) {
      py::dict d;
      d["name"] = m.name;
      d["family"] = std::string(m.traits.family_key);
      d["order"] = m.order;
      d["stages"] = m.stages;
      d["evals_per_step"] = m.evals_per_step;
      d["description"] = m.description;
      d["geometry"] = geometry_text(m);  // what its flows preserve (methods --csv's column)
      d["symmetric"] = m.symmetric;
      d["table"] = m.table;
      l.append(d);
    }
    return l;
  });
}

/// The Stepper class (bodypoint/__init__.py wraps it).
void bind_stepper(py::module_& mod) {
  py::class_<PyStepper>(mod, "_Stepper")
      .def(py::init<const Scene&, std::size_t, const std::string&, std::optional<double>, const std::vector<std::string>&,
                    const std::vector<std::string>&, std::optional<double>, std::optional<double>, std::optional<double>,
                    bool, double>(),
           py::arg("scene"), py::arg("body"), py::arg("method"), py::arg("step"), py::arg("events"), py::arg("stop_at"),
           py::arg("omega_c"), py::arg("tol"), py::arg("t_end"), py::arg("invariants"), py::arg("max_seconds"))
      .def("advance_to", &PyStepper::advance_to, py::arg("t"), py::arg("max_seconds"))
      .def_property_readonly("time", [](const PyStepper& s) { return s.stepper.time(); })
      .def_property("state", &PyStepper::state, &PyStepper::set_state)
      .def_property_readonly("accuracy", &PyStepper::accuracy)
      .def_property_readonly("error", &PyStepper::error)
      .def("carry_error", &PyStepper::carry_error, py::arg("error"))
      .def("apply", &PyStepper::apply, py::arg("write"))
      .def_property_readonly("step", [](const PyStepper& s) { return s.stepper.step(); })
      .def_property_readonly("events", &PyStepper::hits)
      .def_property_readonly("stopped", [](const PyStepper& s) { return s.stepper.stopped(); })
      .def_property_readonly("force_evals", [](const PyStepper& s) { return s.stepper.force_evals(); })
      .def_property_readonly("steps", [](const PyStepper& s) { return s.stepper.steps(); })
      .def_property_readonly("reason", [](const PyStepper& s) { return s.stepper.reason(); })
      .def_property_readonly("method", [](const PyStepper& s) { return s.stepper.method().name; });
}

}  // namespace

PYBIND11_MODULE(_bodypoint, mod) {
  mod.doc() = "bodypoint: integrator of a body-point (translation and rotation) in Coulomb fields";
  py::register_exception<Error>(mod, "Error", PyExc_ValueError);
  bind_scenes(mod);
  bind_stepper(mod);
  mod.attr("DEFAULT_MAX_ENERGY_ERROR") = kDefaultMaxEnergyError;  // the bounds of a run called ok
  mod.attr("DEFAULT_MAX_ERROR") = kDefaultMaxError;
  mod.attr("__revision__") = git_revision();
  mod.attr("__version__") = version();
  mod.def("_integrate", &integrate_py, py::arg("scene"), py::arg("method"), py::arg("h"), py::arg("steps"),
          py::arg("t_end"), py::arg("tol"), py::arg("invariants"), py::arg("omega_c"), py::arg("events"),
          py::arg("stop_at"), py::arg("max_energy_error"), py::arg("estimate_error"), py::arg("max_error"),
          py::arg("max_seconds"));
  mod.def("_trajectory", &trajectory_py, py::arg("scene"), py::arg("method"), py::arg("step"), py::arg("times"),
          py::arg("omega_c"), py::arg("tol"), py::arg("max_seconds"), py::arg("progress"));
  mod.def("_sweep", &sweep_py, py::arg("axes"), py::arg("methods"), py::arg("base"), py::arg("h"), py::arg("steps"),
          py::arg("t_end"), py::arg("tol"), py::arg("threads"), py::arg("max_energy_error"), py::arg("estimate_error"), py::arg("max_error"),
          py::arg("scattering"), py::arg("force_law"), py::arg("accuracy"), py::arg("max_seconds"), py::arg("scene"), py::arg("progress"));
  mod.def("_encounter", &encounter_py, py::arg("scene"), py::arg("method"), py::arg("tol"), py::arg("t_end"),
          py::arg("max_seconds"), py::arg("thesis"));
}

// bodypoint's Python module (`import bodypoint`): the public API (bodypoint.hpp, sweep.hpp) with numpy
// arrays. Results are plain dicts of numbers and arrays (a sweep's is a dict of equal-length 1-D
// columns, which pandas.DataFrame takes as it is); errors are bodypoint.Error (a ValueError) with the
// library's one-line reason; the GIL is released while integrating. The Python-side docs and the
// keyword interface are in bodypoint/__init__.py; this file holds only the conversions.
#include "bodypoint/bodypoint.hpp"
#include "bodypoint/record.hpp"
#include "bodypoint/sweep.hpp"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
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

Vec3 to_vec(const py::handle& o, const char* what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(o);
  if (!a || a.ndim() != 1 || a.shape(0) != 3) throw Error(std::string(what) + " must be a sequence of 3 numbers");
  return Vec3(a.at(0), a.at(1), a.at(2));
}

double number(const py::dict& d, const char* key, double fallback) {
  return d.contains(key) ? d[key].cast<double>() : fallback;
}

py::dict centre_dict(const Centre& c) {
  py::dict d;
  d["c"] = vec(c.c);
  d["A"] = c.A;
  d["law"] = c.law == ForceLaw::coulomb ? "coulomb" : "thesis_code";
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

Centre centre_from(const py::dict& d) {
  Centre c;
  if (d.contains("c")) c.c = to_vec(d["c"], "a centre's c");
  c.A = number(d, "A", 0.0);
  if (d.contains("law")) {
    const auto law = d["law"].cast<std::string>();
    if (law == "coulomb") c.law = ForceLaw::coulomb;
    else if (law == "thesis_code") c.law = ForceLaw::thesis_code;
    else throw Error("a centre's law must be 'coulomb' or 'thesis_code', got '" + law + "'");
  }
  return c;
}

Body body_from(const py::dict& d) {
  Body b;
  b.p.m = number(d, "m", 1.0);
  b.p.B = number(d, "B", 0.0);
  b.p.J = number(d, "J", 1.0);
  if (!d.contains("R") || !d.contains("v")) throw Error("a body needs its start R and velocity v");
  b.s0.R = to_vec(d["R"], "a body's R");
  b.s0.v = to_vec(d["v"], "a body's v");
  b.s0.w = d.contains("w") ? to_vec(d["w"], "a body's w") : Vec3::Zero();
  if (d.contains("name")) b.name = d["name"].cast<std::string>();
  return b;
}

/// The thesis's scene from keyword parameters (model.hpp scene_parameters(); b and v_inf: asymptotic data).
Scene thesis_from(const py::dict& kw) {
  SceneParams sp;
  double b = kNaN, v_inf = kNaN, arrival = kNaN;
  for (const auto& [k, v] : kw) {
    const auto key = k.cast<std::string>();
    if (key == "b") b = v.cast<double>();
    else if (key == "v_inf") v_inf = v.cast<double>();
    else if (key == "arrival_phase") arrival = v.cast<double>();
    else scene_field(sp, key) = v.cast<double>();
  }
  if (!std::isnan(b) || !std::isnan(v_inf) || !std::isnan(arrival)) sp = with_asymptotic_data(sp, b, v_inf, arrival);
  return thesis_scene(sp);
}

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
  return advance_for(m, request);
}

py::dict integrate_py(const Scene& scene, const std::string& method, std::optional<double> h,
                      std::optional<long> steps, std::optional<double> t_end, std::optional<double> tol,
                      bool invariants, double omega_c, const std::vector<std::string>& event_names,
                      double max_energy_error, bool estimate_error, double max_error) {
  const MethodInfo* m = method == "auto" ? nullptr : &method_or_throw(method);
  const bool code_loop = std::any_of(scene.centres.begin(), scene.centres.end(),
                                     [](const Centre& c) { return c.law == ForceLaw::thesis_code; });
  const Advance how = advance_of_keywords(m, h, steps, t_end, tol, code_loop);
  Options o;
  o.track_invariants = invariants;
  o.omega_c = omega_c;
  o.max_energy_error = max_energy_error;
  o.estimate_error = estimate_error;
  o.max_error = max_error;
  for (const std::string& e : event_names) o.events.push_back(parse_event(e));
  Result r;
  {
    py::gil_scoped_release free;
    r = integrate(scene, m, how, o);
  }
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

/// Each body's state at the given times (increasing, >= 0), by a Stepper landing on every one.
py::list trajectory_py(const Scene& scene, const std::string& method, double step, const std::vector<double>& times,
                       double omega_c) {
  for (std::size_t k = 0; k < times.size(); ++k)
    if (!std::isfinite(times[k]) || times[k] < 0.0 || (k > 0 && !(times[k] > times[k - 1])))
      throw Error("times must be finite, >= 0 and increasing");
  validate(scene);
  py::list out;
  for (const Body& body : scene.bodies) {
    const std::size_t n = times.size();
    py::array_t<double> t(static_cast<py::ssize_t>(n));
    py::array_t<double> R({static_cast<py::ssize_t>(n), py::ssize_t{3}}), v({static_cast<py::ssize_t>(n), py::ssize_t{3}}),
        w({static_cast<py::ssize_t>(n), py::ssize_t{3}});
    auto tm = t.mutable_unchecked<1>();
    auto Rm = R.mutable_unchecked<2>();
    auto vm = v.mutable_unchecked<2>();
    auto wm = w.mutable_unchecked<2>();
    Options o;
    o.track_invariants = false;
    o.omega_c = omega_c;
    Stepper s(method, body, scene.centres, step, o);
    std::string failure;
    {
      py::gil_scoped_release free;
      for (std::size_t k = 0; k < n && failure.empty(); ++k) {
        if (times[k] > s.time() && s.advance_to(times[k]) != Outcome::ok) failure = s.reason();
        const State& x = s.state();
        tm(static_cast<py::ssize_t>(k)) = times[k];
        for (py::ssize_t j = 0; j < 3; ++j) {
          const auto i = static_cast<py::ssize_t>(k);
          Rm(i, j) = x.R[static_cast<Eigen::Index>(j)];
          vm(i, j) = x.v[static_cast<Eigen::Index>(j)];
          wm(i, j) = x.w[static_cast<Eigen::Index>(j)];
        }
      }
    }
    if (!failure.empty()) throw Error((body.name.empty() ? std::string("body") : body.name) + ": " + failure);
    py::dict d;
    d["name"] = body.name;
    d["t"] = t;
    d["R"] = R;
    d["v"] = v;
    d["w"] = w;
    d["force_evals"] = s.force_evals();
    out.append(d);
  }
  return out;
}

/// A sweep or grid of the thesis's scene as columns (sweep.hpp).
py::dict sweep_py(const std::vector<std::pair<std::string, std::vector<double>>>& axes,
                  const std::vector<std::string>& methods, const py::dict& base, double h, long steps, double t_end,
                  double tol, unsigned threads, double max_energy_error, bool estimate_error, double max_error) {
  SweepSpec s;
  s.max_energy_error = max_energy_error;
  s.estimate_error = estimate_error;
  s.max_error = max_error;
  for (const auto& [param, values] : axes) s.axes.push_back({param, values});
  for (const std::string& m : methods) s.methods.push_back(&method_or_throw(m));
  for (const auto& [k, v] : base) scene_field(s.base, k.cast<std::string>()) = v.cast<double>();
  s.h = h;
  s.steps = t_end > 0.0 ? 0 : steps;
  s.t_end = t_end;
  s.tol = tol;
  std::vector<SweepRow> rows;
  {
    py::gil_scoped_release free;
    rows = run_sweep_rows(s, threads);
  }
  const auto n = static_cast<py::ssize_t>(rows.size());
  py::dict cols;
  std::vector<py::array_t<double>> point(s.axes.size(), py::array_t<double>(n));
  for (auto& p : point) p = py::array_t<double>(n);
  py::list method, outcome, reason;
  const char* names[] = {"t_end", "Rx", "Ry", "Rz", "vx", "vy", "vz", "wx", "wy", "wz", "max_rel_dE", "max_rel_dK2sq", "max_abs_dK2Q",
                         "err_estimate"};
  py::list err_basis;
  std::vector<py::array_t<double>> num;
  for (std::size_t c = 0; c < std::size(names); ++c) num.emplace_back(n);
  py::array_t<long> force_evals(n), nsteps(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const SweepRow& r = rows[static_cast<std::size_t>(i)];
    for (std::size_t a = 0; a < point.size(); ++a) point[a].mutable_at(i) = r.point[a];
    method.append(r.method->name);
    outcome.append(std::string(outcome_name(r.outcome)));
    reason.append(r.reason);
    const State& f = r.result.final;
    const auto& inv = r.result.invariants;
    const double v[] = {r.result.t_end, f.R.x(), f.R.y(), f.R.z(), f.v.x(), f.v.y(), f.v.z(), f.w.x(), f.w.y(), f.w.z(),
                        inv ? inv->max_rel_dE : kNaN, inv ? inv->max_rel_dK2sq : kNaN,
                        inv && inv->has_K2Q ? inv->max_abs_dK2Q : kNaN, r.error.known() ? r.error.value : kNaN};
    err_basis.append(r.error.basis);
    for (std::size_t c = 0; c < std::size(names); ++c) num[c].mutable_at(i) = v[c];
    force_evals.mutable_at(i) = r.result.force_evals;
    nsteps.mutable_at(i) = r.result.steps;
  }
  for (std::size_t a = 0; a < point.size(); ++a) cols[py::str(s.axes[a].param)] = point[a];
  cols["method"] = method;
  cols["outcome"] = outcome;
  cols["reason"] = reason;
  cols["steps"] = nsteps;
  cols["force_evals"] = force_evals;
  cols["err_basis"] = err_basis;
  for (std::size_t c = 0; c < std::size(names); ++c) cols[names[c]] = num[c];
  return cols;
}

/// The encounter's record with its run's (`run`: method, steps, t_end, err_estimate, force_evals, ...).
py::dict encounter_py(const Scene& scene, const std::string& method, double tol, double t_end) {
  const MethodInfo* m = method == "auto" ? nullptr : &method_or_throw(method);
  Options o;
  o.track_invariants = false;
  EncounterResult r;
  {
    py::gil_scoped_release free;
    r = encounter(scene.bodies.front(), scene.centres, m, tol, t_end, o);
  }
  if (r.run.outcome != Outcome::ok) throw Error(r.run.reason);
  const Advance how = Accuracy{tol, r.run.run.t_end};
  return to_py(encounter_record(r.encounter).record("run", body_record(r.run, how, r.events)));
}

}  // namespace

PYBIND11_MODULE(_bodypoint, mod) {
  mod.doc() = "bodypoint: integrator of a body-point (translation and rotation) in Coulomb fields";
  py::register_exception<Error>(mod, "Error", PyExc_ValueError);
  py::class_<Scene>(mod, "Scene", "Fixed Coulomb centres and independent body-points (docs/physics.md).")
      .def(py::init([](const std::vector<py::dict>& centres, const std::vector<py::dict>& bodies) {
             Scene s;
             for (const py::dict& c : centres) s.centres.push_back(centre_from(c));
             for (const py::dict& b : bodies) s.bodies.push_back(body_from(b));
             validate(s);
             return s;
           }),
           py::arg("centres"), py::arg("bodies"))
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
  mod.def("_parse_scene", [](const std::string& text) { return parse_scene(text, "<string>"); }, py::arg("text"));
  mod.def("_arrival_phase", [](const py::dict& kw) {
    SceneParams sp;
    for (const auto& [k, v] : kw) scene_field(sp, k.cast<std::string>()) = v.cast<double>();
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
      d["family"] = std::string(family_key(m.family));
      d["order"] = m.order;
      d["stages"] = m.stages;
      d["evals_per_step"] = m.evals_per_step;
      d["description"] = m.description;
      l.append(d);
    }
    return l;
  });
  mod.attr("DEFAULT_MAX_ENERGY_ERROR") = kDefaultMaxEnergyError;  // the bounds of a run called ok
  mod.attr("DEFAULT_MAX_ERROR") = kDefaultMaxError;
  mod.def("_integrate", &integrate_py, py::arg("scene"), py::arg("method"), py::arg("h"), py::arg("steps"),
          py::arg("t_end"), py::arg("tol"), py::arg("invariants"), py::arg("omega_c"), py::arg("events"),
          py::arg("max_energy_error"), py::arg("estimate_error"), py::arg("max_error"));
  mod.def("_trajectory", &trajectory_py, py::arg("scene"), py::arg("method"), py::arg("step"), py::arg("times"),
          py::arg("omega_c"));
  mod.def("_sweep", &sweep_py, py::arg("axes"), py::arg("methods"), py::arg("base"), py::arg("h"), py::arg("steps"),
          py::arg("t_end"), py::arg("tol"), py::arg("threads"), py::arg("max_energy_error"), py::arg("estimate_error"), py::arg("max_error"));
  mod.def("_encounter", &encounter_py, py::arg("scene"), py::arg("method"), py::arg("tol"), py::arg("t_end"));
}

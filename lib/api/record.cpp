// A run's results as named fields (record.hpp): built once here, written as JSON by the command line
// and turned into dicts by the Python module.
#include "bodypoint/record.hpp"

#include "bodypoint/io.hpp"

#include <algorithm>
#include <cmath>
#include <ostream>
#include <utility>

namespace bodypoint {

namespace {

Record& add(Record& r, std::string key, Value v) {
  r.fields.push_back({std::move(key), std::move(v)});
  return r;
}

/// The step a run was asked for or chosen: h, ds, the first trial step, the accuracy mode's choice. Its size,
/// for every kind alike: a run backwards says so by its negative t_end (a fixed step read -0.01 there, a
/// searched one 0.2).
double step_of(const BodyResult& r, const Advance& how) {
  if (const auto* f = std::get_if<FixedSteps>(&how)) return std::abs(f->h);
  if (const auto* f = std::get_if<FictitiousSteps>(&how)) return std::abs(f->ds);
  if (const auto* c = std::get_if<ControlledSteps>(&how)) return std::abs(c->h0);
  return r.accuracy ? r.accuracy->h_chosen : Scattering::kNaN;
}

Record event_hits(const BodyResult& r, const std::vector<Event>& events) {
  std::vector<Record> hits;
  for (const EventHit& h : r.events) hits.push_back(event_record(h, events));
  Record out;
  out.records("events", std::move(hits)).count("event_force_evals", r.event_force_evals);
  if (std::any_of(events.begin(), events.end(), [](const Event& e) { return e.stop; })) {
    if (r.run.stopped && !r.events.empty()) out.text("stopped_by", events[r.events.back().event].label());
    else out.null("stopped_by");
  }
  return out;
}

void write_value(std::ostream& os, const Value& v) {
  switch (v.kind) {
    case Value::Kind::null: os << "null"; return;
    case Value::Kind::number: os << json_number(v.number); return;
    case Value::Kind::count: os << v.count; return;
    case Value::Kind::text: os << json_string(v.text); return;
    case Value::Kind::vector: os << json_vec(v.vector); return;
    case Value::Kind::texts:
      os << "[";
      for (std::size_t i = 0; i < v.texts.size(); ++i) os << (i ? ", " : "") << json_string(v.texts[i]);
      os << "]";
      return;
    case Value::Kind::record: write_json(os, v.records.front()); return;
    case Value::Kind::records:
      os << "[";
      for (std::size_t i = 0; i < v.records.size(); ++i) {
        if (i) os << ", ";
        write_json(os, v.records[i]);
      }
      os << "]";
      return;
  }
}

}  // namespace

Record& Record::number(std::string key, double x) {
  Value v;
  v.kind = Value::Kind::number;
  v.number = x;
  return add(*this, std::move(key), std::move(v));
}
Record& Record::count(std::string key, long n) {
  Value v;
  v.kind = Value::Kind::count;
  v.count = n;
  return add(*this, std::move(key), std::move(v));
}
Record& Record::text(std::string key, std::string s) {
  Value v;
  v.kind = Value::Kind::text;
  v.text = std::move(s);
  return add(*this, std::move(key), std::move(v));
}
Record& Record::note(std::string key, std::string s) {
  Value v;
  v.kind = Value::Kind::text;
  v.free_text = true;
  v.text = std::move(s);
  return add(*this, std::move(key), std::move(v));
}
Record& Record::vector(std::string key, const Vec3& x) {
  Value v;
  v.kind = Value::Kind::vector;
  v.vector = x;
  return add(*this, std::move(key), std::move(v));
}
Record& Record::texts(std::string key, std::vector<std::string> list) {
  Value v;
  v.kind = Value::Kind::texts;
  v.texts = std::move(list);
  return add(*this, std::move(key), std::move(v));
}
Record& Record::record(std::string key, Record r) {
  Value v;
  v.kind = Value::Kind::record;
  v.records.push_back(std::move(r));
  return add(*this, std::move(key), std::move(v));
}
Record& Record::records(std::string key, std::vector<Record> list) {
  Value v;
  v.kind = Value::Kind::records;
  v.records = std::move(list);
  return add(*this, std::move(key), std::move(v));
}
Record& Record::null(std::string key) { return add(*this, std::move(key), Value{}); }

Record& Record::append(const Record& more) {
  fields.insert(fields.end(), more.fields.begin(), more.fields.end());
  return *this;
}

Record& Record::insert_before(std::string_view key, const Record& more) {
  const auto at = std::find_if(fields.begin(), fields.end(), [key](const Field& f) { return f.key == key; });
  fields.insert(at, more.fields.begin(), more.fields.end());
  return *this;
}

const Value* Record::find(std::string_view key) const {
  for (const Field& f : fields)
    if (f.key == key) return &f.value;
  return nullptr;
}

Record event_record(const EventHit& h, const std::vector<Event>& events) {
  Record e;
  e.text("event", events[h.event].label()).number("t", h.t).number("r", h.r);
  e.number("t_error", h.t_error).number("r_error", h.r_error).number("state_error", h.state_error);
  return e.vector("R", h.s.R).vector("v", h.s.v).vector("w", h.s.w);
}

Record body_record(const BodyResult& r, const Advance& how, const std::vector<Event>& events) {
  Record out;
  if (r.method) out.text("method", std::string(r.method->name));
  else out.null("method");
  out.text("outcome", std::string(outcome_name(r.outcome))).note("reason", r.reason).number("h", step_of(r, how));
  if (const auto* c = std::get_if<ControlledSteps>(&how)) out.number("tol", c->tol);
  if (const auto* a = r.accuracy ? &*r.accuracy : nullptr) {
    out.number("tol", a->tol).number("h_chosen", a->h_chosen);
    // The time-step constant the search delivered with ds: the run is reproduced only with both (--omega-c).
    if (r.method && takes_time_step_constant(*r.method)) out.number("omega_c", a->omega_c);
    out.count("search_runs", a->runs);
    out.count("search_force_evals", a->force_evals).number("search_wall_s", a->wall_s);
  }
  if (!r.chosen.empty()) out.text("chosen", r.chosen);
  out.number("err_estimate", r.error.value).note("err_basis", r.error.basis).count("estimate_force_evals", r.error.force_evals);
  out.texts("warnings", r.warnings).count("steps", r.run.steps).number("t_end", r.run.t_end);
  out.vector("R", r.run.final.R).vector("v", r.run.final.v).vector("w", r.run.final.w);
  if (const auto& inv = r.run.invariants) {
    out.number("max_rel_dE", inv->max_rel_dE).number("max_rel_dK2sq", inv->max_rel_dK2sq);
    if (inv->has_K2Q) out.number("max_abs_dK2Q", inv->max_abs_dK2Q);
  }
  if (r.run.max_step > 0.0)
    out.count("accepted_steps", r.run.steps).number("min_step", r.run.min_step).number("max_step", r.run.max_step);
  out.count("force_evals", r.run.force_evals).number("wall_s", r.run.wall_s).count("total_force_evals", r.total_force_evals());
  return out.append(event_hits(r, events));
}

Record encounter_record(const Encounter& e) {
  const Scattering& sc = e.scattering;
  Record out;
  out.text("outcome", std::string(outcome_name(e.outcome))).note("reason", e.reason).note("asymptotes", sc.asymptotes);
  out.number("deflection", sc.deflection).number("out_of_plane", sc.out_of_plane).number("out_of_plane_error", e.out_of_plane_error);
  out.number("b_in", sc.b);
  out.number("v_inf_in", sc.v_inf).number("b_in_error", e.b_error).number("v_inf_in_error", e.v_inf_error);
  out.number("time_delay", sc.time_delay).number("asymptote_error", e.asymptote_error);
  out.note("asymptote_basis", e.asymptote_basis);
  out.number("start_distance_error", e.start_distance_error).number("time_delay_error", e.time_delay_error);
  out.number("time_delay_run_error", e.time_delay_run_error);
  out.note("start_distance_basis", e.start_distance_basis).count("start_distance_force_evals", e.start_distance_force_evals);
  out.number("deflection_error", e.deflection_error);
  if (sc.in) out.vector("direction_in", sc.in->direction).vector("direction_out", sc.out->direction);
  out.number("r_min", e.r_min).number("t_min", e.t_min).number("r_min_error", e.r_min_error).number("t_min_error", e.t_min_error);
  out.number("K1_turn", sc.K1_turn).number("spin_turn", sc.spin_turn);
  out.vector("K1_start", sc.K1_start).vector("K1_end", sc.K1_end).vector("K2_start", sc.K2_start).vector("K2_end", sc.K2_end);
  out.number("E_start", sc.E_start).number("E_end", sc.E_end);
  if (sc.has_K2Q) out.vector("K2Q_start", sc.K2Q_start).vector("K2Q_end", sc.K2Q_end);
  return out;
}

Record sweep_record(const SweepSpec& spec, const SweepRow& r) {
  constexpr double nan = Scattering::kNaN;
  const InvariantStats s = r.result.invariants ? *r.result.invariants : InvariantStats{nan, nan, nan};
  const State& f = r.result.final;
  Record out;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) out.number(spec.axes[a].param, a < r.point.size() ? r.point[a] : nan);
  out.text("method", r.automatic ? std::string("auto") : r.method ? std::string(r.method->name) : std::string());
  out.number("max_rel_dE", s.max_rel_dE).number("max_rel_dK2sq", s.max_rel_dK2sq).number("max_abs_dK2Q", s.max_abs_dK2Q);
  out.number("Rx", f.R.x()).number("Ry", f.R.y()).number("Rz", f.R.z());
  out.count("force_evals", r.result.force_evals).number("wall_s", r.result.wall_s);
  out.text("outcome", std::string(outcome_name(r.outcome)));
  out.note("reason", r.reason).number("err_estimate", r.error.value).count("estimate_force_evals", r.error.force_evals);
  out.note("err_basis", r.error.basis).note("warning", join(r.warnings, "; "));
  if (spec.scattering) {  // NaN where there is no value (no minimum, no asymptotes, a run that did not finish)
    const Scattering sc = r.scattering ? *r.scattering : Scattering{};
    out.number("r_min", r.r_min).number("t_min", r.t_min).number("r_min_error", r.r_min_error).number("t_min_error", r.t_min_error);
    out.number("deflection", sc.deflection);
    out.number("out_of_plane", sc.out_of_plane).number("b_in", sc.b).number("v_inf_in", sc.v_inf);
    out.number("time_delay", sc.time_delay).number("asymptote_error", r.asymptote_error);
    out.number("start_distance_error", r.start_distance_error).number("time_delay_error", r.time_delay_error);
    out.number("deflection_error", r.deflection_error).count("start_distance_force_evals", r.start_distance_force_evals);
    out.count("event_force_evals", r.event_force_evals);
    out.number("K1_turn", r.scattering ? sc.K1_turn : nan).number("spin_turn", r.scattering ? sc.spin_turn : nan);
    out.number("K1x", sc.K1_end.x()).number("K1y", sc.K1_end.y()).number("K1z", sc.K1_end.z());
    out.note("asymptotes", r.scattering ? sc.asymptotes : std::string("none: the run did not finish"));
  }
  out.count("steps", r.result.steps).number("t_end", r.result.t_end);
  if (spec.accuracy) {  // the accuracy mode's choice and cost (the row's own run is its delivered one)
    out.number("h_chosen", r.accuracy ? r.accuracy->h_chosen : nan);
    out.number("omega_c", r.accuracy && r.method ? time_step_constant_of(*r.method, r.accuracy->omega_c) : nan);
    out.count("search_force_evals", r.accuracy ? r.accuracy->force_evals : 0);
    if (has_auto(spec)) out.text("chosen", r.automatic && r.method ? std::string(r.method->name) : std::string());
  }
  out.number("vx", f.v.x()).number("vy", f.v.y()).number("vz", f.v.z()).number("wx", f.w.x()).number("wy", f.w.y()).number("wz", f.w.z());
  return out;
}

Record sweep_record(const SweepSpec& spec) { return sweep_record(spec, SweepRow{}); }

std::string csv_header(const Record& r) {
  CsvLine line;
  for (const Field& f : r.fields) line.text(f.key);
  return line.str();
}

std::string csv_row(const Record& r) {
  CsvLine line;
  for (const Field& f : r.fields) {
    const Value& v = f.value;
    if (v.kind == Value::Kind::number) line.num(v.number);
    else if (v.kind == Value::Kind::count) line.count(v.count);
    else if (v.kind == Value::Kind::text && v.free_text) line.quoted(v.text);
    else if (v.kind == Value::Kind::text) line.text(v.text);
    else throw Error("the CSV column '" + f.key + "' is not a number or a text");
  }
  return line.str();
}

void write_json(std::ostream& os, const Record& r) {
  os << "{";
  for (std::size_t i = 0; i < r.fields.size(); ++i) {
    os << (i ? ", " : "") << json_string(r.fields[i].key) << ": ";
    write_value(os, r.fields[i].value);
  }
  os << "}";
}

}  // namespace bodypoint

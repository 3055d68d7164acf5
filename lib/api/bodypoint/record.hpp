// A run's results as named fields: the one description of what `bodypoint simulate --json` prints and
// what the Python module's dicts hold, so that a key means the same in both (docs/guide.md, "Output
// fields"). A run-level observable is added here once and reaches both.
#pragma once

#include "bodypoint/bodypoint.hpp"
#include "bodypoint/sweep.hpp"

#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace bodypoint {

struct Record;

/// One field's value: nothing (JSON null, Python None), a number (non-finite numbers are null), a
/// count, a text, a 3-vector, a list of texts, a nested record or a list of records.
struct Value {
  enum class Kind { null, number, count, text, vector, texts, record, records };
  Kind kind = Kind::null;
  bool free_text = false;  ///< a text of words (a reason), quoted in CSV; otherwise a name
  double number = 0.0;
  long count = 0;
  std::string text;
  Vec3 vector = Vec3::Zero();
  std::vector<std::string> texts;
  std::vector<Record> records;  ///< record: exactly one; records: the list
};

struct Field {
  std::string key;
  Value value;
};

/// Named fields in the order they are written.
struct Record {
  std::vector<Field> fields;

  Record& number(std::string key, double x);
  Record& count(std::string key, long n);
  Record& text(std::string key, std::string s);  ///< a name: a method, an outcome
  Record& note(std::string key, std::string s);  ///< free text: a reason, a basis
  Record& vector(std::string key, const Vec3& v);
  Record& texts(std::string key, std::vector<std::string> list);
  Record& record(std::string key, Record r);
  Record& records(std::string key, std::vector<Record> list);
  Record& null(std::string key);
  /// Appends every field of `more`.
  Record& append(const Record& more);
  /// Inserts the fields of `more` before the field `key` (at the end when there is none).
  Record& insert_before(std::string_view key, const Record& more);
  /// The field named `key`, or nullptr.
  [[nodiscard]] const Value* find(std::string_view key) const;
};

/// One body's run as it was asked for (`how`, `events`: the Options::events its hits index):
///   method, outcome, reason, h (the step, ds, the first trial step or the step the accuracy mode
///   chose), tol (a step-size-controlled method's tolerance per step), the accuracy mode's search
///   (tol, h_chosen, search_runs, search_force_evals, search_wall_s) and its choice (chosen), the error
///   estimate (err_estimate, err_basis, estimate_force_evals), warnings, steps, t_end, the final state
///   R, v, w, the invariants' largest deviations (max_rel_dE, max_rel_dK2sq, max_abs_dK2Q) when
///   tracked, the accepted steps' range of a step-size-controlled or time-transformed run, force_evals
///   (the delivered run), wall_s, total_force_evals (the search, the estimate and the events
///   included), events (event, t, r, R, v, w), event_force_evals and, with a stop event, stopped_by.
Record body_record(const BodyResult& r, const Advance& how, const std::vector<Event>& events);

/// A located event: event (its label), t, r (the distance to its centre, or to the nearest), R, v, w.
Record event_record(const EventHit& hit, const std::vector<Event>& events);

/// An encounter (measure_encounter): outcome, reason, asymptotes, deflection, out_of_plane, b,
/// v_inf, time_delay, asymptote_error, asymptote_basis, direction_in/out (with asymptotes), r_min,
/// t_min, K1_turn, spin_turn, K1, K2 and E at both ends, K2Q at both ends when defined.
Record encounter_record(const Encounter& e);

/// One row of a sweep (sweep.hpp), the columns of `bodypoint sweep`'s CSV and of the Python module's
/// sweep(): the point's parameters, method, the invariants' deviations, Rx..Rz, force_evals, wall_s,
/// status, reason, err_estimate, estimate_force_evals, err_basis, warning, with SweepSpec::scattering
/// the encounter's columns, then steps, t_end, vx..vz, wx..wz.
Record sweep_record(const SweepSpec& spec, const SweepRow& row);
/// The sweep's columns: the record of a row that holds nothing, for its keys and their kinds.
Record sweep_record(const SweepSpec& spec);

/// The record as one JSON object on one line.
void write_json(std::ostream& os, const Record& r);
/// The record's keys, and its values, as one CSV line each (fmt numbers, names bare, free text quoted);
/// a record of numbers, counts and texts only.
std::string csv_header(const Record& r);
std::string csv_row(const Record& r);

}  // namespace bodypoint

// bodypoint: the list of observables (observables.hpp).
#include "bodypoint/observables.hpp"

#include "bodypoint/io.hpp"

#include <cmath>

namespace bodypoint {
namespace {

bool always(const std::vector<Centre>& /*centres*/) { return true; }
bool one_centre(const std::vector<Centre>& centres) { return centres.size() == 1; }

/// The angle between the spin w and the linear momentum K1 = m v + B w, in radians (0 when either
/// vanishes): how far the spin leans out of the direction of motion, which the spin-orbit coupling B
/// turns (docs/physics.md).
double spin_angle(const Sample& s, const BodyPoint& p) {
  const Vec3 K1 = p.m * s.s.v + p.B * s.s.w;
  return std::atan2(s.s.w.cross(K1).norm(), s.s.w.dot(K1));
}

}  // namespace

const std::vector<Observable>& observables() {
  static const std::vector<Observable> list = {
      {"t", "time", true, always, [](const Sample& s, const BodyPoint&) { return s.t; }},
      {"Rx", "position R = (Rx, Ry, Rz)", true, always, [](const Sample& s, const BodyPoint&) { return s.s.R.x(); }},
      {"Ry", "", true, always, [](const Sample& s, const BodyPoint&) { return s.s.R.y(); }},
      {"Rz", "", true, always, [](const Sample& s, const BodyPoint&) { return s.s.R.z(); }},
      {"vx", "velocity v = (vx, vy, vz)", true, always, [](const Sample& s, const BodyPoint&) { return s.s.v.x(); }},
      {"vy", "", true, always, [](const Sample& s, const BodyPoint&) { return s.s.v.y(); }},
      {"vz", "", true, always, [](const Sample& s, const BodyPoint&) { return s.s.v.z(); }},
      {"wx", "spin w = (wx, wy, wz)", true, always, [](const Sample& s, const BodyPoint&) { return s.s.w.x(); }},
      {"wy", "", true, always, [](const Sample& s, const BodyPoint&) { return s.s.w.y(); }},
      {"wz", "", true, always, [](const Sample& s, const BodyPoint&) { return s.s.w.z(); }},
      {"rel_dE", "|E - E0|/|E0|", true, always, [](const Sample& s, const BodyPoint&) { return s.rel_dE; }},
      {"rel_dK2sq", "|K2^2 - K2^2_0|/K2^2_0", true, always,
       [](const Sample& s, const BodyPoint&) { return s.rel_dK2sq; }},
      {"abs_dK2Q", "|K2Q - K2Q_0| (one centre only)", true, one_centre,
       [](const Sample& s, const BodyPoint&) { return s.abs_dK2Q; }},
      {"spin_angle", "angle between w and K1 = m v + B w, radians", false, always, spin_angle},
      {"K1x", "linear momentum K1 = m v + B w = (K1x, K1y, K1z)", false, always,
       [](const Sample& s, const BodyPoint& p) { return to_momenta(p, s.s).K1.x(); }},
      {"K1y", "", false, always, [](const Sample& s, const BodyPoint& p) { return to_momenta(p, s.s).K1.y(); }},
      {"K1z", "", false, always, [](const Sample& s, const BodyPoint& p) { return to_momenta(p, s.s).K1.z(); }},
      {"K2x", "proper angular momentum K2 = B v + J w = (K2x, K2y, K2z)", false, always,
       [](const Sample& s, const BodyPoint& p) { return to_momenta(p, s.s).K2.x(); }},
      {"K2y", "", false, always, [](const Sample& s, const BodyPoint& p) { return to_momenta(p, s.s).K2.y(); }},
      {"K2z", "", false, always, [](const Sample& s, const BodyPoint& p) { return to_momenta(p, s.s).K2.z(); }},
  };
  return list;
}

std::vector<const Observable*> select_observables(const std::vector<Centre>& centres,
                                                  const std::vector<std::string>& extra) {
  std::vector<const Observable*> out;
  for (const Observable& o : observables())
    if (o.by_default && o.applies(centres)) out.push_back(&o);
  for (const std::string& name : extra) {
    const Observable* found = nullptr;
    for (const Observable& o : observables())
      if (o.name == name) found = &o;
    if (!found) {
      std::vector<std::string> known;
      for (const Observable& o : observables()) known.emplace_back(o.name);
      throw Error(unknown_name("observable", name, known));
    }
    if (!found->applies(centres)) throw Error("observable '" + name + "' does not apply to this scene");
    bool present = false;
    for (const Observable* o : out) present = present || o == found;
    if (!present) out.push_back(found);
  }
  return out;
}

TrajectoryWriter::TrajectoryWriter(std::ostream& os, std::vector<const Observable*> columns, bool body_column)
    : os_(os), columns_(std::move(columns)), body_column_(body_column) {}

void TrajectoryWriter::help() const {
  for (const Observable* o : columns_)
    if (!o->help.empty()) os_ << "# " << o->name << ": " << o->help << "\n";
}

void TrajectoryWriter::header() const {
  bool first = !body_column_;
  if (body_column_) os_ << "body";
  for (const Observable* o : columns_) {
    os_ << (first ? "" : ",") << o->name;
    first = false;
  }
  os_ << '\n';
}

void TrajectoryWriter::row(long body, const Sample& s, const BodyPoint& p) const {
  CsvLine line;
  if (body_column_) line.count(body);
  for (const Observable* o : columns_) line.num(o->value(s, p));
  os_ << line.str() << '\n';
}

}  // namespace bodypoint

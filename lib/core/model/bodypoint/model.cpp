#include "bodypoint/model.hpp"

#include "bodypoint/io.hpp"
#include "bodypoint/detail/model_parts.hpp"

#include <cmath>
#include <sstream>
#include <utility>

namespace bodypoint {
namespace {

std::string num(double x) {
  std::ostringstream os;
  os.precision(17);
  os << x;
  return os.str();
}

/// Each rule below as a value: its message, or "" where it holds (why_invalid); validate throws it.
std::string not_finite(double x, const std::string& what) {
  return std::isfinite(x) ? std::string() : what + " must be a finite number, got " + num(x);
}

std::string not_finite(const Vec3& x, const std::string& what) {
  for (int i = 0; i < 3; ++i)
    if (std::string why = not_finite(x[i], what); !why.empty()) return why;
  return {};
}

void require(const std::string& why) {
  if (!why.empty()) throw Error(why);
}

std::string why_invalid(const BodyPoint& p, const std::string& who) {
  for (const auto& [x, name] : {std::pair{p.m, ": m"}, {p.B, ": B"}, {p.J, ": J"}})
    if (std::string why = not_finite(x, who + name); !why.empty()) return why;
  if (p.m <= 0.0) return who + ": mass m must be > 0, got " + num(p.m);
  if (p.J <= 0.0) return who + ": inertia J must be > 0, got " + num(p.J);
  if (!std::isfinite(p.D())) return who + ": D = m J - B^2 overflows (m J = " + num(p.m * p.J) + "); rescale the units";
  if (!(p.D() > 0.0)) return who + ": D = m J - B^2 must be > 0 (kinetic energy positive definite), got " + num(p.D());
  // D is computed with a rounding error of about eps m J; a D within a few dozen of those is not
  // resolved (m = 0.49, J = 1, B = 0.7 gives D = 5.6e-17 for an exact 0) and every velocity built
  // from 1/D would be noise.
  if (p.D() <= kMinRelativeD * p.m * p.J)
    return who + ": D = m J - B^2 = " + num(p.D()) + " is zero within rounding (it must exceed " + num(kMinRelativeD) +
           " m J)";
  return {};
}

std::string why_invalid(const ThesisStart& t, const std::string& who) {
  for (const auto& [x, name] : {std::pair{t.d, "d"}, {t.L, "L"}, {t.K1, "K1"}, {t.Kx, "Kx"}, {t.Kz, "Kz"}, {t.phase, "phase"}})
    if (std::string why = not_finite(x, who + name); !why.empty()) return why;
  if (t.K1 == 0.0) return who + "K1 must be non-zero (R(0) contains Kz/K1)";
  return {};
}

/// A body's start against the centres: off each, at a distance whose square, potential and force are
/// doubles, with representable integrals.
std::string why_invalid_start(const Body& b, const std::vector<Centre>& centres, const std::string& who) {
  for (const auto& [x, name] : {std::pair{&b.s0.R, ": R"}, {&b.s0.v, ": v"}, {&b.s0.w, ": w"}})
    if (std::string why = not_finite(*x, who + name); !why.empty()) return why;
  for (std::size_t k = 0; k < centres.size(); ++k) {
    // A body on a centre has infinite potential energy and an undefined force; one so close that A/r
    // overflows (R = 1e-300: |R|^2 underflows to 0) has them too, in double precision.
    const Vec3 d = b.s0.R - centres[k].c;
    const std::string centre = "centre " + std::to_string(k + 1);
    if (d == Vec3::Zero()) return who + " starts on " + centre + " (R = c); move it off the centre";
    const double r = d.stableNorm();
    // The force and the potential take |R - c|^2 (a centre at 1e308 read "an invariant became
    // non-finite; reduce --h").
    if (!std::isfinite(d.squaredNorm()))
      return who + " starts " + num(r) + " from " + centre + ": the square of that distance overflows a double; rescale the units";
    if (!(r > 0.0) || !std::isfinite(centres[k].A / r) || !std::isfinite(centres[k].A / (r * r)))
      return who + " starts " + num(r) + " from " + centre + ": its potential or force there (A/r, A/r^2 with A = " +
             num(centres[k].A) + ") overflows a double; start it farther or rescale the units";
  }
  // The integrals at the start must be representable: |R| |K1| and the energies of a scene of
  // scale 1e308 overflow, and every deviation after that is NaN.
  const Momenta k = to_momenta(b.p, b.s0);
  double potential = 0.0;
  for (const Centre& c : centres) potential -= c.A / (b.s0.R - c.c).norm();
  const double kinetic = 0.5 * (b.p.m * b.s0.v.squaredNorm() + 2.0 * b.p.B * b.s0.v.dot(b.s0.w) +
                                b.p.J * b.s0.w.squaredNorm());
  if (!(k.K1.allFinite() && k.K2.allFinite() && (k.R.cross(k.K1) + k.K2).allFinite() && std::isfinite(kinetic) &&
        std::isfinite(potential) && std::isfinite(kinetic + potential)))
    return who + ": the energy or angular momentum at the start overflows a double (|R| = " + num(b.s0.R.norm()) +
           ", |v| = " + num(b.s0.v.norm()) + "); rescale the units";
  // The angular momentum about each centre is an integral the runs track (a centre at 1e308 read
  // "an invariant became non-finite; reduce --h").
  for (std::size_t c = 0; c < centres.size(); ++c)
    if (!((k.R - centres[c].c).cross(k.K1) + k.K2).allFinite())
      return who + ": the angular momentum about centre " + std::to_string(c + 1) + " overflows a double (|R - c| = " +
             num((b.s0.R - centres[c].c).norm()) + "); rescale the units";
  return {};
}

}  // namespace

double require_positive(double x, std::string_view what) {
  if (!(std::isfinite(x) && x > 0.0)) throw Error(std::string(what) + " must be a finite number > 0, got " + num(x));
  return x;
}

double require_non_negative(double x, std::string_view what) {
  if (!(std::isfinite(x) && x >= 0.0)) throw Error(std::string(what) + " must be a finite number >= 0, got " + num(x));
  return x;
}

long require_count(long n, std::string_view what) {
  if (n < 1) throw Error(std::string(what) + " must be a whole number >= 1, got " + std::to_string(n));
  return n;
}

void validate(const BodyPoint& p, const std::string& who) { require(why_invalid(p, who)); }

std::string why_invalid(const Scene& scene) {
  if (scene.centres.empty()) return "the scene has no Coulomb centre";
  if (scene.bodies.empty()) return "the scene has no body-point";
  for (std::size_t k = 0; k < scene.centres.size(); ++k) {
    const std::string who = "centre " + std::to_string(k + 1);
    if (std::string why = not_finite(scene.centres[k].c, who + ": position"); !why.empty()) return why;
    if (std::string why = not_finite(scene.centres[k].A, who + ": A"); !why.empty()) return why;
  }
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    const Body& b = scene.bodies[i];
    const std::string who = b.name.empty() ? "body " + std::to_string(i + 1) : "body '" + b.name + "'";
    if (std::string why = why_invalid(b.p, who); !why.empty()) return why;
    if (std::string why = why_invalid_start(b, scene.centres, who); !why.empty()) return why;
  }
  return {};
}

void validate(const Scene& scene) { require(why_invalid(scene)); }

void validate(const ThesisStart& t, const std::string& who) { require(why_invalid(t, who)); }

std::string why_invalid(const SceneParams& sp) {
  if (std::string why = not_finite(sp.A, "A"); !why.empty()) return why;
  if (std::string why = why_invalid(sp.start, ""); !why.empty()) return why;
  return why_invalid(BodyPoint{sp.m, sp.B, sp.J}, "body");
}

Scene thesis_scene(const SceneParams& sp) {
  require(why_invalid(sp));
  const BodyPoint p{sp.m, sp.B, sp.J};
  Body body{p, to_state(p, thesis_momenta(sp.start)), "body"};
  Scene s;
  s.centres.push_back(Centre{Vec3::Zero(), sp.A, sp.law});
  s.bodies.push_back(body);
  return s;  // the scene as a whole is checked by the request that runs it (model.hpp)
}

Expected<Scene> valid_scene(Scene scene) {
  if (std::string why = why_invalid(scene); !why.empty()) return Expected<Scene>::failure(std::move(why));
  return scene;
}

Expected<Scene> valid_thesis_scene(const SceneParams& sp) {
  if (std::string why = why_invalid(sp); !why.empty()) return Expected<Scene>::failure(std::move(why));
  return valid_scene(thesis_scene(sp));
}

const std::vector<SceneParameter>& scene_parameters() {
  using Of = SceneParameter::Of;
  static const std::vector<SceneParameter> list = {
      {"A", "Coulomb constant of the centre at the origin (A < 0 repels)", [](SceneParams& p) -> double& { return p.A; }, Of::centre},
      {"m", "mass", [](SceneParams& p) -> double& { return p.m; }, Of::body},
      {"B", "coupling inertia (B = 0: material point)", [](SceneParams& p) -> double& { return p.B; }, Of::body},
      {"J", "rotational inertia", [](SceneParams& p) -> double& { return p.J; }, Of::body},
      {"K1", "initial linear momentum K1(0) = K1 i", [](SceneParams& p) -> double& { return p.start.K1; }, Of::start},
      {"Kx", "K2(0) = Kx i - Kz k", [](SceneParams& p) -> double& { return p.start.Kx; }, Of::start},
      {"Kz", "K2(0) = Kx i - Kz k", [](SceneParams& p) -> double& { return p.start.Kz; }, Of::start},
      {"d", "angular-momentum impact parameter: K2Q_z = -d K1 (not the asymptote's b; see --b)", [](SceneParams& p) -> double& { return p.start.d; }, Of::start},
      {"L", "initial distance along -x", [](SceneParams& p) -> double& { return p.start.L; }, Of::start},
      {"phase", "the helix's phase at the start: K2 turned about K1 by this angle (rad), the body with it about its "
                "guiding centre (0: the thesis's start; see arrival_phase)",
       [](SceneParams& p) -> double& { return p.start.phase; }, Of::start, true},
  };
  return list;
}

const char* force_law_name(ForceLaw law) {
  switch (law) {
    case ForceLaw::thesis_code: return "thesis-code";
    case ForceLaw::thesis_code_force: return "thesis-code-force";
    case ForceLaw::coulomb: break;
  }
  return "coulomb";
}

ForceLaw parse_force_law(std::string_view name) {
  for (const ForceLaw law : {ForceLaw::coulomb, ForceLaw::thesis_code, ForceLaw::thesis_code_force})
    if (name == force_law_name(law)) return law;
  throw Error(unknown_name("force law", name, {"coulomb", "thesis-code", "thesis-code-force"}));
}

double& scene_field(SceneParams& p, std::string_view name) {
  for (const SceneParameter& q : scene_parameters())
    if (q.name == name) return q.field(p);
  std::vector<std::string> names;
  for (const SceneParameter& q : scene_parameters()) names.emplace_back(q.name);
  throw Error(unknown_name("scene parameter", name, names));
}

}  // namespace bodypoint

// bodypoint: the model's and the scattering code's helpers that the library and the commands share but a
// program outside the tree has no use for: the one wording of a number's range, the resolution of D, the
// helix of a spinning body far from the centres, the checks of asymptotic data and the least drifting K1;
// the Kepler particle a far body is, with its asymptotes and periapsis (the scattering code's).
// Internal (not installed).
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/scattering.hpp"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bodypoint {

namespace detail {
/// x with three significant digits, for messages.
inline std::string short_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", x);
  return buf;
}
}  // namespace detail

/// The one wording of a number's range, shared by every check of the library and the commands: each
/// throws Error("<what> must be a finite number > 0, got <x>") (>= 0; a whole number >= 1) and
/// returns x when it is in range.
double require_positive(double x, std::string_view what);
double require_non_negative(double x, std::string_view what);
long require_count(long n, std::string_view what);

/// D = m J - B^2 must exceed this multiple of m J (about 45 rounding errors of m J - B^2): below it
/// the sign and size of D are not resolved in double precision.
constexpr double kMinRelativeD = 1e-14;

/// True when some centre does not follow Coulomb's law (a reproduction of the thesis's code).
inline bool non_coulomb(const std::vector<Centre>& centres) {
  for (const Centre& k : centres)
    if (k.law != ForceLaw::coulomb) return true;
  return false;
}

/// A spinning body's helix far from the centres (docs/physics.md, "Spinning body"): the kinetic drift
/// turns the body about an axis along K1 through its guiding centre G = R + K1 x K2/|K1|^2, and G moves
/// at (J |K1| - B K2.K1/|K1|)/D along K1. A material point (B = 0) has no helix: G = R, moving at v.
struct Helix {
  Vec3 centre = Vec3::Zero();    ///< G
  Vec3 velocity = Vec3::Zero();  ///< dG/dt under the drift (0 at rest)
  double radius = 0.0;           ///< |G - R| = |K1 x K2|/|K1|^2
};

inline Helix helix_of(const BodyPoint& p, const Momenta& q) {
  const double k2 = q.K1.squaredNorm();
  if (!(k2 > 0.0)) return {q.R, Vec3::Zero(), 0.0};  // at rest: no drift
  const Vec3 offset = p.B != 0.0 ? Vec3(q.K1.cross(q.K2) / k2) : Vec3::Zero();
  return {q.R + offset, ((p.J - p.B * q.K1.dot(q.K2) / k2) / p.D()) * q.K1, offset.norm()};
}

/// The least distance from c of the guiding centre's straight path over the times [0, t_max] (t_max may
/// be infinite): where a body far from the centres comes closest to c, the force bending the path aside.
inline double path_distance(const Helix& h, const Vec3& c, double t_max) {
  const Vec3 d = h.centre - c;
  const double vv = h.velocity.squaredNorm();
  const double t = vv > 0.0 ? std::clamp(-d.dot(h.velocity) / vv, 0.0, t_max) : 0.0;
  return (d + t * h.velocity).norm();
}

/// The least K1 > 0 at which the thesis's guiding centre drifts along K1, towards the centre: its drift
/// K1 (J K1 - B Kx)/D vanishes at K1 = B Kx/J; 0 where it drifts along K1 at every K1 > 0.
double least_approaching_k1(const SceneParams& p);
/// The speed at infinity of the thesis's scene p (its incoming asymptote's, from its start state), or why it has none.
Expected<double> incoming_speed(const SceneParams& p);

/// A scene as a value, checked whole once (why_invalid, model.hpp): `scene`, or why it is not valid.
Expected<Scene> valid_scene(Scene scene);
/// The thesis's scene of sp as a value: thesis_scene(sp) where sp builds one and the scene is valid as a
/// whole, or the first reason why not (a study's point, the encounter from twice the start distance).
Expected<Scene> valid_thesis_scene(const SceneParams& sp);

/// arrival_phase (scattering.hpp) as a value: the phase, or why the scene has none.
Expected<double> solve_arrival_phase(const SceneParams& params);

/// Refuses an asymptotic datum (b, v_inf, arrival_phase) in `data` (given or swept) beside the
/// parameter it solves (d, K1, phase) in `given` (set explicitly): "give b or d, not both".
void check_data_beside_solved(const std::vector<std::string>& data, const std::vector<std::string>& given);

/// The angle between two vectors, accurate for small and for near-opposite angles: atan2(|a x b|, a.b).
double angle_between(const Vec3& a, const Vec3& b);

// --- the thesis's start and a scene file's keys -----------------------------------------------

/// K1(0) = K1 i, K2(0) = Kx i - Kz k, R(0) = -L i + (d - Kz/K1) j (eq. 1.11-1.13), so that the
/// z-component of K2Q = R x K1 + K2 is -d K1; with a phase psi, K2(0) = Kx i + Kz (sin psi j - cos psi k)
/// and R(0) = -L i + (d - Kz/K1 cos psi) j - (Kz/K1) sin psi k (G and K2Q_z kept).
inline Momenta thesis_momenta(const ThesisStart& t) {
  Momenta q;
  const double c = t.phase == 0.0 ? 1.0 : std::cos(t.phase), s = t.phase == 0.0 ? 0.0 : std::sin(t.phase);
  q.K1 = Vec3(t.K1, 0.0, 0.0);
  q.K2 = Vec3(t.Kx, t.Kz * s, -t.Kz * c);
  q.R = Vec3(-t.L, t.d - t.Kz / t.K1 * c, -t.Kz / t.K1 * s);
  return q;
}

/// Whether `key` is a key path of SceneValue's form (a scene file's key, not a thesis parameter).
bool is_scene_key(const std::string& key);

// --- the Kepler particle a far body is, its asymptotes and periapsis (scattering.cpp) ----------------

/// The asymptote (outgoing, or incoming) of the Kepler orbit of a particle of mass mu at X relative
/// to a centre of force kappa X/|X|^3 (kappa = -A > 0 repels) with momentum P. Nothing when the
/// orbit is bound (E <= 0) or P = 0.
std::optional<Asymptote> kepler_asymptote(double mu, double kappa, const Vec3& X, const Vec3& P, bool outgoing);

/// The periapsis of that orbit (E > 0): the closest distance and the time from the state at (X, P)
/// until the body is there (negative once past it), from Kepler's hyperbolic equation.
struct Periapsis {
  double r = 0.0, dt = 0.0;
  double e = 1.0;  ///< the hyperbola's eccentricity (a straight line: 1)
};
std::optional<Periapsis> kepler_periapsis(double mu, double kappa, const Vec3& X, const Vec3& P);

/// The Kepler particle a body-point's state is far from a centre at c: (mu, X, P) as above (B = 0:
/// the body itself; B != 0: its guiding centre). Nothing when the guiding centre does not drift (u = 0).
struct KeplerParticle {
  double mu = 0.0;
  Vec3 X = Vec3::Zero(), P = Vec3::Zero();
  /// +1; -1 when the guiding centre drifts against K1 (u < 0): then P = -K1, and the centre's force
  /// acts on the particle as kappa_sign * kappa (a repelling centre attracts it).
  double kappa_sign = 1.0;
  /// The force constant the particle feels from a centre of constant A: -A kappa_sign.
  [[nodiscard]] double kappa(double A) const { return -A * kappa_sign; }
};
std::optional<KeplerParticle> kepler_particle(const BodyPoint& p, const State& s, const Vec3& c);

}  // namespace bodypoint

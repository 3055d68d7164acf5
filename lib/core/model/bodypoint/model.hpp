// bodypoint: the body-point model.
//
// A body-point is a particle with translational and rotational degrees of freedom and spherical
// inertia tensors, kinetic energy T = 1/2 m v.v + B v.w + 1/2 J w.w (thesis eq. 1.3,
// docs/physics.md "Model"). Symbols follow the physics:
//   m  mass, B  coupling, J  rotational inertia, D = m J - B^2 (> 0 for positive-definite T),
//   R  position, v  translational velocity, w  angular velocity,
//   K1 = m v + B w  linear momentum (eq. 1.4), K2 = B v + J w  proper angular momentum (eq. 1.5),
//   A  Coulomb constant of a centre at c: F = -A (R - c)/|R - c|^3, Pi = -A/|R - c|.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace bodypoint {

using Vec3 = Eigen::Vector3d;

/// Every invalid input is reported by throwing this; drivers print what() on one line.
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// A value, or why there is none (one line, in Error's words): what a check or a solver returns where
/// its caller decides what a failure means (a study records it beside its point, a run reports "not
/// known"); value() throws the reason as Error for a caller that stops on it. The part of C++23's
/// std::expected<T, std::string> this code needs.
template <class T>
class Expected {
 public:
  Expected(T value) : value_(std::move(value)) {}  // NOLINT(google-explicit-constructor): a value is an answer
  /// No value, because of `why` (non-empty).
  static Expected failure(std::string why) { return Expected(std::move(why), 0); }
  [[nodiscard]] bool has_value() const { return value_.has_value(); }
  explicit operator bool() const { return has_value(); }
  [[nodiscard]] const std::string& error() const { return why_; }
  [[nodiscard]] const T& value() const& {
    if (!value_) throw Error(why_);
    return *value_;
  }
  [[nodiscard]] const T& operator*() const& { return *value_; }
  [[nodiscard]] const T* operator->() const { return &*value_; }

 private:
  Expected(std::string why, int) : why_(std::move(why)) {}
  std::optional<T> value_;
  std::string why_;
};

/// Inertial parameters of one body-point.
struct BodyPoint {
  double m = 1.0;
  double B = 0.0;
  double J = 1.0;
  [[nodiscard]] double D() const { return m * J - B * B; }
};

/// The force law of a centre. `coulomb` is the model. The other two reproduce the thesis's published
/// Java code (github.com/axothy/Body-point-dynamics, BodyPointEquationWithoutTensors.java), which the
/// thesis's figures came from: it divides by |R|^1.5 where |R|^3 is meant, so F = -A (R - c)/|R - c|^1.5
/// (a force of size |A|/sqrt(r) that grows with distance), while its energy diagnostic keeps -A/|R|.
/// `thesis_code` also reinstates the code's third-kick index slip in Ruth 3, Forest-Ruth 4 and
/// Yoshida 6 (see splitting/thesis.hpp); `thesis_code_force` is the force law alone.
enum class ForceLaw { coulomb, thesis_code_force, thesis_code };
/// A force law by its one name (coulomb, thesis-code, thesis-code-force: the command line's
/// --force-law, a scene file's and the Python module's `law`); Error with the valid ones otherwise.
ForceLaw parse_force_law(std::string_view name);
const char* force_law_name(ForceLaw law);

/// A fixed Coulomb centre at c with constant A (A < 0 repels, A > 0 attracts).
struct Centre {
  Vec3 c = Vec3::Zero();
  double A = 0.0;
  ForceLaw law = ForceLaw::coulomb;
};

/// Physical variables (R, v, w).
struct State {
  Vec3 R = Vec3::Zero();
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
};

/// Whether every component of the state is a finite number.
inline bool is_finite(const State& s) { return s.R.allFinite() && s.v.allFinite() && s.w.allFinite(); }

/// Relative distance of two states, max(|dR|/|R_b|, |dv|/|v_b|) (a part of b that is zero: its absolute
/// distance): the norm of every estimate, --tol and the far legs' corrections.
inline double state_distance(const State& a, const State& b) {
  const auto rel = [](const Vec3& x, const Vec3& y) {
    const double n = y.norm();
    return n > 0.0 ? (x - y).norm() / n : (x - y).norm();
  };
  return std::max(rel(a.R, b.R), rel(a.v, b.v));
}

/// Time reversal (docs/physics.md, "Time reversal"): the equations keep their form under t -> -t,
/// v -> -v, w -> -w (the kinetic energy is quadratic in the velocities, the potential depends on R
/// alone), so a run backwards in time is the forward run of the reversed state, reversed again.
inline State time_reversed(State s) {
  s.v = -s.v;
  s.w = -s.w;
  return s;
}

/// Canonical variables (R, K1, K2) used by the splitting methods.
struct Momenta {
  Vec3 R = Vec3::Zero();
  Vec3 K1 = Vec3::Zero();
  Vec3 K2 = Vec3::Zero();
};

/// (R, v, w) -> (R, K1, K2), eq. 1.4-1.5.
inline Momenta to_momenta(const BodyPoint& p, const State& s) {
  return {s.R, p.m * s.v + p.B * s.w, p.B * s.v + p.J * s.w};
}

/// (R, K1, K2) -> (R, v, w): v = (J K1 - B K2)/D, w = (m K2 - B K1)/D (docs/physics.md "Model").
inline State to_state(const BodyPoint& p, const Momenta& q) {
  const double inv_D = 1.0 / p.D();
  return {q.R, (p.J * q.K1 - p.B * q.K2) * inv_D, (p.m * q.K2 - p.B * q.K1) * inv_D};
}

/// The thesis's initial-condition parameters (eq. 1.11-1.13).
struct ThesisStart {
  double d = 10.0;   ///< impact parameter
  double L = 200.0;  ///< initial distance along -x
  double K1 = 5.0;   ///< |K1(0)|, K1(0) = K1 i
  double Kx = 2.0;   ///< K2(0) = Kx i - Kz k
  double Kz = 5.0;
  /// The helix's phase at the start (rad): K2's part across K1 turned about K1 by this angle, and the
  /// body with it about its guiding centre G = (-L, d, 0), which stays. 0: the thesis's start.
  double phase = 0.0;
};


/// One body of a scene: parameters, initial state and a label for output.
struct Body {
  BodyPoint p;
  State s0;
  std::string name;
};

/// Centres and independent body-points (body-points do not act on each other).
struct Scene {
  std::vector<Centre> centres;
  std::vector<Body> bodies;
};

/// Table 3.1 of the thesis: A=-2, m=1, J=1, B=0.7, K1=5, Kx=2, Kz=5, d=10, L=200.
struct SceneParams {
  double A = -2.0;
  double m = 1.0;
  double B = 0.7;
  double J = 1.0;
  ThesisStart start;
  ForceLaw law = ForceLaw::coulomb;
};

/// One number of SceneParams, by name: the CLI option, the sweep axis, the appendix recipes' key and
/// the scene line of every output header read this list (one place for the names and the fields).
struct SceneParameter {
  /// What a parameter belongs to: the centre (A), the body-point's inertia (m, B, J), or its start in
  /// the thesis's form (d, L, K1, Kx, Kz). Scene files take each under its name, in that table.
  enum class Of { centre, body, start };
  std::string_view name;
  std::string_view help;
  double& (*field)(SceneParams& p);
  Of of;
  bool optional = false;  ///< a scene file may leave it out (its default then)
};
/// Every scene parameter, in the order options and headers list them.
const std::vector<SceneParameter>& scene_parameters();
/// The field of p named `name`; Error for an unknown name.
double& scene_field(SceneParams& p, std::string_view name);

/// Scene of one body and one centre at the origin from the thesis's parameters. Error for a parameter
/// it cannot compute from (not finite, K1 = 0, m, J or D not positive); the scene as a whole (its start
/// off the centre, its energy representable) is checked once, by the request that runs it (validate).
Scene thesis_scene(const SceneParams& sp);

/// Throws Error with a one-line message on the first violated rule: finite numbers, m > 0,
/// J > 0, D = mJ - B^2 > 0, at least one centre and one body, no body starting on a centre.
void validate(const Scene& scene);
/// The same rules as a value: the message validate would throw, or "" for a valid scene. For a caller
/// that records the reason and goes on (a study's skipped point, a sweep's calibration).
std::string why_invalid(const Scene& scene);
/// Why thesis_scene refuses these parameters (its message), or "" when it builds a scene from them.
std::string why_invalid(const SceneParams& sp);
void validate(const BodyPoint& p, const std::string& who);
/// The thesis's start parameters (d, L, K1, Kx, Kz, phase) finite and K1 non-zero; `who` prefixes the
/// message ("" for the thesis's scene, "body 2: " in a scene file).
void validate(const ThesisStart& t, const std::string& who);

}  // namespace bodypoint

// bodypoint: the observables of a scattering encounter (docs/physics.md, "Scattering").
//
// A run that starts far from a single Coulomb centre and ends far from it again is an encounter.
// What is measured on it:
//   - K1, K2, the energy E and (one centre) K2Q at the start and at the end of the run;
//   - the incoming and outgoing asymptotes: straight lines the body travels on at infinity, with their
//     directions, the impact parameter b of the incoming one and the momentum at infinity;
//   - the deflection: the angle between the two asymptotes' directions, and its part out of the
//     incoming plane (a material point stays in that plane; a spinning body need not);
//   - the angle K1 turned between the start and the end (no asymptote: at the run's own distances)
//     and the angle the spin K2 turned.
// The closest approach is an event of the run (located on the method's own steps, bodypoint.hpp).
//
// Asymptotes. For B = 0 (a material point of mass m) the orbit about the centre is a Kepler
// hyperbola, and its asymptotes follow exactly from the state at any distance: with kappa = -A, the
// energy E = P^2/(2 mu) + kappa/|X|, the angular momentum Lv = X x P and the Laplace-Runge-Lenz
// vector Avec = P x Lv + mu kappa X/|X| (all three conserved), the outgoing direction u solves
// Avec = mu kappa u + p_inf u x Lv and the incoming one Avec = -mu kappa u + p_inf u x Lv, so
//   u_out = ( mu kappa Avec + p_inf Lv x Avec) / |Avec|^2,
//   u_in  = (-mu kappa Avec + p_inf Lv x Avec) / |Avec|^2,      p_inf = sqrt(2 mu E),
// and the deflection satisfies Rutherford's tan(theta/2) = |A|/(mu v_inf^2 b), b = |Lv|/p_inf.
// For B != 0 the body travels on a helix about its guiding centre G = R + K1 x K2/|K1|^2, which the
// kinetic drift moves exactly along K1 at the speed u = (J |K1| - B K2.K1/|K1|)/D (docs/physics.md,
// "Exact Lie-Poisson splitting"): far from the centre G is a Kepler particle of momentum K1 and mass
// mu = |K1|/u. Its asymptotes' directions are those of that hyperbola ("guiding-centre"); the momentum and
// speed at infinity come from the energy with the guiding centre's own kinetic energy, and the impact from
// the total angular momentum K2Q (both exact first integrals; the hyperbola's are O(1/r) off). The model neglects
// the helix's radius against the distance and the slow change of K2.K1, an error that falls as
// L^-2.7 .. L^-3.9 with the distance L it is applied at (Encounter::asymptote_error estimates it).
#pragma once

#include "bodypoint/model.hpp"

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint {

/// A straight line the body travels on at infinity.
struct Asymptote {
  Vec3 direction = Vec3::Zero();  ///< unit vector of the motion along the line
  Vec3 impact = Vec3::Zero();     ///< from the centre to the line's closest point; its length is b
  double p_inf = 0.0;             ///< momentum at infinity
  double v_inf = 0.0;             ///< speed at infinity (B != 0: the guiding centre's)
  [[nodiscard]] double b() const { return impact.norm(); }
};

/// The observables of an encounter between two states of one run (start and end).
struct Scattering {
  Vec3 K1_start = Vec3::Zero(), K1_end = Vec3::Zero(), K2_start = Vec3::Zero(), K2_end = Vec3::Zero();
  double E_start = 0.0, E_end = 0.0;
  bool has_K2Q = false;  ///< one centre: K2Q about it
  Vec3 K2Q_start = Vec3::Zero(), K2Q_end = Vec3::Zero();
  double K1_turn = 0.0;    ///< angle between K1 at the start and at the end (rad)
  double spin_turn = 0.0;  ///< angle between K2 at the start and at the end (rad)
  /// "kepler" (B = 0, exact), "guiding-centre" (B != 0), or why there are none (several centres,
  /// a centre not following Coulomb's law, a bound orbit, no drift along K1).
  std::string asymptotes;
  std::optional<Asymptote> in, out;
  double deflection = kNaN;    ///< angle between in and out directions (rad), in [0, pi]
  double out_of_plane = kNaN;  ///< angle of out's direction out of the plane of in (direction, impact)
  double b = kNaN;             ///< impact parameter of the incoming asymptote
  double v_inf = kNaN;         ///< speed at infinity (B != 0: of the guiding centre), incoming
  /// The time delay against free motion (needs the run's duration): the run's time minus the Kepler
  /// time of the two legs (start to the incoming hyperbola's periapsis, the outgoing one's periapsis
  /// to the end), plus each leg's Coulomb time delay -kappa/(mu v_inf^3) (1 + ln e). For B = 0 it is
  /// -2 kappa/(mu v_inf^3)(1 + ln e) (the run's own timing error aside): free motion along the
  /// asymptotes takes that much longer than the orbit once the logarithm (kappa/(mu v_inf^3)) ln(2r/a)
  /// per leg (a = |kappa|/(mu v_inf^2)), which grows without bound in any Coulomb field, is removed.
  /// For B != 0: the guiding centre's delay, the spin's part included, each leg carried from its cut to
  /// infinity by the averaged flight, not the hyperbola (whose one mass leaves O(1/r)). docs/physics.md, "Time delay".
  double time_delay = kNaN;

  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
};

/// The single centre an encounter with `centres` is measured about far from all of them: the one centre,
/// or for several Coulomb centres their total charge sum A at their |A|-weighted centre (for charges of one
/// sign the charge centre, where their dipole vanishes: the field differs from it as 1/r^4 far away, and
/// the asymptotes' model error says what that leaves at the run's distances). Nothing without a centre, or
/// where a centre does not follow Coulomb's law.
std::optional<Centre> far_field_centre(const std::vector<Centre>& centres);

/// The encounter's observables from the first and last state of a run in this field; `elapsed` (the
/// run's duration, t_end) gives the time delay.
Scattering scattering(const BodyPoint& p, const std::vector<Centre>& centres, const State& start, const State& end,
                      double elapsed = Scattering::kNaN);

/// The thesis's scene (model.hpp, thesis_scene) whose incoming asymptote has impact parameter b: the
/// parameter d solved for it (secant iterations on the asymptote of the starting state, to a relative
/// 1e-14). For B = 0 the body starts at height d - Kz/K1 above the axis, so d ~ Kz/K1 + b; for B != 0
/// its guiding centre starts at height d, so d ~ b. Error when b is not a finite number > 0, or the
/// scene has no incoming asymptote (an attracting centre and a bound orbit).
double d_for_impact_parameter(SceneParams params, double b);

/// The thesis's scene whose body moves at speed v_inf at infinity (B != 0: its guiding centre): the
/// momentum K1 solved for it (secant iterations, relative 1e-14), d and the rest kept. The root is the one
/// with an encounter: K1 above least_approaching_k1, where the guiding centre drifts towards the centre
/// (below it, it drifts away: a second root with no encounter). Error when v_inf is not a finite number
/// > 0 or no K1 on that branch reaches it (a bound orbit on the way).
double k1_for_speed_at_infinity(SceneParams params, double v_inf);
/// The speed at infinity of the thesis's scene whose momentum at infinity is its K1 (B = 0: K1/m; B != 0: the
/// guiding centre's, (J K1 - B Kx)/D); NaN where the guiding centre would drift away (no encounter). A scene
/// given by b and not by v_inf takes this speed (solve_asymptotic_data): its L -> infinity limit keeps K1 as
/// the momentum at infinity.
double speed_at_infinity_of(const SceneParams& p);
/// The scene given by its asymptotic data: impact parameter b and/or speed at infinity v_inf (NaN:
/// not given, the scene's own d or K1 kept). Both are solved together (each depends a little on the
/// other through the start at finite distance L) until neither d nor K1 changes.
SceneParams with_asymptotic_data(SceneParams params, double b, double v_inf);
/// The same with the helix's phase at arrival (NaN: the scene's own start phase kept), set after b and
/// v_inf (which do not depend on it): start_phase_for_arrival.
SceneParams with_asymptotic_data(SceneParams params, double b, double v_inf, double arrival);
/// The same as a value: the solved parameters, or why no scene has these data (the message the
/// throwing form gives), for a caller that records the reason beside its point.
Expected<SceneParams> solve_asymptotic_data(SceneParams params, double b, double v_inf, double arrival);

/// Asymptotic data a thesis scene is given by (absent: not given), each in place of the start
/// parameter it solves: b for d, v_inf for K1, arrival_phase for phase.
struct AsymptoticData {
  std::optional<double> b, v_inf, arrival_phase;
};
/// The thesis scene's parameters with `data` solved in: each datum checked (b and v_inf finite
/// numbers > 0, the phase finite), refused beside the parameter it solves when that one is in
/// `given` (the names of the parameters set explicitly), the scene itself validated first. Throws
/// Error naming the quantity.
SceneParams with_asymptotic_data(const SceneParams& params, const AsymptoticData& data,
                                 const std::vector<std::string>& given);

/// The helix's phase at arrival of the thesis's scene (rad, in [0, 2 pi)): its start phase (ThesisStart::
/// phase) advanced by the turn of the spin about K1, -(B/D) int |K1| dt, along the guiding centre's
/// far-field motion (G drifting at u along K1, K1 pushed by the force at G) from the start to G's
/// periapsis. Starting further away at the same arrival phase gives the same encounter, up to the
/// asymptotes' model error (docs/physics.md, "Scattering": the phase is a parameter of the encounter).
double arrival_phase(const SceneParams& params);
/// The start phase that gives the arrival phase `arrival`. Error when it is not finite or the guiding
/// centre does not drift.
double start_phase_for_arrival(const SceneParams& params, double arrival);

}  // namespace bodypoint

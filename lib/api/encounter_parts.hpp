// bodypoint: the parts of an encounter (bodypoint.hpp, encounter()) that simulate, sweep, the scattering
// study and Python assemble themselves: the events a run needs, the measurement on a run, the end time,
// and the start distance's error from the same encounter twice as far. Internal to the API and the
// commands (not installed): an installed program calls encounter().
#pragma once

#include "bodypoint/bodypoint.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace bodypoint {

/// The slowest fall of the asymptotes' model error with the distance L measured (L^-2.7; study
/// --name scattering, docs/physics.md "Scattering"): halving the distance raises it at least 2^2.7x.
inline constexpr double kAsymptoteFall = 2.7;
/// A time delay is the elapsed time less quantities of its size (the asymptotes' times): its error is at
/// least this many units in the last place of the elapsed time.
inline constexpr double kTimeDelayRounding = 16.0 * std::numeric_limits<double>::epsilon();
/// A run with no end time given ends at the departure, or after this many free passes (twice the
/// start distance over the speed at infinity), then incomplete.
inline constexpr double kEncounterSpans = 2.0;

/// The events an encounter's run needs, added to `options`: every centre's closest approach; with a
/// single centre, the guiding centre's arrival at and departure from half its start distance (the
/// asymptotes' error estimate) and, with `stop_at_departure`, its departure through the start distance
/// as a stop event. The caller's events stay first, with their indices.
Options encounter_options(const Body& body, const std::vector<Centre>& centres, Options options, bool stop_at_departure);

/// The time delay's error from a run of `body` to t_end whose estimate is `error`: the far legs' own where
/// they set it (ErrorEstimate::time_delay), otherwise its pair's (ErrorEstimate::quantity: the delay read from
/// the run's state and time at the end of the span they were compared over, against the companion's, at least
/// kTimeDelayRounding of t_end); NaN without either.
double time_delay_run_error(const Body& body, const std::vector<Centre>& centres, const ErrorEstimate& error, double t_end);

/// The encounter of `body` on its run `r` (its hits of `events`, as encounter_options made them; its
/// estimate's pair for the time delay's error).
Encounter measure_encounter(const Body& body, const std::vector<Centre>& centres, const BodyResult& r,
                            const std::vector<Event>& events);

/// The end time an encounter of `body` runs to when none is given: kEncounterSpans free passes. Error
/// when the body has no speed at infinity (a bound orbit, several centres).
double encounter_span(const Body& body, const std::vector<Centre>& centres);

/// The encounter from twice the start distance run beside the encounter from L where far legs serve both
/// (integrate_encounter_checked): the legs in from L and 2L hand off at the limit L -> infinity, and one run
/// between the legs serves both (far_legs.cpp, run_pair_with_legs); add_start_distance takes its run instead of
/// running its own.
struct TwiceAsFar {
  Body body;        ///< the body of the scene from 2L (thesis_scene_twice_as_far)
  std::vector<Centre> centres;  ///< its centres
  Options options;  ///< its encounter's events (encounter_options) and the caller's options, as encounter_twice_as_far's
  std::optional<BodyResult> run;  ///< its run, where it was shared; otherwise add_start_distance runs its own
  /// What the shared run's observables differ by from its own encounter's to first order, and twice that the
  /// encounter from L's (their hand-off at the limit differs from their own by S(2L) - S(L) and 2 (S(2L) - S(L))):
  /// it cancels in the limit 2 x(2L) - x(L), and the limit's error reads |x(L) - x(2L)| less it.
  double deflection_shift = 0.0, time_delay_shift = 0.0, out_of_plane_shift = 0.0;
};
/// The accuracy of the encounter from twice the start distance, run by auto (the run's own method may not
/// reach its tol that far out: lp-kl8 at 1e-10 from L = 400): the run's tol where it had one, otherwise
/// kTwiceAsFarTol (its error must stay well below the 1/L term it measures, 1e-5..1e-3 relative at L = 200).
inline constexpr double kTwiceAsFarTol = 1e-10;
inline double twice_as_far_tol(std::optional<double> run_tol) { return run_tol ? *run_tol : kTwiceAsFarTol; }
/// Sets the start distance's part of `at_L`'s error from the same encounter started twice as far
/// (`at_2L`: encounter_twice_as_far of thesis_scene_twice_as_far; its own estimated
/// error counts in), and the deflection's total error with `numerical` (the run's err_estimate). For
/// B = 0 (`material`) no second encounter is needed: pass nullptr.
/// With `at_limit` (a scene given by asymptotic data: b or v_inf) the deflection, out-of-plane angle and
/// time delay become their values at the limit, 2 x(2L) - x(L), and the errors those values' (kLimitFactor).
void add_start_distance_error(Encounter& at_L, const EncounterResult* at_2L, bool material, double numerical,
                              bool at_limit = false);
/// The encounter of `far` (the thesis's scene from 2L) by auto at `tol` (twice_as_far_tol), looser by
/// 100x while auto refuses it as out of reach, to 1e-6 at most (the 1/L term it measures is 1e-6..1e-3
/// at L = 200..1600; auto at 1e-10 is out of reach from L = 3200). With `near` (the same encounter's run
/// from L, by auto or a named method at the same tol) its search starts at that run's delivered step where
/// auto chooses the same method here: the near field, which sets the step, is the same.
EncounterResult encounter_twice_as_far(const Scene& far, double tol, const Options& options = {},
                                       const BodyResult* near = nullptr);
/// The same when the start distance cannot be doubled (a scene given by its states): the part is not
/// known (`why`), nor is the total, for B != 0.
void no_start_distance_error(Encounter& e, bool material, double numerical, const std::string& why);
/// Whether a thesis scene given by these asymptotic data (NaN: not given) answers at the limit L -> infinity
/// (`at_limit` of add_start_distance): given by b or v_inf.
inline bool answers_at_limit(double b, double v_inf) { return !(std::isnan(b) && std::isnan(v_inf)); }
/// The start distance's part of `e`'s error, one rule for every caller (simulate, sweep, the scattering
/// study, Python): exact (0) for a material point, and 0 where the scene gives states (`far` empty, `no_far`
/// saying so: its observables are its trajectory's); not known (its reason) where `far()` finds no scene
/// there; otherwise the encounter from `far()` (thesis_scene_twice_as_far) run by auto at
/// twice_as_far_tol(tol), and with `at_limit` (a scene given by b or v_inf) the observables taken to the limit
/// L -> infinity (add_start_distance_error); `near`, the run from L, seeds the far run's search
/// (encounter_twice_as_far); `twice` with its run (twice_as_far_beside, shared far legs' run) stands for that
/// encounter. Returns the force evaluations of that second encounter (0 where none ran), also in
/// Encounter::start_distance_force_evals.
long add_start_distance(Encounter& e, const Body& body, const std::function<Expected<Scene>()>& far,
                        std::optional<double> tol, double numerical, const std::string& no_far, const Options& options = {},
                        bool at_limit = false, const BodyResult* near = nullptr, const TwiceAsFar* twice = nullptr);
/// The run from 2L to share with an encounter of `body` at the limit (`at_limit`: a scene given by asymptotic
/// data, `far` its scene from 2L) in the accuracy mode (`tol`); none for a material point, a scene given by
/// states, a run by step, or where `far` finds no scene (add_start_distance then says why).
std::optional<TwiceAsFar> twice_as_far_beside(const std::function<Expected<Scene>()>& far, bool at_limit, const Body& body,
                                              const std::vector<Centre>& centres, std::optional<double> tol,
                                              const Options& options = {});
/// encounter() to its departure with the run from 2L beside it (`twice`, twice_as_far_beside; or none) where far
/// legs serve both.
EncounterResult encounter_beside(const Body& body, const std::vector<Centre>& centres, const MethodInfo* method, double tol,
                                 Options options, TwiceAsFar* twice);

/// The thesis's scene of the parameters `solved` (d, K1, phase solved for the asymptotic data) with the start
/// distance L doubled and the data b, v_inf (NaN: not given, d, K1 kept) solved for again; the arrival phase
/// as given, or (NaN) the scene's own at L (a start phase kept has no limit L -> infinity: the extra way in
/// turns it). Or why no scene from 2L has the data.
Expected<Scene> thesis_scene_twice_as_far(SceneParams solved, double b, double v_inf, double arrival_phase);

}  // namespace bodypoint

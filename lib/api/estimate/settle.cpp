// bodypoint: what a run's flags make of its error estimate (estimate.hpp, settle): a heuristic flag overruled by
// an estimate that resolves it, the energy's flag by a final state that no longer shows it, an estimate above the
// bound made a flag.
#include "estimate/parts.hpp"

#include "bodypoint/field.hpp"
#include "bodypoint/detail/monitor.hpp"
#include "bodypoint/detail/model_parts.hpp"
#include "checked.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace bodypoint::detail {
namespace {

/// A final state whose relative energy error exceeds this many times its estimated error has an error
/// the estimate does not account for; below kEnergyRoundOff it is round-off.
constexpr double kEnergyPerState = 10.0;
constexpr double kEnergyRoundOff = 1e-12;

}  // namespace

double final_energy_error(const Body& body, const std::vector<Centre>& centres, const State& end) {
  if (non_coulomb(centres)) return std::numeric_limits<double>::quiet_NaN();  // E is not an integral there
  const CentreList field{centres};
  const double scale = energy_scale(body.p, field, body.s0);
  const double dE = std::abs(energy(body.p, field, end) - energy(body.p, field, body.s0));
  return scale > 0.0 ? dE / scale : dE;
}

void settle(Outcome& outcome, std::string& reason, std::vector<std::string>& warnings, const ErrorEstimate& e,
            double max_error, double max_energy_error, double final_rel_dE) {
  if (!e.known()) return;
  const bool within = e.value <= max_error;
  const std::string kept = ", but the estimated error is " + short_number(e.value) + " (" + e.basis + "): kept";
  // The heuristic flag is overruled by an estimate within both bounds whose companion resolves what the
  // run did not: a pair that both alias the spin differ by what aliasing leaves, not by the error
  // (kep-ss10 at h = 0.5 and 0.25 on B = 0.9: 9.5 and 9.1 % off, 0.4 % apart).
  if (outcome == Outcome::unresolved && within && e.value <= max_energy_error && e.confirmed) {
    warnings.push_back(reason + kept);
    outcome = Outcome::ok;
    reason.clear();
    return;
  }
  // The energy's flag is a measurement: it is overruled only where the final state no longer shows it
  // (its energy error within the bound: a transient near a centre, as the two-centre pass at h = 0.2,
  // 5.4e-2 on the way and 0.33 % off at the end) and the estimate accounts for what it does show. An
  // estimate far below the final energy error was fooled (rk4 at h = 0.1 and 0.05 on B = 0.9 agree to
  // 1.8e-5, both 81 % off, the energy 69 % off at the end).
  if (outcome == Outcome::inaccurate && within && final_rel_dE <= max_energy_error &&
      final_rel_dE <= kEnergyPerState * e.value + kEnergyRoundOff) {
    warnings.push_back(reason + " on the way, " + short_number(final_rel_dE) + " at the end" + kept);
    outcome = Outcome::ok;
    reason.clear();
    return;
  }
  if (!within && outcome == Outcome::ok) {
    outcome = Outcome::inaccurate;
    reason = "the estimated relative error of the final state is " + short_number(e.value) + " (above the bound " +
             short_number(max_error) + "; " + e.basis + ")";
  }
}

void judge(BodyResult& r, const std::vector<Centre>& centres, const Options& options) {
  // A run observed for its events or samples alone has invariants it was not asked for: they are neither
  // reported nor judged (a Stepper with invariants off and a stop event was refused "unresolved" far out,
  // where a controlled step at a tolerance per step of 1e-13 turned the spin by 3.6 rad).
  if (!options.track_invariants) r.run.invariants.reset();
  Health h = assess(r.run, checks_for(*r.method, centres, options.max_energy_error));
  r.outcome = h.outcome;
  r.reason = std::move(h.why);
}

}  // namespace bodypoint::detail

namespace bodypoint {

void check_error_bound(double max_error) {
  if (!(max_error > 0.0))
    throw Error("the bound on the estimated error max_error must be a number > 0 (infinity: no bound), got " +
                detail::short_number(max_error));
}

}  // namespace bodypoint

// bodypoint command line: options shared by the subcommands.
#pragma once

#include "bodypoint/bodypoint.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"

#include <boost/program_options.hpp>

#include <optional>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

namespace bodypoint {
struct TwiceAsFar;  // encounter_parts.hpp
}  // namespace bodypoint

namespace bodypoint::cli {

namespace po = boost::program_options;

/// An option stored in *field and defaulting to its present value; a number's default is shown as the
/// shortest text that reads back (--B arg (=0.7), not 0.69999999999999996).
template <class T>
po::typed_value<T>* defaulted(T* field) {
  if constexpr (std::is_floating_point_v<T>) return po::value(field)->default_value(*field, fmt(*field));
  else return po::value(field)->default_value(*field);
}

/// Scene options named as in the thesis, defaulting to table 3.1.
struct SceneOptions {
  SceneParams params;
  std::string scene_file;
  /// --b, --v-inf: the scene by its asymptotic data (NaN: not given); d and K1 solved for them.
  double b = std::numeric_limits<double>::quiet_NaN(), v_inf = std::numeric_limits<double>::quiet_NaN();
  double arrival_phase = std::numeric_limits<double>::quiet_NaN();  ///< --arrival-phase: the start phase solved for it
};
void add_scene_options(po::options_description& desc, SceneOptions& o);
/// The thesis's parameters with --b and --v-inf applied (d and K1 solved for them; scattering.hpp).
SceneParams scene_params(const po::variables_map& vm, const SceneOptions& o);
/// The scene from --scene or from the thesis's parameters (never both); o.params becomes the solved ones.
/// The scene is checked here, once (validate): the command's runs take it as checked (run_body).
Scene make_scene(const po::variables_map& vm, SceneOptions& o);

/// Step options: --h and --steps or --t-end.
struct StepOptions {
  double h = kDefaultStep;  // the defaults of every run are the library's (bodypoint.hpp)
  long steps = kDefaultSteps;
  double t_end = 0.0;
  double max_energy_error = kDefaultMaxEnergyError;  ///< the accuracy flag's bound (Options)
  double max_error = kDefaultMaxError;               ///< the bound on the estimated error (Options)
  bool no_error_estimate = false;                    ///< Options::estimate_error off
};
void add_step_options(po::options_description& desc, StepOptions& o);
/// o.max_energy_error, checked: a number > 0 (inf: no bound); Error otherwise.
double energy_bound(const StepOptions& o);
/// o.max_error, checked the same way.
double error_bound(const StepOptions& o);
/// The library's step request from --h, --steps, --t-end and --tol as given (defaulted ones left out),
/// with the command line's defaults: no end given, --steps 500000 (or with --tol, t_end = 50, the
/// thesis's h n); --force-law thesis-code counts steps as the thesis's code did.
/// end_if_none: the end time when neither --t-end nor --steps is given (else table 3.1's).
StepRequest step_request(const po::variables_map& vm, const StepOptions& o, const MethodInfo* method, double tol,
                         std::optional<double> end_if_none = std::nullopt);

/// What --method, --tol and the step options ask for: a method (nullptr: auto) and the way it
/// advances (Accuracy when --tol chooses the step), with the run's options.
struct RunPlan {
  const MethodInfo* method = nullptr;
  bool automatic = false;  ///< --method auto, or --tol without --method
  bool search = false;     ///< --tol chooses the step (any method but odeint-*/gsl-*)
  double tol = 0.0;
  Advance how = FixedSteps{kDefaultStep, kDefaultSteps};
  Options options;  ///< invariants, every, omega_c and the energy bound; events and sink are per run
};
/// The method, the way of advancing time and the energy bound from the options; throws Error with
/// the reason (plan.cpp).
RunPlan plan_run(const po::variables_map& vm, const StepOptions& st, const std::string& method_name,
                 bool method_defaulted, double tol, std::optional<double> end_if_none = std::nullopt);
/// plan.how's step: h, the fictitious step ds, or a controlled method's first trial step (0: search).
double planned_step(const RunPlan& plan);
/// plan.how's end time: t_end, or the end of its steps (fictitious steps: 0, not known in advance).
double planned_end(const RunPlan& plan);

/// Runs one body of a scene checked by make_scene as planned through the library (integrate_body with
/// `how`, plan.options, the sink and the events, its scene not checked again). A method that refuses the scene or a run that fails throws Error with the
/// library's reason; diverged and collision are left to the caller (outcome, reason).
/// With `twice` (an encounter at the limit: the same from 2L) its run is set where far legs serve both
/// (integrate_encounter_checked).
BodyResult run_body(const RunPlan& plan, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                 const SampleSink* sink, const std::vector<Event>& events = {}, TwiceAsFar* twice = nullptr);

/// One run of a study through the public API (integrate_body), as a value: a refused or failed run says
/// so in its outcome and reason, which the study records. A study measures its errors against
/// references: the run makes no error estimate of its own (Options::estimate_error off).
BodyResult run_unestimated(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres,
                           const Advance& how, const Options& options);
/// run_unestimated's RunResult where the run must succeed (a reference, a timed rerun of a run that
/// did): a refused or failed run throws Error with the library's reason.
RunResult run_or_throw(const MethodInfo& m, const Body& body, const std::vector<Centre>& centres, const Advance& how,
                       const Options& options);
/// Options that observe nothing (no invariants, no samples, no error estimate): the fastest run, for
/// timings and errors measured against references.
inline Options unobserved() {
  Options o;
  o.track_invariants = false;
  o.estimate_error = false;
  return o;
}

/// Parses argv into vm, rejecting unknown options and positional words; returns false after
/// printing help when --help is given.
bool parse(int argc, char** argv, const po::options_description& desc, po::variables_map& vm,
           const std::string& usage);

int cmd_simulate(int argc, char** argv);
int cmd_methods(int argc, char** argv);
int cmd_work_precision(int argc, char** argv);
int cmd_sweep(int argc, char** argv);
int cmd_timing(int argc, char** argv);
int cmd_study(int argc, char** argv);
int cmd_view(int argc, char** argv);

std::string describe(const SceneParams& p);

/// The non-empty items of a comma-separated list.
std::vector<std::string> split_list(const std::string& s);
/// One number (subnormals accepted); throws Error naming `option` for text that is not one or overflows.
double parse_number(const std::string& s, const std::string& option);
/// x as a count in [1, max], checked before the conversion; throws Error with the reason.
long whole_number(double x, const std::string& what, double max);
/// The numbers of a comma-separated list; throws Error naming `option` for an item that is not one.
std::vector<double> parse_numbers(const std::string& list, const std::string& option);
/// "bodypoint <argv...>", for output headers.
std::string command_line(int argc, char** argv);


}  // namespace bodypoint::cli

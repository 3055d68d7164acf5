#include "process.hpp"
#include "cli.hpp"
#include "budget.hpp"
#include "checked.hpp"

#include "bodypoint/io.hpp"
#include "bodypoint/scattering.hpp"
#include "bodypoint/scene_file.hpp"
#include "sweep.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace bodypoint::cli {

void add_scene_options(po::options_description& desc, SceneOptions& o) {
  SceneParams& p = o.params;
  for (const SceneParameter& q : scene_parameters()) {
    double& field = q.field(p);
    desc.add_options()(std::string(q.name).c_str(), defaulted(&field), std::string(q.help).c_str());
  }
  desc.add_options()
      ("force-law", po::value<std::string>()->default_value("coulomb")->notifier([&p](const std::string& v) {
         p.law = parse_force_law(v);
       }),
       "coulomb (the model); thesis-code (the thesis's published code: F ~ R/|R|^1.5, its third-kick slip and "
       "its loop, n - 1 steps of n asked, to regenerate its figures as published); thesis-code-force (that force "
       "law alone)")
      ("b", po::value(&o.b), "the scene by its impact parameter b (of the incoming asymptote): d is solved for it "
       "(docs/physics.md, Scattering)")
      ("v-inf", po::value(&o.v_inf), "the scene by its speed at infinity (B != 0: the guiding centre's): K1 is solved for it")
      ("arrival-phase", po::value(&o.arrival_phase), "the scene by the helix's phase when its guiding centre reaches "
       "the periapsis (rad): --phase is solved for it (docs/physics.md, Scattering)")
      ("scene", po::value(&o.scene_file), "TOML scene file with several centres and bodies (see scenes/)");
}

SceneParams scene_params(const po::variables_map& vm, const SceneOptions& o) {
  // The parameters given explicitly, in the library's names (the options' dashes are underscores).
  std::vector<std::string> given;
  for (const SceneParameter& q : scene_parameters())
    if (vm.count(std::string(q.name)) && !vm[std::string(q.name)].defaulted()) given.emplace_back(q.name);
  AsymptoticData data;
  if (vm.count("b")) data.b = o.b;
  if (vm.count("v-inf")) data.v_inf = o.v_inf;
  if (vm.count("arrival-phase")) data.arrival_phase = o.arrival_phase;
  return with_asymptotic_data(o.params, data, given);
}

Scene make_scene(const po::variables_map& vm, SceneOptions& o) {
  if (vm.count("scene")) {
    std::vector<std::string> keys{"force-law", "b", "v-inf", "arrival-phase"};
    for (const SceneParameter& q : scene_parameters()) keys.emplace_back(q.name);
    for (const std::string& k : keys)
      if (vm.count(k) && !vm[k].defaulted())
        throw Error("--" + k + " cannot be combined with --scene (set it in the scene file)");
    Scene scene = read_scene_file(o.scene_file);
    register_input(o.scene_file);  // no output of this run may replace it
    return scene;
  }
  o.params = scene_params(vm, o);  // with b, v_inf or the arrival phase: d, K1 or phase as solved
  Scene scene = thesis_scene(o.params);
  validate(scene);
  return scene;
}

void add_step_options(po::options_description& desc, StepOptions& o) {
  desc.add_options()
      ("h", defaulted(&o.h), "step size")
      ("steps", defaulted(&o.steps), "number of steps n")
      ("t-end", po::value(&o.t_end), "end time T (steps = ceil(T/h), h adjusted to T/steps)")
      ("max-energy-error", defaulted(&o.max_energy_error),
       "flag a run whose relative energy error exceeds this bound as inaccurate (inf: no bound; not applied "
       "under --force-law thesis-code, whose flow does not conserve E)")
      ("max-error", defaulted(&o.max_error),
       "flag a run whose estimated relative error of the final state exceeds this bound as inaccurate (inf: no "
       "bound)")
      ("no-error-estimate", po::bool_switch(&o.no_error_estimate),
       "no companion run to estimate the error of a run by step (it costs about half the run's time; a run at the rounding level "
       "without a batch kernel, one run; 2.5 runs where a companion at half the step decides); the outputs "
       "then say the run has no estimate");
}

double energy_bound(const StepOptions& o) {
  if (!(o.max_energy_error > 0.0))
    throw Error("--max-energy-error must be a number > 0 (inf: no bound), got " + fmt(o.max_energy_error));
  return o.max_energy_error;
}

double error_bound(const StepOptions& o) {
  if (!(o.max_error > 0.0)) throw Error("--max-error must be a number > 0 (inf: no bound), got " + fmt(o.max_error));
  return o.max_error;
}

StepRequest step_request(const po::variables_map& vm, const StepOptions& o, const MethodInfo* method, double tol,
                         std::optional<double> end_if_none) {
  StepRequest r;
  if ((vm.count("tol") && !vm["tol"].defaulted()) || (method && takes_tolerance_per_step(*method))) r.tol = tol;
  // A step given is passed on (the accuracy mode refuses it); a default one only where a step is used.
  if (!vm["h"].defaulted() || !searches(method, r)) r.h = o.h;
  if (!vm["steps"].defaulted()) r.steps = o.steps;
  if (vm.count("t-end")) r.t_end = o.t_end;
  // --force-law thesis-code counts steps as the thesis's code did (n - 1 of n asked; run.hpp).
  r.code_loop = vm.count("force-law") && parse_force_law(vm["force-law"].as<std::string>()) == ForceLaw::thesis_code;
  if (!r.t_end && !r.steps && end_if_none) r.t_end = end_if_none;
  return with_default_end(r, method);
}

std::string describe(const SceneParams& p) {
  std::ostringstream os;
  SceneParams copy = p;
  const char* sep = "";
  for (const SceneParameter& q : scene_parameters()) {
    os << sep << q.name << '=' << fmt(q.field(copy));
    sep = " ";
  }
  if (p.law != ForceLaw::coulomb) os << " force-law=" << force_law_name(p.law);
  return os.str();
}

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

double parse_number(const std::string& s, const std::string& option) {
  const std::optional<double> v = read_double(s);
  if (v) return *v;
  char* end = nullptr;
  std::strtod(s.c_str(), &end);  // read whole but refused: beyond the range of a double
  const bool whole = !s.empty() && end == s.c_str() + s.size() && !std::isspace(static_cast<unsigned char>(s.front()));
  throw Error(option + ": '" + s + (whole ? "' is beyond the range of a double" : "' is not a number"));
}

long whole_number(double x, const std::string& what, double max) {
  if (!std::isfinite(x) || x != std::floor(x)) throw Error(what + " must be a whole number, got " + fmt(x));
  if (x < 1.0) throw Error(what + " must be >= 1, got " + fmt(x));
  if (x > max) throw Error(what + " must be at most " + fmt(max) + ", got " + fmt(x));
  return static_cast<long>(x);  // in range: no undefined conversion
}

std::vector<double> parse_numbers(const std::string& list, const std::string& option) {
  std::vector<double> out;
  for (const std::string& s : split_list(list)) out.push_back(parse_number(s, option));
  if (out.empty()) throw Error(option + " is empty");
  return out;
}

std::string command_line(int argc, char** argv) {
  std::string command = "bodypoint";
  for (int i = 0; i < argc; ++i) command += std::string(" ") + argv[i];
  return command;
}

bool parse(int argc, char** argv, const po::options_description& desc, po::variables_map& vm,
           const std::string& usage) {
  po::options_description all(desc);
  all.add_options()("help", "show this help");
  // One budget for every command (simulate has its own default): past it, every loop stops alike.
  if (!desc.find_nothrow("max-seconds", false))
    all.add_options()("max-seconds", po::value<double>()->default_value(kDefaultMaxSeconds, fmt(kDefaultMaxSeconds)),
                      "stop with an error after this many seconds of wall-clock time (0: no limit); runs "
                      "whose calibrated estimate exceeds it are refused before they start");
  // Whole option names only: with boost's default prefix guessing, "--ou x" would mean "--out x".
  const int style = po::command_line_style::default_style & ~po::command_line_style::allow_guessing;
  try {
    po::store(po::command_line_parser(argc, argv).options(all).positional({}).style(style).run(), vm);
  } catch (const po::unknown_option& e) {
    std::vector<std::string> names;
    for (const auto& o : all.options()) names.push_back("--" + o->long_name());
    const std::string near = closest_word(e.get_option_name(), names, 2);
    // The message is built here: boost's what() substitutes placeholders into the option's own text,
    // which loops without end when that text holds a placeholder ('--x%option%', fuzz_cli's find).
    throw Error("unrecognised option '" + e.get_option_name() + "'" +
                (near.empty() ? "" : " (did you mean " + near + "?)"));
  }
  if (vm.count("help")) {
    std::cout << usage << "\n\n" << all << "\n";
    return false;
  }
  po::notify(vm);
  const double budget = vm["max-seconds"].as<double>();
  if (!(budget >= 0.0)) throw Error("--max-seconds must be a number >= 0");
  set_deadline(budget, "stopped after --max-seconds " + fmt(budget) + " s of wall-clock time (the run's budget)");
  return true;
}

}  // namespace bodypoint::cli

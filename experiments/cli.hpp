// bodypoint command line: options shared by the subcommands.
#pragma once

#include "bodypoint/model.hpp"
#include "bodypoint/run.hpp"

#include <boost/program_options.hpp>

#include <string>
#include <vector>

namespace bodypoint::cli {

namespace po = boost::program_options;

/// Scene options named as in the thesis, defaulting to table 3.1.
struct SceneOptions {
  SceneParams params;
  std::string scene_file;
};
void add_scene_options(po::options_description& desc, SceneOptions& o);
/// The scene from --scene or from the thesis's parameters (never both).
Scene make_scene(const po::variables_map& vm, const SceneOptions& o);

/// Step options: --h and --steps or --t-end.
struct StepOptions {
  double h = 1e-4;
  long steps = 500000;
  double t_end = 0.0;
};
void add_step_options(po::options_description& desc, StepOptions& o);
/// Fills spec.h and spec.steps. With --t-end T: steps = ceil(T/h), h = T/steps (hits T exactly).
void apply_step_options(const po::variables_map& vm, const StepOptions& o, RunSpec& spec);

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

/// "A=.. m=.. B=.. J=.. K1=.. Kx=.. Kz=.. d=.. L=..": the thesis's parameters, for output headers.
std::string describe(const SceneParams& p);

/// The non-empty items of a comma-separated list.
std::vector<std::string> split_list(const std::string& s);
/// The numbers of a comma-separated list; throws Error naming `option` for an item that is not one.
std::vector<double> parse_numbers(const std::string& list, const std::string& option);
/// "bodypoint <argv...>", for output headers.
std::string command_line(int argc, char** argv);

/// Method list from 'all', 'fixed' (every fixed-step method) or comma-separated names.
std::vector<const MethodInfo*> parse_methods(const std::string& list);

}  // namespace bodypoint::cli

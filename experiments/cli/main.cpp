// bodypoint: command-line entry point. Every failure ends in one line on stderr and exit code 2.
#include "process.hpp"
#include "bodypoint/io.hpp"
#include "bodypoint/model.hpp"
#include "budget.hpp"
#include "cli.hpp"
#include "mpi_sweep.hpp"
#include "rows_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <new>
#include <string>
#include <string_view>
#include <unistd.h>

#ifdef BODYPOINT_MPI_PROGRAM
#include <climits>
#include <unistd.h>
#endif

namespace {

constexpr const char* usage =
    "usage: bodypoint <command> [options]\n"
    "commands:\n"
    "  simulate   integrate a scene with one method (default: thesis table 3.1)\n"
    "  methods    list the integration methods\n"
    "  work-precision  final-position error against run time, every method and Boost.Odeint\n"
    "  sweep      vary one parameter, or a grid of several, for a list of methods (CSV; --shard, --resume)\n"
    "  merge      the CSV of a sweep from its shards' rows files\n"
    "  timing     run time against the number of steps (median of repeats)\n"
    "  study      regenerate the thesis's studies (d, L, h, Kx sweeps, timing, table 4.1, appendix 1)\n"
    "  view       write a self-contained HTML page that animates a run in 3D (three.js)\n"
    "Run 'bodypoint <command> --help' for the options of a command; 'bodypoint --version' for the version.";

#ifdef BODYPOINT_MPI_PROGRAM
/// Started by an MPI launcher: hand this process over to the build of the same program with MPI
/// (experiments/CMakeLists.txt), which sits beside this one. Returns only when it is not there.
void exec_mpi_program(char** argv) {
  char self[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) return;
  std::string path(self, static_cast<std::size_t>(n));
  path = path.substr(0, path.rfind('/') + 1) + BODYPOINT_MPI_PROGRAM;
  ::execv(path.c_str(), argv);
}
#endif

/// Standard output is checked like a file: what the command printed is flushed now, and a write that
/// failed (a full disk, a closed pipe, /dev/full) turns the exit code into 2 with one line saying so,
/// so that a cut table is never taken for a whole one.
int checked_stdout(int code) {
  errno = 0;
  std::cout.flush();
  const bool failed = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout) != 0;
  if (!failed) return code;
  const int err = errno;
  std::cerr << "bodypoint: error: standard output could not be written" << (err ? std::string(" (") + std::strerror(err) + ")" : "")
            << ": what was printed is incomplete\n";
  return 2;
}

int run_command(int argc, char** argv);

}  // namespace

int main(int argc, char** argv) { return checked_stdout(run_command(argc, argv)); }

namespace {

int run_command(int argc, char** argv) {
#ifdef BODYPOINT_MPI_PROGRAM
  if (bodypoint::cli::launched_by_mpi()) exec_mpi_program(argv);
#endif
  if (argc < 2) {  // an error: the one-line reason, then the usage, on standard error
    std::cerr << "bodypoint: error: no command given\n" << usage << "\n";
    return 2;
  }
  if (std::strcmp(argv[1], "--version") == 0) {
    std::cout << "bodypoint " << bodypoint::version() << " (revision " << bodypoint::git_revision() << ")\n";
    return 0;
  }
  if (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    std::cout << usage << "\n";
    return 0;
  }
  const std::string cmd = argv[1];
  bodypoint::cli::install_signal_cleanup(bodypoint::cli::launcher_rank() == 0);
  try {
    // Every process of an MPI launch runs the same command line: only sweep shares its runs among them,
    // any other command would run N times over, its outputs colliding.
    if (bodypoint::cli::launched_by_mpi() && cmd != "sweep")
      throw bodypoint::Error(cmd + " runs in one process: under an MPI launcher (more than one process) only sweep "
                             "shares its runs among the processes; start it without mpirun, or with -np 1");
    // A command at work for more than kNoticeSeconds says so in one line, where no progress bar does
    // (simulate draws its own on a terminal); --quiet and CI keep stderr for errors.
    bool quiet = false;
    for (int i = 2; i < argc; ++i) quiet = quiet || std::strcmp(argv[i], "--quiet") == 0 || std::strcmp(argv[i], "--help") == 0;
    const bool bar = cmd == "simulate" && ::isatty(2) == 1;
    const bodypoint::cli::WorkingNotice notice(cmd, bodypoint::cli::launcher_rank() == 0 && !bar &&
                                                        bodypoint::cli::notice_wanted(quiet));
    if (cmd == "simulate") return bodypoint::cli::cmd_simulate(argc - 1, argv + 1);
    if (cmd == "methods") return bodypoint::cli::cmd_methods(argc - 1, argv + 1);
    if (cmd == "work-precision") return bodypoint::cli::cmd_work_precision(argc - 1, argv + 1);
    if (cmd == "sweep") return bodypoint::cli::cmd_sweep(argc - 1, argv + 1);
    if (cmd == "merge") return bodypoint::cli::cmd_merge(argc - 1, argv + 1);
    if (cmd == "timing") return bodypoint::cli::cmd_timing(argc - 1, argv + 1);
    if (cmd == "study") return bodypoint::cli::cmd_study(argc - 1, argv + 1);
    if (cmd == "view") return bodypoint::cli::cmd_view(argc - 1, argv + 1);
    std::cerr << "bodypoint: error: unknown command '" << cmd << "' (simulate, methods, work-precision, sweep, merge, timing, study, view)\n";
    return 2;
  } catch (const std::bad_alloc&) {  // its what() is "std::bad_alloc"
    if (bodypoint::cli::launcher_rank() == 0)
      std::cerr << "bodypoint: error: out of memory: the request needs more memory than this process may have "
                   "(fewer points, frames, rows or threads)\n";
  } catch (const std::exception& e) {  // bodypoint::Error, boost::program_options::error and the rest
    if (bodypoint::cli::launcher_rank() == 0) std::cerr << "bodypoint: error: " << bodypoint::one_line(e.what()) << "\n";
  }
  return 2;
}

}  // namespace

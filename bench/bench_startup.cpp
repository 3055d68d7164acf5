// Start-up of the command line (issue #26): wall time of one process from spawn to exit, for the
// plain program beside it (startup_plain.cpp: a C++ main linked with the standard library only) and
// for short bodypoint commands. A user or a script that runs many short simulations pays this on
// every call; the target is bodypoint within ~2 ms of the plain program.
// Run: build/bin/bench_startup --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// and compare the medians of one run.
#include <benchmark/benchmark.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdexcept>
#include <string>
#include <vector>

extern char** environ;

namespace {

/// Spawns argv with stdout and stderr on /dev/null and waits for it; throws unless it exits 0.
void run_process(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (err != 0) throw std::runtime_error("cannot start " + args[0]);
  int status = 0;
  if (waitpid(pid, &status, 0) != pid || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error(args[0] + " failed");
}

void BM_Process(benchmark::State& state, std::vector<std::string> args) {
  for (auto _ : state) run_process(args);
}

const std::string kBin = BODYPOINT_BIN_DIR;

BENCHMARK_CAPTURE(BM_Process, plain, std::vector<std::string>{kBin + "/startup_plain"})->UseRealTime();
BENCHMARK_CAPTURE(BM_Process, help, std::vector<std::string>{kBin + "/bodypoint", "--help"})->UseRealTime();
BENCHMARK_CAPTURE(BM_Process, simulate_help, std::vector<std::string>{kBin + "/bodypoint", "simulate", "--help"})
    ->UseRealTime();
// A 7-microsecond run as a process: the exact ks flow of the material point for t = 1.
BENCHMARK_CAPTURE(BM_Process, simulate_ks,
                  std::vector<std::string>{kBin + "/bodypoint", "simulate", "--method", "ks", "--B", "0", "--h", "1",
                                           "--t-end", "1", "--quiet", "--json"})
    ->UseRealTime();
#ifdef BODYPOINT_HAVE_MPI_PROGRAM
// The same binary with Open MPI linked, as every command loaded it before the split.
BENCHMARK_CAPTURE(BM_Process, help_with_mpi_linked, std::vector<std::string>{kBin + "/bodypoint-mpi", "--help"})
    ->UseRealTime();
#endif

}  // namespace

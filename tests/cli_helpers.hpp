// Running the bodypoint command line from a test: exit code, standard output, standard error.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

namespace bodypoint::test {

struct CliResult {
  int code;
  std::string out, err;
};

/// Runs `bodypoint ARGS` (no terminal, no standard input).
inline CliResult run_cli(const std::string& args) {
  namespace fs = std::filesystem;
  const fs::path err = fs::temp_directory_path() / ("bp_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = std::string(BODYPOINT_BIN) + " " + args + " 2>" + err.string() + " </dev/null";
  CliResult r;
  FILE* p = ::popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), p)) r.out += buf.data();
  const int status = ::pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream e(err);
  std::stringstream ss;
  ss << e.rdbuf();
  r.err = ss.str();
  fs::remove(err);
  return r;
}

}  // namespace bodypoint::test

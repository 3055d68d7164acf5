// Running the bodypoint command line from a test: exit code, standard output, standard error; or
// started in the background (spawn) to be signalled; and the files a run leaves.
#pragma once

#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fcntl.h>
#include <fstream>
#include <spawn.h>
#include <sstream>
#include <string>
#include <utility>
#include <vector>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace bodypoint::test {

/// A path for a test's files in this process's own folder under the system's temporary directory
/// (removed at exit): two suites running at once (a developer's and CI's) never share a file.
inline std::filesystem::path temp_path(const std::string& name) {
  struct Root {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("bodypoint-tests." + std::to_string(::getpid()));
    Root() { std::filesystem::create_directories(path); }
    ~Root() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Root root;
  return root.path / name;
}

/// A fresh folder under temp_path(name), removed with everything in it when the test ends.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) : path(temp_path(name)) {
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

struct CliResult {
  int code;
  std::string out, err;
};

/// Runs `bodypoint ARGS` (no terminal, no standard input), under CI=1: a command slowed by a busy machine
/// past kNoticeSeconds would otherwise add its "working" line to the stderr a test reads.
inline CliResult run_cli(const std::string& args) {
  namespace fs = std::filesystem;
  const fs::path err = fs::temp_directory_path() / ("bp_cli_err_" + std::to_string(::getpid()));
  const std::string cmd = "CI=1 " + std::string(BODYPOINT_BIN) + " " + args + " 2>" + err.string() + " </dev/null";
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

/// Runs `bodypoint PREFIX ARGS` for each (ARGS, FRAGMENT): each must fail, say FRAGMENT on stderr and
/// print nothing on stdout.
inline void expect_refused(const std::string& prefix, const std::vector<std::pair<std::string, std::string>>& cases) {
  for (const auto& [args, fragment] : cases) {
    const CliResult r = run_cli(prefix + args);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_NE(r.err.find(fragment), std::string::npos) << args << " -> " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

namespace fs = std::filesystem;

/// Files in dir whose name starts with `stem` (the output, its temporaries, its lock).
inline std::vector<std::string> leftovers(const fs::path& dir, const std::string& stem) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind(stem, 0) == 0) out.push_back(e.path().filename().string());
  return out;
}

/// Starts `bodypoint args...` with stderr to err_file; returns its pid.
inline pid_t spawn(const std::vector<std::string>& args, const fs::path& err_file) {
  std::vector<std::string> all{BODYPOINT_BIN};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

inline std::string read(const fs::path& p) {
  std::ifstream in(p);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Fields of one CSV line with double-quoted fields (no quotes inside them).
inline std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out(1);
  bool quoted = false;
  for (const char c : line) {
    if (c == '"') quoted = !quoted;
    else if (c == ',' && !quoted) out.emplace_back();
    else out.back() += c;
  }
  return out;
}

}  // namespace bodypoint::test

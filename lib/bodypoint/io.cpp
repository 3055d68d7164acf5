#include "bodypoint/io.hpp"

#include <algorithm>

#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <limits>
#include <mutex>
#include <set>
#include <signal.h>
#include <sstream>
#include <unistd.h>
#include <vector>

#ifndef BODYPOINT_GIT_REVISION
#define BODYPOINT_GIT_REVISION "unknown"
#endif

namespace bodypoint {

namespace {

// Files to remove when a signal arrives, in storage the handler can read without locking or
// allocating: kSlots fixed buffers, each claimed by one open AtomicFile.
constexpr int kSlots = 64;
constexpr std::size_t kPathMax = 4096;
struct Slot {
  std::atomic<bool> used{false};
  char tmp[kPathMax];
  char lock[kPathMax];
};
Slot g_slots[kSlots];
std::atomic<int> g_signal{0};
std::atomic<int> g_cooperative{0};
std::atomic<long> g_counter{0};

std::mutex g_paths_mutex;
std::set<std::string> g_outputs, g_inputs;  // weakly canonical paths

std::string key_of(const std::string& path) {
  std::error_code ec;
  const std::filesystem::path p = std::filesystem::weakly_canonical(std::filesystem::absolute(path, ec), ec);
  return ec ? path : p.string();
}

int claim_slot(const std::string& tmp, const std::string& lock) {
  if (tmp.size() >= kPathMax || lock.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_slots[i].used.load() || !g_slots[i].used.compare_exchange_strong(expected, true)) continue;
    std::memcpy(g_slots[i].tmp, tmp.c_str(), tmp.size() + 1);
    std::memcpy(g_slots[i].lock, lock.c_str(), lock.size() + 1);
    return i;
  }
  return -1;
}

extern "C" void on_signal(int sig) {
  g_signal.store(sig);
  if (g_cooperative.load() > 0) return;
  for (Slot& s : g_slots)
    if (s.used.load()) {
      ::unlink(s.tmp);
      ::unlink(s.lock);
    }
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

/// True when a process with this pid exists (a lock whose writer has died is stale).
bool process_alive(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

/// Removes "<target>.tmp.<pid>.*", the temporaries a writer killed without cleanup (kill -9) left.
void remove_temporaries(const std::string& target, long pid) {
  namespace fs = std::filesystem;
  const fs::path t(target);
  const std::string prefix = t.filename().string() + ".tmp." + std::to_string(pid) + ".";
  std::error_code ec;
  const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->path().filename().string().rfind(prefix, 0) == 0) fs::remove(it->path(), ec);
}

/// Creates path exclusively with our pid in it; a stale lock (its writer is gone) is replaced once.
void take_lock(const std::string& lock, const std::string& target) {
  for (int attempt = 0; attempt < 2; ++attempt) {
    const int fd = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
    if (fd >= 0) {
      const std::string pid = std::to_string(::getpid()) + "\n";
      const bool ok = ::write(fd, pid.data(), pid.size()) == static_cast<ssize_t>(pid.size());
      ::close(fd);
      if (!ok) {
        ::unlink(lock.c_str());
        throw Error("cannot write output file '" + target + "' (writing its lock file failed)");
      }
      return;
    }
    if (errno != EEXIST) throw Error("cannot write output file '" + target + "' (directory missing or not writable)");
    std::ifstream in(lock);
    long pid = 0;
    in >> pid;
    if (process_alive(pid))
      throw Error("another run (pid " + std::to_string(pid) + ") is writing '" + target + "' (lock file " + lock +
                  "); wait for it or choose another path");
    // Stale: its writer is gone (kill -9, power loss), so are its temporaries. They go first: killed
    // between the two, this run leaves the lock that names them for the next run to clean up (the
    // other order orphaned a temporary that no lock names; ASan's slow start made that window real).
    remove_temporaries(target, pid);
    ::unlink(lock.c_str());
  }
  throw Error("cannot take the lock file " + lock + " of '" + target + "'");
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  if (path_.empty()) throw Error("output path is empty");
  key_ = key_of(path_);
  {
    std::lock_guard<std::mutex> g(g_paths_mutex);
    if (g_inputs.count(key_)) throw Error("output '" + path_ + "' is an input of this run; choose another path");
    if (g_outputs.count(key_)) throw Error("two outputs of this run write '" + path_ + "'; give them different paths");
    g_outputs.insert(key_);
  }
  tmp_ = path_ + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(g_counter.fetch_add(1));
  lock_ = path_ + ".lock";
  try {
    take_lock(lock_, path_);
  } catch (...) {
    std::lock_guard<std::mutex> g(g_paths_mutex);
    g_outputs.erase(key_);
    throw;
  }
  slot_ = claim_slot(tmp_, lock_);
  out_.open(tmp_, std::ios::out | std::ios::trunc);
  if (!out_) {
    release();
    throw Error("cannot write output file '" + path_ + "' (directory missing or not writable)");
  }
}

void AtomicFile::release() noexcept {
  if (out_.is_open()) out_.close();
  if (!committed_) std::remove(tmp_.c_str());
  ::unlink(lock_.c_str());
  if (slot_ >= 0) g_slots[slot_].used.store(false);
  slot_ = -1;
  std::lock_guard<std::mutex> g(g_paths_mutex);
  g_outputs.erase(key_);
}

AtomicFile::~AtomicFile() {
  if (slot_ >= 0 || !committed_) release();
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) throw Error("writing '" + path_ + "' failed (disk full?)");
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
    throw Error("cannot move the finished output onto '" + path_ + "'");
  committed_ = true;
  release();
}

void register_input(const std::string& path) {
  std::lock_guard<std::mutex> g(g_paths_mutex);
  g_inputs.insert(key_of(path));
}

void install_signal_cleanup() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &sa, nullptr);
}

int interrupted() { return g_signal.load(); }

CooperativeInterrupt::CooperativeInterrupt() { g_cooperative.fetch_add(1); }
CooperativeInterrupt::~CooperativeInterrupt() { g_cooperative.fetch_sub(1); }
void CooperativeInterrupt::check() {
  if (const int sig = g_signal.load()) throw Error("interrupted by signal " + std::to_string(sig) + "; no output written");
}

std::string fmt(double x) {
  // Shortest representation that reads back to the same double (0.7, not 0.69999999999999996).
  if (std::isnan(x)) return "nan";  // not "-nan": the sign of a NaN means nothing
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

CsvLine& CsvLine::quoted(std::string s) {
  std::replace(s.begin(), s.end(), '"', '\'');
  return add('"' + s + '"');
}

std::string json_number(double x) { return std::isfinite(x) ? fmt(x) : "null"; }

std::string json_vec(const Vec3& v) {
  std::ostringstream os;
  os << '[' << json_number(v.x()) << ", " << json_number(v.y()) << ", " << json_number(v.z()) << ']';
  return os.str();
}

std::string json_string(std::string_view s, bool html_safe) {
  std::string out = "\"";
  for (const unsigned char c : s) {
    if (c == '"' || c == '\\' || c < 0x20 || (html_safe && (c == '<' || c == '>' || c == '&'))) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const bool same =
          std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
      const std::size_t next = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = row[j];
      row[j] = next;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string closest_word(std::string_view word, const std::vector<std::string>& candidates, std::size_t max_edits) {
  std::string best;
  std::size_t best_d = max_edits + 1;
  for (const std::string& c : candidates)
    if (const std::size_t d = edit_distance(word, c); d < best_d) {
      best_d = d;
      best = c;
    }
  return best;
}

const char* git_revision() { return BODYPOINT_GIT_REVISION; }

}  // namespace bodypoint

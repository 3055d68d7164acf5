// bodypoint command line: atomic outputs, locks, signals and the deadline (process.hpp).
#include "process.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fcntl.h>
#include <filesystem>
#include <limits>
#include <mutex>
#include <set>
#include <signal.h>
#include <sstream>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>
#include <vector>

namespace bodypoint::cli {

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
std::atomic<bool> g_say_signal{true};  ///< install_signal_cleanup(say)
std::atomic<int> g_cooperative{0};
std::atomic<long> g_counter{0};
// The budget (set_deadline): its end on CLOCK_MONOTONIC (a SIGALRM from outside before it is a signal
// like any other) and its message, formatted beforehand for the handler.
std::atomic<bool> g_deadline{false};
std::atomic<long long> g_deadline_ns{0};
char g_deadline_message[512];
/// The budget's message takes its tail when it is said: whether a journal keeps the finished work then.
std::atomic<bool> g_deadline_tail{false};
std::atomic<bool> g_journal_open{false};  ///< note_journal()
constexpr char kJournalTail[] = "; what finished so far is in the journal, finish with --resume\n";
constexpr char kNoOutputTail[] = "; no output written\n";

long long monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);  // async-signal-safe
  return static_cast<long long>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec;
}

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

void remove_open_outputs() {
  for (Slot& s : g_slots)
    if (s.used.load()) {
      ::unlink(s.tmp);
      ::unlink(s.lock);
    }
}

/// How long a loop that stops at its own boundary (a sweep's row) may take after the first signal.
constexpr unsigned kInterruptGraceSeconds = 1;

/// From a signal handler: after kInterruptGraceSeconds the deadline path ends the process with a line
/// saying why (only async-signal-safe calls: the message is composed by hand, alarm() arms the timer).
void arm_interrupt_grace(int sig) {
  static constexpr char kHead[] = "bodypoint: error: interrupted by signal ";
  const char* const kTail = g_journal_open.load() ? kJournalTail : kNoOutputTail;
  g_deadline_tail = false;
  std::size_t n = 0;
  for (const char* c = kHead; *c && n + 1 < sizeof g_deadline_message; ++c) g_deadline_message[n++] = *c;
  char digits[12];
  int k = 0;
  for (int x = sig; x > 0 && k < 11; x /= 10) digits[k++] = static_cast<char>('0' + x % 10);
  while (k > 0 && n + 1 < sizeof g_deadline_message) g_deadline_message[n++] = digits[--k];
  for (const char* c = kTail; *c && n + 1 < sizeof g_deadline_message; ++c) g_deadline_message[n++] = *c;
  g_deadline_message[n] = '\0';
  g_deadline_ns.store(monotonic_ns() + static_cast<long long>(kInterruptGraceSeconds) * 1'000'000'000LL - 1'000'000);
  g_deadline.store(true);
  ::alarm(kInterruptGraceSeconds);
}

/// From a signal handler that ends the process by the signal: one line saying so (a SIGINT while a
/// large grid was checked ended it with exit 130 and no word). Async-signal-safe: composed by hand.
void say_interrupted(int sig) {
  // A closed pipe (`bodypoint methods | head -1`) ends the process as it ends every filter: silently.
  if (!g_say_signal.load() || sig == SIGPIPE) return;
  static constexpr char kHead[] = "bodypoint: error: interrupted by signal ";
  static constexpr char kTail[] = "; its unfinished outputs removed\n";
  char line[sizeof kHead + sizeof kTail + 12];
  std::size_t n = 0;
  for (const char* c = kHead; *c; ++c) line[n++] = *c;
  char digits[12];
  int k = 0;
  for (int x = sig; x > 0 && k < 11; x /= 10) digits[k++] = static_cast<char>('0' + x % 10);
  while (k > 0) line[n++] = digits[--k];
  for (const char* c = kTail; *c; ++c) line[n++] = *c;
  const ssize_t written = ::write(2, line, n);
  (void)written;
}

extern "C" void on_signal(int sig) {
  if (sig == SIGALRM && g_deadline.load() && monotonic_ns() >= g_deadline_ns.load()) {  // the budget: stop now, wherever the process is
    remove_open_outputs();
    ssize_t n = ::write(2, g_deadline_message, std::strlen(g_deadline_message));
    if (g_deadline_tail) {  // the budget's line (the grace's has its own tail)
      const char* tail = g_journal_open.load() ? kJournalTail : kNoOutputTail;
      n = ::write(2, tail, std::strlen(tail));
    }
    (void)n;
    ::_exit(2);
  }
  // A loop that stops at a boundary of its own (a sweep's row) gets one signal and a grace of
  // kInterruptGraceSeconds to do so; then, or at a second signal, the process stops at once, its
  // finished rows kept in the journal.
  const int before = g_signal.exchange(sig);
  if (g_cooperative.load() > 0 && before == 0) {
    arm_interrupt_grace(sig);
    return;
  }
  remove_open_outputs();
  say_interrupted(sig);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

/// True for "<digits>.<digits>", the tail of a temporary's name after ".tmp." (pid and counter).
bool pid_and_counter(std::string_view rest) {
  auto digits = [](std::string_view x) {
    return !x.empty() && std::all_of(x.begin(), x.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  const std::size_t dot = rest.find('.');
  return dot != std::string_view::npos && digits(rest.substr(0, dot)) && digits(rest.substr(dot + 1));
}

/// Removes "<stem>.tmp.<digits>.<digits>", temporaries of writers that died without cleanup (kill -9,
/// power loss). Called by the holder of the target's lock: every writer holds the lock for as long as its
/// temporary exists, so no live writer owns one of these.
void remove_orphaned_temporaries(const std::string& stem) {
  namespace fs = std::filesystem;
  const fs::path t(stem);
  const std::string prefix = t.filename().string() + ".tmp.";
  auto ours = [&](const std::string& name) { return name.rfind(prefix, 0) == 0 && pid_and_counter(name.substr(prefix.size())); };
  std::error_code ec;
  const fs::path dir = t.has_parent_path() ? t.parent_path() : fs::path(".");
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (ours(it->path().filename().string()) && it->is_regular_file(ec)) fs::remove(it->path(), ec);
}

/// The pid a lock file names ("" when it names none yet: its writer locks before it writes the pid).
std::string lock_holder(int fd) {
  char buf[32] = {};
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  std::string pid(buf, n > 0 ? static_cast<std::size_t>(n) : 0);
  while (!pid.empty() && (pid.back() == '\n' || pid.back() == ' ')) pid.pop_back();
  return std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; }) ? pid : std::string();
}

/// Takes the target's lock: an flock on "<target>.lock", which the kernel holds for exactly as long as
/// the writer lives (kill -9 releases it; no pid is ever guessed, so a lock file left behind, empty or
/// naming any pid of any namespace, is simply taken). A writer removes the lock file before it lets go of
/// the lock, so a writer that locked a file just removed finds another inode at the path and tries again.
/// Returns the lock's descriptor.
int take_lock(const std::string& lock, const std::string& target, const std::string& stem) {
  constexpr int kAttempts = 1000;  // each retry means another writer finished in between
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    const int fd = ::open(lock.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0644);
    if (fd < 0) {
      if (errno == ELOOP) throw Error("the lock file " + lock + " of '" + target + "' is a symbolic link; remove it");
      throw Error("cannot write output file '" + target + "' (directory missing or not writable)");
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
      const int e = errno;
      const std::string pid = lock_holder(fd);
      ::close(fd);
      if (e == EWOULDBLOCK)
        throw Error("another run" + (pid.empty() ? std::string() : " (pid " + pid + ")") + " is writing '" + target +
                    "' (lock file " + lock + "); wait for it or choose another path");
      throw Error("cannot lock '" + target + "' (" + std::strerror(e) + ")");
    }
    struct stat held {}, named {};
    if (::fstat(fd, &held) == 0 && ::stat(lock.c_str(), &named) == 0 && held.st_dev == named.st_dev &&
        held.st_ino == named.st_ino) {
      const std::string pid = std::to_string(::getpid()) + "\n";
      if (::ftruncate(fd, 0) != 0 || ::pwrite(fd, pid.data(), pid.size(), 0) != static_cast<ssize_t>(pid.size())) {
        ::unlink(lock.c_str());
        ::close(fd);
        throw Error("cannot write output file '" + target + "' (writing its lock file failed)");
      }
      remove_orphaned_temporaries(stem);
      return fd;
    }
    ::close(fd);  // the file we locked was removed by its finishing writer: lock the new one
  }
  throw Error("cannot take the lock file " + lock + " of '" + target + "'");
}

/// A file name at most this long keeps its whole name in its temporary's and lock's names; a longer
/// one (up to the 255 bytes a name may have) is cut to it, so that those names fit too.
constexpr std::size_t kMaxStem = 255 - 32;

/// The path the temporaries and the lock of target are named after: target, its file name cut to kMaxStem.
std::string stem_of(const std::string& target) {
  const std::filesystem::path t(target);
  const std::string name = t.filename().string();
  if (name.size() <= kMaxStem) return target;
  return (t.parent_path() / name.substr(0, kMaxStem)).string();
}

/// Where an output path leads: the regular file (or the place of a new one) that a symbolic link
/// names, followed link by link, so that the link stays and its target is replaced.
/// The path and every symbolic link's target on the way to what it names, in order.
std::vector<std::string> link_chain(const std::string& path) {
  namespace fs = std::filesystem;
  fs::path p(path);
  std::vector<std::string> chain{p.string()};
  for (int hop = 0; hop < 40; ++hop) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return chain;
    std::error_code ec;
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) throw Error("cannot read the symbolic link '" + p.string() + "': " + ec.message());
    p = to.is_absolute() ? to : p.parent_path() / to;
    chain.push_back(p.string());
  }
  throw Error("output '" + path + "' is a loop of symbolic links");
}

/// What a path names in the end, its links followed.
std::string resolve_links(const std::string& path) { return link_chain(path).back(); }

/// True when `path`, or a link on the way to what it names, is an open descriptor of a process
/// (/dev/stdout, /dev/fd/N, /proc/PID/fd/N): the stream a shell opened, for `--out /dev/stdout >> log`.
bool through_descriptor(const std::string& path) {
  auto descriptor = [](const std::string& link) {
    const std::string p = std::filesystem::path(link).lexically_normal().string();
    if (p == "/dev/stdout" || p == "/dev/stderr" || p.rfind("/dev/fd/", 0) == 0) return true;
    const std::size_t fd = p.find("/fd/");
    return p.rfind("/proc/", 0) == 0 && fd != std::string::npos && p.find('/', fd + 4) == std::string::npos;
  };
  const std::vector<std::string> chain = link_chain(path);
  return std::any_of(chain.begin(), chain.end(), descriptor);
}

}  // namespace

void note_journal(bool open) { g_journal_open.store(open); }

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  if (path_.empty()) throw Error("output path is empty");
  if (path_ == "-")
    throw Error("output '-': the command prints its report on standard output, so data cannot go there; give a file name");
  if (std::any_of(path_.begin(), path_.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; }))
    throw Error("output path contains a control character (a newline or tab); choose another name");
  // What the path names: a regular file (or nothing yet) is replaced atomically; a FIFO or character
  // device (/dev/null, /dev/stdout, a pipe) is written directly and never replaced; anything else is refused.
  struct stat st {};
  if (::stat(path_.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) throw Error("output '" + path_ + "' is a directory; give a file name");
    if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) {
      open_direct(S_ISFIFO(st.st_mode), false);
      return;
    }
    // A regular file reached through a process's descriptor (--out /dev/stdout >> log.txt) is the
    // shell's stream: appended to in place, never replaced (its earlier contents stay).
    if (S_ISREG(st.st_mode) && through_descriptor(path_)) {
      open_direct(false, true);
      return;
    }
    if (!S_ISREG(st.st_mode)) throw Error("output '" + path_ + "' is neither a regular file, a FIFO nor a character device");
  } else if (errno != ENOENT && errno != ENOTDIR) {
    throw Error("cannot write output file '" + path_ + "' (" + std::strerror(errno) + ")");
  }
  target_ = resolve_links(path_);
  // The names of the writer's and the sweeps' own files: an output there would replace a live lock or
  // journal of another run (or be removed by it as an orphan).
  {
    const std::string name = std::filesystem::path(target_).filename().string();
    auto ends = [&](std::string_view tail) { return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0; };
    const std::size_t tmp = name.rfind(".tmp.");
    if (ends(".lock") || ends(".journal") || (tmp != std::string::npos && pid_and_counter(std::string_view(name).substr(tmp + 5))))
      throw Error("output '" + path_ + "': names ending in .lock, .journal or .tmp.<pid>.<n> are bodypoint's own files; choose another name");
  }
  key_ = key_of(target_);
  {
    std::lock_guard<std::mutex> g(g_paths_mutex);
    if (g_inputs.count(key_)) throw Error("output '" + path_ + "' is an input of this run; choose another path");
    if (g_outputs.count(key_)) throw Error("two outputs of this run write '" + path_ + "'; give them different paths");
    g_outputs.insert(key_);
  }
  const std::string stem = stem_of(target_);
  tmp_ = stem + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(g_counter.fetch_add(1));
  lock_ = stem + ".lock";
  try {
    lock_fd_ = take_lock(lock_, path_, stem);
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

void AtomicFile::open_direct(bool fifo, bool append) {
  direct_ = true;
  int probe = -1;
  if (fifo) {
    // Opening a FIFO for writing waits for a reader; without one, say so instead of waiting forever.
    // The probe stays open until the stream is, so the reader never sees the FIFO without a writer.
    probe = ::open(path_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (probe < 0)
      throw Error(errno == ENXIO ? "output '" + path_ + "' is a FIFO that nobody reads; start its reader first"
                                 : "cannot write output file '" + path_ + "' (" + std::strerror(errno) + ")");
  }
  out_.open(path_, append ? std::ios::app : std::ios::out);
  if (probe >= 0) ::close(probe);
  if (!out_) throw Error("cannot write output file '" + path_ + "' (" + std::strerror(errno) + ")");
}

void AtomicFile::release() noexcept {
  if (out_.is_open()) out_.close();
  if (direct_) return;
  if (!committed_) std::remove(tmp_.c_str());
  if (slot_ >= 0) g_slots[slot_].used.store(false);
  slot_ = -1;
  if (lock_fd_ >= 0) {
    ::unlink(lock_.c_str());  // before the lock is let go: see take_lock
    ::close(lock_fd_);
    lock_fd_ = -1;
  }
  std::lock_guard<std::mutex> g(g_paths_mutex);
  g_outputs.erase(key_);
}

AtomicFile::~AtomicFile() {
  if (slot_ >= 0 || lock_fd_ >= 0 || !committed_) release();
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) throw Error("writing '" + path_ + "' failed (disk full or file size limit?)");
  if (!direct_ && std::rename(tmp_.c_str(), target_.c_str()) != 0)
    throw Error("cannot move the finished output onto '" + path_ + "' (" + std::strerror(errno) + ")");
  committed_ = true;
  release();
}

void register_input(const std::string& path) {
  std::lock_guard<std::mutex> g(g_paths_mutex);
  g_inputs.insert(key_of(path));
}

void install_signal_cleanup(bool say) {
  g_say_signal.store(say);
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF, SIGPIPE})
    ::sigaction(sig, &sa, nullptr);
  // Past `ulimit -f` a write fails (EFBIG) and the output's commit reports it, instead of the default
  // SIGXFSZ ending the process with its temporary and lock in place.
  ::signal(SIGXFSZ, SIG_IGN);
}

int interrupted() { return g_signal.load(); }

void set_deadline(double seconds, const std::string& what) {
  if (!(seconds > 0.0) || !std::isfinite(seconds) || seconds > 1e9) return;
  std::snprintf(g_deadline_message, sizeof g_deadline_message, "bodypoint: error: %s", what.c_str());
  g_deadline_tail = true;
  g_deadline_ns.store(monotonic_ns() + static_cast<long long>(seconds * 1e9) - 1'000'000);  // the timer's slack
  g_deadline.store(true);
  itimerval t{};
  t.it_value.tv_sec = static_cast<time_t>(seconds);
  t.it_value.tv_usec = static_cast<suseconds_t>((seconds - std::floor(seconds)) * 1e6);
  if (t.it_value.tv_sec == 0 && t.it_value.tv_usec == 0) t.it_value.tv_usec = 1;
  ::setitimer(ITIMER_REAL, &t, nullptr);
}

CooperativeInterrupt::CooperativeInterrupt() { g_cooperative.fetch_add(1); }
CooperativeInterrupt::~CooperativeInterrupt() { g_cooperative.fetch_sub(1); }
void CooperativeInterrupt::check() {
  if (const int sig = g_signal.load()) {
    // Stopped at its boundary within the grace: the process unwinds and says so itself.
    g_deadline.store(false);
    const itimerval off{};
    ::setitimer(ITIMER_REAL, &off, nullptr);
    std::string tail = g_journal_open.load() ? kJournalTail : kNoOutputTail;
    tail.pop_back();  // the newline
    throw Error("interrupted by signal " + std::to_string(sig) + tail);
  }
}

}  // namespace bodypoint::cli

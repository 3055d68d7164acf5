// bodypoint command line: writing outputs safely, and the process's signals and budget of time.
//
// `AtomicFile` writes to a temporary file beside the target and renames it over the target on
// commit(), so a failed or interrupted run never leaves a half-written result: each output has its
// own temporary name, an flock on <target>.lock (which names the writer's pid) refuses a second writer
// of the same path for as long as the first lives (kill -9 releases it; the next writer removes the
// temporaries it left), an output that is another output or an input of the same run is refused, and
// the terminating signals remove every temporary and lock file (install_signal_cleanup). Only a regular
// file is ever replaced: a symbolic link's target is replaced and the link kept, a FIFO or character
// device (/dev/null, /dev/stdout) is written directly, a regular file reached through a process's
// descriptor (/dev/stdout or /dev/fd/N redirected to a file) is appended to in place, a directory or
// anything else is refused before any work.
#pragma once

#include "bodypoint/model.hpp"

#include <fstream>
#include <string>

namespace bodypoint::cli {

class AtomicFile {
 public:
  /// Opens "<target>.tmp.<pid>.<n>" for writing (or, for a FIFO or device, the path itself); throws
  /// Error if that is impossible (missing directory, no permission, a directory, a FIFO nobody reads),
  /// before any computation has been spent.
  explicit AtomicFile(std::string path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  std::ofstream& stream() { return out_; }
  /// Flushes, closes and renames onto the target path; throws Error on any failure.
  void commit();
  /// True when the output is a FIFO, a device or a process's open stream, written directly (nothing to
  /// resume from).
  [[nodiscard]] bool direct() const { return direct_; }

 private:
  void release() noexcept;
  void open_direct(bool fifo, bool append);

  std::string path_, target_, tmp_, lock_, key_;
  std::ofstream out_;
  bool committed_ = false, direct_ = false;
  int slot_ = -1, lock_fd_ = -1;
};

/// Records a file this run reads (a scene file), so that no output of the run may replace it.
void register_input(const std::string& path);

/// Installs handlers for the terminating signals (SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1/2, SIGALRM,
/// SIGVTALRM, SIGPROF, SIGPIPE; SIGXFSZ is ignored, so a write past the size limit fails) that remove the temporary and lock files of every
/// open AtomicFile and then end the process with the signal (exit status 128 + signal). While a
/// `CooperativeInterrupt` is alive the handler records the first signal, so that a loop can stop at a
/// boundary of its own (a sweep's row) and unwind normally; a loop that has not stopped a second later
/// is ended there, with its one-line reason and exit status 2 (the journal keeps the finished rows).
/// `say`: a signal that ends the process is said on stderr in one line (false on an MPI launch's ranks
/// other than 0, which the launcher ends when one of them fails).
void install_signal_cleanup(bool say = true);

/// The signal received since install_signal_cleanup(), or 0.
int interrupted();

/// Whether a journal of finished rows is open (RowJournal): what the line of an interrupted loop says
/// (a sweep to standard output has none: "no output written", not "finish with --resume").
void note_journal(bool open);

/// The whole process's budget of wall-clock time (--max-seconds of every command): when it has passed,
/// every loop (runs, the accuracy search, the reference, peers' steppers, timing repeats, a sweep's row)
/// is stopped alike, by SIGALRM: the temporary and lock files go, "<what>" is printed as the one-line
/// error and the process exits with status 2 (a sweep's journal keeps its finished rows for --resume).
/// seconds <= 0 or infinite: no budget. Needs install_signal_cleanup().
void set_deadline(double seconds, const std::string& what);

class CooperativeInterrupt {
 public:
  CooperativeInterrupt();
  ~CooperativeInterrupt();
  CooperativeInterrupt(const CooperativeInterrupt&) = delete;
  CooperativeInterrupt& operator=(const CooperativeInterrupt&) = delete;
  /// Throws Error("interrupted by signal N") when a signal has arrived.
  static void check();
};

}  // namespace bodypoint::cli

// bodypoint: a sweep's rows as durable records, for resuming an interrupted sweep and for merging
// the shards of one sweep run on several machines.
//
// A rows file is text, one record per line:
//   #bodypoint-rows 1 key=<B>-<S>-<Q> tasks=<T>       first line: which sweep (key: 16 hex digits each of
//                                                      its build, scene file and request) and its size
//   H\t<line>\t<check>                                 the CSV header of the sweep, line by line
//   R\t<task index>\t<CSV row>\t<check>                 one finished row; check = FNV-1a of the rest
// Two different rows under one task index are refused (an edited or mixed file), the same row twice
// (a resumed run that redid it) is one row.
// A journal (<out>.journal) is appended one record per finished row, each in one write() at the row's
// boundary, so after a kill -9 it holds every row that finished (the page cache outlives the process).
// fsync runs at row boundaries too, at most every kSyncInterval and when the journal closes, so a
// power loss costs at most the rows of the last interval, which a resumed run computes again; a torn
// last line is cut off and every record carries a checksum, so no row is ever read half-written. A shard's output (--shard K/N) is the same format, written atomically.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace bodypoint::cli {

/// FNV-1a, 64 bits.
std::uint64_t fnv1a(const std::string& s, std::uint64_t h = 1469598103934665603ull);
std::string hex64(std::uint64_t x);

/// A sweep's key: its build's revision, its scene file's text and the rest of its request, hashed apart so
/// that a journal of another sweep says which of them changed (key_difference).
std::string sweep_key_of(const std::string& revision, const std::string& scene_text, const std::string& request);
/// What differs between two sweeps' keys, in words ("the scene file was edited"); for a key of another
/// format, "another sweep".
std::string key_difference(const std::string& was, const std::string& is);

/// The rows of one sweep gathered from rows files.
struct RowsContent {
  std::string key;
  std::size_t tasks = 0;
  std::vector<std::string> header;          ///< the CSV header lines
  std::map<std::size_t, std::string> rows;  ///< task index -> CSV row
};

/// Reads a rows file; a torn or corrupt record is dropped (counted in *dropped when given). Throws
/// Error when the file cannot be read or is not a rows file.
RowsContent read_rows_file(const std::string& path, std::size_t* dropped = nullptr);

/// The text of a rows file holding `c`.
std::string rows_file_text(const RowsContent& c);

/// The journal of a running sweep: opened for append (created when missing; a torn last line is
/// cut off first), one record written and fsync'ed per row. Thread-safe.
class RowJournal {
 public:
  /// Creates or continues the journal at `path` for the sweep `key` of `tasks` rows. With
  /// resume = false an existing journal is refused (it belongs to an interrupted run); with resume =
  /// true its rows are loaded (a journal of another sweep is refused).
  RowJournal(std::string path, const std::string& key, std::size_t tasks, const std::vector<std::string>& header,
             bool resume);
  RowJournal(const RowJournal&) = delete;
  RowJournal& operator=(const RowJournal&) = delete;
  ~RowJournal();

  /// Rows finished by earlier runs (resume), by task index.
  const std::map<std::size_t, std::string>& done() const { return done_; }
  /// Appends one finished row (one write(); fsync when kSyncInterval has passed); throws Error on failure.
  void append(std::size_t index, const std::string& row);
  /// fsync now.
  void sync();
  /// Deletes the journal (after the final output is committed).
  void remove();
  const std::string& path() const { return path_; }

 private:
  /// fsync at most this often: each fsync costs a disk flush (milliseconds), and a sweep's rows can
  /// take well under that; a power loss within the interval only means recomputing those rows.
  static constexpr std::chrono::milliseconds kSyncInterval{100};

  std::string path_;
  int fd_ = -1;
  std::chrono::steady_clock::time_point last_sync_{};
  std::map<std::size_t, std::string> done_;
};

/// `bodypoint merge`: the CSV of a sweep from the rows files of its shards.
int cmd_merge(int argc, char** argv);

}  // namespace bodypoint::cli

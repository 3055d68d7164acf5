// Rows files: the journal of a running sweep and the output of a shard (format in rows_file.hpp).
#include "process.hpp"
#include "rows_file.hpp"

#include "bodypoint/io.hpp"
#include "bodypoint/model.hpp"
#include "cli.hpp"

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <sys/stat.h>
#include <unistd.h>

namespace bodypoint::cli {
namespace {

constexpr const char* kMagic = "#bodypoint-rows 1";

/// One line of a rows file: body, a tab and the FNV-1a checksum of the body.
std::string with_check(const std::string& body) { return body + "\t" + hex64(fnv1a(body)) + "\n"; }

/// The body of a checked line ("X\t...\t<check>", without the newline), or false when the check does
/// not match (a torn or corrupt line).
bool checked_body(const std::string& line, std::string& body) {
  const std::size_t last = line.rfind('\t');
  if (last == std::string::npos || last < 2) return false;
  body = line.substr(0, last);
  return line.substr(last + 1) == hex64(fnv1a(body));
}

std::string record(std::size_t index, const std::string& row) {
  return with_check("R\t" + std::to_string(index) + "\t" + row);
}

/// A header line, checksummed like a record, so that an edited or injected header is caught.
std::string header_record(const std::string& line) { return with_check("H\t" + line); }

/// Parses "H\t<line>\t<check>"; false for a corrupt header line.
bool parse_header(const std::string& record, std::string& line) {
  std::string body;
  if (!checked_body(record, body)) return false;
  line = body.substr(2);
  return true;
}

/// Parses "R\t<index>\t<row>\t<check>" (without the newline); false for a torn or corrupt record.
bool parse_record(const std::string& line, std::size_t& index, std::string& row) {
  std::string body;
  if (line.rfind("R\t", 0) != 0 || !checked_body(line, body)) return false;
  const std::size_t second = body.find('\t', 2);
  if (second == std::string::npos) return false;
  const char* first = body.data() + 2;
  const auto [end, ec] = std::from_chars(first, body.data() + second, index);
  if (ec != std::errc() || end != body.data() + second) return false;
  row = body.substr(second + 1);
  return true;
}

/// Parses the first line; throws Error naming `path` when it is not a rows file.
void parse_magic(const std::string& line, const std::string& path, RowsContent& c) {
  std::istringstream in(line.substr(std::min(line.size(), std::strlen(kMagic))));
  std::string key, tasks;
  if (line.rfind(kMagic, 0) != 0 || !(in >> key >> tasks) || key.rfind("key=", 0) != 0 || tasks.rfind("tasks=", 0) != 0)
    throw Error("'" + path + "' is not a bodypoint rows file (a sweep's journal or shard output)");
  c.key = key.substr(4);
  const std::string n = tasks.substr(6);
  const auto [end, ec] = std::from_chars(n.data(), n.data() + n.size(), c.tasks);
  if (ec != std::errc() || end != n.data() + n.size())
    throw Error("'" + path + "' is not a bodypoint rows file (its task count '" + n + "' is not a number)");
}

/// Cuts a torn last line (no newline: the writer died in the middle of it) off the file at `fd`.
void cut_torn_tail(int fd, const std::string& path) {
  struct stat st{};
  if (::fstat(fd, &st) != 0) throw Error("cannot read the journal '" + path + "': " + std::strerror(errno));
  off_t end = st.st_size;
  char c = '\n';
  while (end > 0 && ::pread(fd, &c, 1, end - 1) == 1 && c != '\n') --end;
  if (end != st.st_size && ::ftruncate(fd, end) != 0)
    throw Error("cannot repair the journal '" + path + "': " + std::strerror(errno));
}

void write_all(int fd, const std::string& s, const std::string& path) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::write(fd, s.data() + off, s.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw Error("cannot write the journal '" + path + "': " + std::strerror(errno));
    off += static_cast<std::size_t>(n);
  }
}

}  // namespace

std::uint64_t fnv1a(const std::string& s, std::uint64_t h) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

std::string hex64(std::uint64_t x) {
  static const char* digits = "0123456789abcdef";
  std::string s(16, '0');
  for (int i = 15; i >= 0; --i, x >>= 4) s[static_cast<std::size_t>(i)] = digits[x & 15u];
  return s;
}

RowsContent read_rows_file(const std::string& path, std::size_t* dropped) {
  // A FIFO would block and a device (/dev/zero) never end: rows files are regular files.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw Error("cannot read '" + path + "': " + std::strerror(errno));
  if (!S_ISREG(st.st_mode)) throw Error("'" + path + "' is not a regular file, so not a bodypoint rows file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot read '" + path + "'");
  RowsContent c;
  std::string line;
  if (!std::getline(in, line)) throw Error("'" + path + "' is empty, not a bodypoint rows file");
  parse_magic(line, path, c);
  std::size_t bad = 0;
  while (std::getline(in, line)) {
    if (in.eof()) {  // no newline after it: a torn last record
      ++bad;
      break;
    }
    if (line.rfind("H\t", 0) == 0) {
      std::string h;
      if (parse_header(line, h))
        c.header.push_back(std::move(h));
      else
        ++bad;
      continue;
    }
    std::size_t index = 0;
    std::string row;
    if (!parse_record(line, index, row) || index >= c.tasks) {
      ++bad;
      continue;
    }
    // A record written twice (a resumed run that redid a row) is the same row; two different rows
    // under one index mean the file was edited or mixed.
    if (const auto [at, fresh] = c.rows.emplace(index, row); !fresh && at->second != row)
      throw Error("'" + path + "' holds two different rows for task " + std::to_string(index) + ": it was edited or mixed with another file");
  }
  if (dropped) *dropped = bad;
  return c;
}

std::string sweep_key_of(const std::string& revision, const std::string& scene_text, const std::string& request) {
  return hex64(fnv1a(revision)) + "-" + hex64(fnv1a(scene_text)) + "-" + hex64(fnv1a(request));
}

std::string key_difference(const std::string& was, const std::string& is) {
  const auto parts = [](const std::string& key) {
    std::vector<std::string> out;
    std::stringstream ss(key);
    for (std::string p; std::getline(ss, p, '-');) out.push_back(p);
    return out;
  };
  const std::vector<std::string> a = parts(was), b = parts(is);
  if (a.size() != 3 || b.size() != 3) return "another sweep (or another version of bodypoint)";
  static const char* const what[3] = {"the build changed (another revision of bodypoint)", "the scene file was edited",
                                      "the parameters, methods or accuracy differ"};
  std::string out;
  for (std::size_t k = 0; k < 3; ++k)
    if (a[k] != b[k]) out += (out.empty() ? "" : "; ") + std::string(what[k]);
  return out.empty() ? "the same sweep" : out;
}

std::string rows_file_text(const RowsContent& c) {
  std::string s = std::string(kMagic) + " key=" + c.key + " tasks=" + std::to_string(c.tasks) + "\n";
  for (const std::string& h : c.header) s += header_record(h);
  for (const auto& [index, row] : c.rows) s += record(index, row);
  return s;
}

RowJournal::RowJournal(std::string path, const std::string& key, std::size_t tasks,
                       const std::vector<std::string>& header, bool resume)
    : path_(std::move(path)) {
  // An empty journal is one whose run was killed between creating it and writing its first line (one
  // write): it holds no row, so it is started afresh.
  struct stat st {};
  const bool exists = ::stat(path_.c_str(), &st) == 0 && !(S_ISREG(st.st_mode) && st.st_size == 0);
  if (exists && !resume)
    throw Error("'" + path_ + "' holds the rows of an interrupted run of this output: add --resume to finish it, or delete it");
  if (exists) {
    std::size_t dropped = 0;
    const RowsContent old = read_rows_file(path_, &dropped);
    if (old.key != key)
      throw Error("the journal '" + path_ + "' belongs to another sweep (" + key_difference(old.key, key) +
                  "); delete it to start over");
    if (old.tasks != tasks)
      throw Error("the journal '" + path_ + "' belongs to another sweep (" + std::to_string(old.tasks) + " rows, this one " +
                  std::to_string(tasks) + "); delete it to start over");
    done_ = old.rows;
    if (dropped > 0)
      std::cerr << "bodypoint: resuming: dropped " << dropped << " torn record(s) of '" << path_ << "', they run again\n";
  }
  fd_ = ::open(path_.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error("cannot write the journal '" + path_ + "': " + std::strerror(errno));
  if (exists) {
    cut_torn_tail(fd_, path_);
  } else {
    RowsContent fresh;
    fresh.key = key;
    fresh.tasks = tasks;
    fresh.header = header;
    write_all(fd_, rows_file_text(fresh), path_);
  }
  sync();
  note_journal(true);
}

RowJournal::~RowJournal() {
  note_journal(false);
  if (fd_ >= 0) {
    ::fsync(fd_);
    ::close(fd_);
  }
}

void RowJournal::append(std::size_t index, const std::string& row) {
  write_all(fd_, record(index, row), path_);
  const auto now = std::chrono::steady_clock::now();
  if (now - last_sync_ >= kSyncInterval) sync();
}

void RowJournal::sync() {
  if (fd_ >= 0 && ::fsync(fd_) != 0) throw Error("cannot write the journal '" + path_ + "': " + std::strerror(errno));
  last_sync_ = std::chrono::steady_clock::now();
}

void RowJournal::remove() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  ::unlink(path_.c_str());
}

int cmd_merge(int argc, char** argv) {
  std::string out;
  std::vector<std::string> inputs;
  po::options_description desc("bodypoint merge");
  desc.add_options()("out", po::value(&out), "the merged CSV (default: standard output)")(
      "input", po::value(&inputs)->multitoken(), "rows files of the shards (sweep --shard K/N --out FILE)");
  po::variables_map vm;
  if (!parse(argc, argv, desc, vm,
             "usage: bodypoint merge --input SHARD1 SHARD2 ... [--out FILE]\n"
             "The CSV of a sweep from its shards: every row exactly once, in the order a single run writes them."))
    return 0;
  if (inputs.empty()) throw Error("give the shards' files with --input");
  RowsContent all;
  std::map<std::size_t, std::string> from;
  for (const std::string& path : inputs) register_input(path);
  for (const std::string& path : inputs) {
    std::size_t dropped = 0;
    RowsContent c = read_rows_file(path, &dropped);
    if (dropped > 0) throw Error("'" + path + "' has " + std::to_string(dropped) + " torn or corrupt record(s)");
    // Every shard is written with the CSV's header lines: one without them was edited.
    if (c.header.empty()) throw Error("'" + path + "' has no header lines (the CSV's column names): it was edited");
    if (all.key.empty()) {
      all.key = c.key;
      all.tasks = c.tasks;
      all.header = c.header;
    } else if (c.key != all.key || c.tasks != all.tasks) {
      throw Error("'" + path + "' is a shard of another sweep than '" + inputs.front() + "' (" +
                  (c.key != all.key ? key_difference(all.key, c.key) : "another number of rows") + ")");
    }
    for (auto& [index, row] : c.rows) {
      if (from.count(index)) throw Error("row " + std::to_string(index) + " is in both '" + from[index] + "' and '" + path + "'");
      from[index] = path;
      all.rows.emplace(index, std::move(row));
    }
  }
  if (all.rows.size() != all.tasks) {
    std::size_t missing = 0;
    while (all.rows.count(missing)) ++missing;
    throw Error("the shards hold " + std::to_string(all.rows.size()) + " of " + std::to_string(all.tasks) +
                " rows (row " + std::to_string(missing) + " is missing): merge every shard");
  }
  std::unique_ptr<AtomicFile> file;
  if (!out.empty()) file = std::make_unique<AtomicFile>(out);
  std::ostream& os = file ? static_cast<std::ostream&>(file->stream()) : std::cout;
  for (const std::string& h : all.header) os << h << "\n";
  for (const auto& [index, row] : all.rows) os << row << "\n";
  if (file) file->commit();
  return 0;
}

}  // namespace bodypoint::cli

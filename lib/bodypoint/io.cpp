#include "bodypoint/io.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <unistd.h>

#ifndef BODYPOINT_GIT_REVISION
#define BODYPOINT_GIT_REVISION "unknown"
#endif

namespace bodypoint {

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  if (path_.empty()) throw Error("output path is empty");
  tmp_ = path_ + ".tmp." + std::to_string(::getpid());
  out_.open(tmp_, std::ios::out | std::ios::trunc);
  if (!out_) throw Error("cannot write output file '" + path_ + "' (directory missing or not writable)");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    if (out_.is_open()) out_.close();
    std::remove(tmp_.c_str());
  }
}

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok || out_.fail()) throw Error("writing '" + path_ + "' failed (disk full?)");
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0)
    throw Error("cannot move the finished output onto '" + path_ + "'");
  committed_ = true;
}

std::string fmt(double x) {
  // Shortest representation that reads back to the same double (0.7, not 0.69999999999999996).
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

std::string json_number(double x) { return std::isfinite(x) ? fmt(x) : "null"; }

std::string json_vec(const Vec3& v) {
  std::ostringstream os;
  os << '[' << json_number(v.x()) << ", " << json_number(v.y()) << ", " << json_number(v.z()) << ']';
  return os.str();
}

const char* git_revision() { return BODYPOINT_GIT_REVISION; }

}  // namespace bodypoint

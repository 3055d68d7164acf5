// bodypoint: output helpers shared by every driver.
//
// `AtomicFile` writes to a temporary file beside the target and renames it over the target on
// commit(), so a failed or interrupted run never leaves a half-written result. Numbers are written
// so that a value read back is exactly the value computed.
#pragma once

#include "bodypoint/model.hpp"

#include <fstream>
#include <string>

namespace bodypoint {

class AtomicFile {
 public:
  /// Opens "<path>.tmp.<pid>" for writing; throws Error if that is impossible (missing directory,
  /// no permission), before any computation has been spent.
  explicit AtomicFile(std::string path);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicFile();

  std::ofstream& stream() { return out_; }
  /// Flushes, closes and renames onto the target path; throws Error on any failure.
  void commit();

 private:
  std::string path_, tmp_;
  std::ofstream out_;
  bool committed_ = false;
};

/// x in the shortest form that reads back exactly ("nan"/"inf" spelled as such).
std::string fmt(double x);
/// JSON number, or null for a non-finite value.
std::string json_number(double x);
/// "[x, y, z]" as JSON.
std::string json_vec(const Vec3& v);

/// The git revision this binary was built from.
const char* git_revision();

}  // namespace bodypoint

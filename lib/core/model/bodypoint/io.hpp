// bodypoint: the one number format and the text outputs of every driver: numbers written so that a value
// read back is exactly the value computed (fmt), CSV rows (CsvLine), JSON values, "did you mean" and the
// revision the binary was built from. Writing files safely (atomic files, locks, signals, a deadline)
// is the command layer's (experiments/cli/process.hpp).
#pragma once


#include "bodypoint/model.hpp"

#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bodypoint {

/// x in the shortest form that reads back exactly ("nan"/"inf" spelled as such).
std::string fmt(double x);
/// The whole text s as a double, or nullopt where it is not a number or beyond the range of a double. A
/// value below the smallest normal double (1e-320) is a number: its subnormal (std::stod refuses it).
/// Leading white space is not a number. "nan" and "inf" read as such: the caller says if they may be.
std::optional<double> read_double(const std::string& s);
/// One CSV line, the one row format of every CSV the tool writes: cells separated by commas, numbers
/// by fmt, counts and names as they are, free text quoted (its own quotes turned into apostrophes).
class CsvLine {
 public:
  CsvLine& num(double x) { return add(fmt(x)); }
  /// fmt(x), or an empty cell when `present` is false (a column that does not apply to the row).
  CsvLine& num_if(bool present, double x) { return add(present ? fmt(x) : std::string()); }
  CsvLine& count(long n) { return add(std::to_string(n)); }
  CsvLine& text(std::string_view s) { return add(std::string(s)); }
  CsvLine& quoted(std::string s);
  [[nodiscard]] const std::string& str() const { return line_; }

 private:
  CsvLine& add(const std::string& cell) {
    if (cells_++) line_ += ',';
    line_ += cell;
    return *this;
  }
  std::string line_;
  long cells_ = 0;
};

/// JSON number, or null for a non-finite value.
std::string json_number(double x);
/// "[x, y, z]" as JSON.
std::string json_vec(const Vec3& v);
/// s as a JSON string: quotes, backslashes and control characters escaped (\u00XX). With html_safe,
/// also <, > and &, so that the text can stand inside an HTML <script> element.
std::string json_string(std::string_view s, bool html_safe = false);

/// The candidate within max_edits edits (insertions, deletions, substitutions; letters compared
/// without case) of word, the closest first in the candidates' order; empty when none is. For "did
/// you mean" in messages.
std::string closest_word(std::string_view word, const std::vector<std::string>& candidates, std::size_t max_edits);

/// The items with `sep` between them.
std::string join(const std::vector<std::string>& items, std::string_view sep);

/// s as one line: a newline, tab or other control character in it shown escaped, so that a message that
/// echoes a value is always one line.
std::string one_line(std::string_view s);

/// "unknown <what> 'word' (did you mean 'x'?); valid: a, b, c": the one wording of an unknown name.
std::string unknown_name(std::string_view what, std::string_view word, const std::vector<std::string>& valid);

/// The git revision this binary was built from.
const char* git_revision();
/// The project's version (CMakeLists.txt's project()).
const char* version();

}  // namespace bodypoint

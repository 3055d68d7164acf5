#include "bodypoint/io.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <string>
#include <vector>

namespace bodypoint {

std::string fmt(double x) {
  // Shortest representation that reads back to the same double (0.7, not 0.69999999999999996).
  if (std::isnan(x)) return "nan";  // not "-nan": the sign of a NaN means nothing
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, x);
  return std::string(buf, res.ptr);
}

std::optional<double> read_double(const std::string& s) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || std::isspace(static_cast<unsigned char>(s.front()))) return std::nullopt;
  if (errno == ERANGE && std::abs(v) > 1.0) return std::nullopt;  // overflow; underflow gives the subnormal
  return v;
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

std::string join(const std::vector<std::string>& items, std::string_view sep) {
  std::string out;
  for (const std::string& item : items) out.append(out.empty() ? "" : sep).append(item);
  return out;
}

std::string one_line(std::string_view s) {
  std::string out;
  for (const unsigned char c : s) {
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
    } else {
      out += static_cast<char>(c);
    }
  }
  return out;
}


std::string unknown_name(std::string_view what, std::string_view word, const std::vector<std::string>& valid) {
  constexpr std::size_t kSuggestEdits = 2;  // a typo: a letter missing, extra, wrong or two of them
  const std::string near = closest_word(word, valid, kSuggestEdits);
  std::string out = "unknown " + std::string(what) + " '" + one_line(word) + "'";
  if (!near.empty()) out += " (did you mean '" + near + "'?)";
  return out + "; valid: " + join(valid, ", ");
}

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

// git_revision() is generated at build time (cmake/revision.cmake).

}  // namespace bodypoint

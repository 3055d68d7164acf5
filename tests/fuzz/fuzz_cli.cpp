// libFuzzer target: the command-line parser of `bodypoint simulate` and `bodypoint view`, with
// --dry-run, so that everything is parsed and validated (options, numbers, scene, method, steps,
// output limits) and nothing runs or is written. The input is split into arguments at NUL bytes and
// newlines; the first byte picks the command. Any input must end in exit 0 or in one of the errors
// that main() turns into one line; a crash or a sanitizer report is a bug.
#include "../../experiments/cli/cli.hpp"

#include <boost/program_options/errors.hpp>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  std::vector<std::string> args{data[0] % 2 ? "view" : "simulate"};
  std::string cur;
  for (std::size_t i = 1; i < size; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\0' || c == '\n') {
      args.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  args.push_back(cur);
  for (const std::string& a : args)  // no reading of devices or large files, no writing
    if (a.rfind("--scene", 0) == 0 || a.rfind("--out", 0) == 0 || a.rfind("--help", 0) == 0) return 0;
  args.emplace_back("--dry-run");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  try {
    if (args.front() == "view") bodypoint::cli::cmd_view(static_cast<int>(argv.size()), argv.data());
    else bodypoint::cli::cmd_simulate(static_cast<int>(argv.size()), argv.data());
  } catch (const bodypoint::Error&) {
  } catch (const boost::program_options::error&) {
  }
  return 0;
}

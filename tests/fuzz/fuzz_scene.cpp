// libFuzzer target: the TOML scene-file parser. Any input must end in a Scene or in bodypoint::Error
// (one line, the reason); a crash, a sanitizer report, a hang or another exception is a bug.
#include "bodypoint/scene_file.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const bodypoint::Scene s = bodypoint::parse_scene(text, "fuzz.toml");
    // A scene that parses is valid: every body has D > 0 and starts off every centre.
    bodypoint::validate(s);
  } catch (const bodypoint::Error&) {
  }
  return 0;
}

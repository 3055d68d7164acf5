// bodypoint view: the page script (three.js + viewer/src/viewer.js) compiled into the binary.
#pragma once

#include <optional>
#include <string_view>

namespace bodypoint::cli {

/// The bundled script, or nothing when the binary was built without experiments/viewer's npm packages.
std::optional<std::string_view> viewer_bundle();

}  // namespace bodypoint::cli

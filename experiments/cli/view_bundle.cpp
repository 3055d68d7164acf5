// bodypoint view: embeds the esbuild bundle of the viewer (experiments/CMakeLists.txt builds it into
// the build tree) with the assembler's .incbin, so the binary writes pages without reading any file.
#include "view_bundle.hpp"

#ifdef BODYPOINT_VIEWER_JS
asm(".section .rodata\n"
    ".balign 16\n"
    ".globl bodypoint_viewer_js_begin\n"
    ".hidden bodypoint_viewer_js_begin\n"
    "bodypoint_viewer_js_begin:\n"
    ".incbin \"" BODYPOINT_VIEWER_JS "\"\n"
    ".globl bodypoint_viewer_js_end\n"
    ".hidden bodypoint_viewer_js_end\n"
    "bodypoint_viewer_js_end:\n"
    ".byte 0\n"
    ".previous\n");
extern "C" const char bodypoint_viewer_js_begin[];
extern "C" const char bodypoint_viewer_js_end[];
#endif

namespace bodypoint::cli {

std::optional<std::string_view> viewer_bundle() {
#ifdef BODYPOINT_VIEWER_JS
  return std::string_view(bodypoint_viewer_js_begin,
                          static_cast<std::size_t>(bodypoint_viewer_js_end - bodypoint_viewer_js_begin));
#else
  return std::nullopt;
#endif
}

}  // namespace bodypoint::cli

// libFuzzer target for the scene-file loader: any input must load or fail with a
// SceneFileError; crashes, hangs, sanitizer reports and other exceptions are bugs.
// Built and run by scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>
#include <string>

#include "scenefile/scene_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        // Files are not read (obj shapes fail cleanly); one parameter is predefined so that
        // $x substitutions are exercised too.
        (void)pathlab::load_scene_text(text, "fuzz.xml", "/nonexistent", {{"x", "1"}}, false);
    } catch (const pathlab::SceneFileError&) {
    }
    return 0;
}

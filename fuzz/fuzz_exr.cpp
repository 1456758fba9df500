// libFuzzer target for the .exr reader (see fuzz_image_reader.hpp). Built and run by scripts/fuzz.sh exr.
#include "fuzz_image_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    return pathlab::fuzz::read_image_input(pathlab::ImageFormat::Exr, "fuzz.exr", data, size);
}

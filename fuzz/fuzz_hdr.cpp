// libFuzzer target for the .hdr reader (see fuzz_image_reader.hpp). Built and run by scripts/fuzz.sh hdr.
#include "fuzz_image_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    return pathlab::fuzz::read_image_input(pathlab::ImageFormat::Hdr, "fuzz.hdr", data, size);
}

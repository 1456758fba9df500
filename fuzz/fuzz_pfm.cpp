// libFuzzer target for the .pfm reader (see fuzz_image_reader.hpp). Built and run by scripts/fuzz.sh pfm.
#include "fuzz_image_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    return pathlab::fuzz::read_image_input(pathlab::ImageFormat::Pfm, "fuzz.pfm", data, size);
}

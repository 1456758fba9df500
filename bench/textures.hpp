#pragma once

#include <string>
#include <vector>

namespace pathlab::bench {

struct TexturesOptions {
    int size = 128;          // image width and height
    double seconds = 4;      // per timed render
    int repeats = 5;         // interleaved rounds (medians reported)
    int lookups = 4000000;   // texture lookups per timing of the lookup table
    std::string scene_file;  // the textured scene (default: scenes/textures.xml)
};

// `pathlab_bench textures`: the cost of textured against constant materials per pt-mis
// sample (the course's diffuse box with its colours as bitmaps of the same values: the same
// image, bit for bit; and scenes/textures.xml with and without its textures, normal and bump
// maps), and the cost of one texture lookup of each kind.
void textures_suite(const TexturesOptions& o);

}  // namespace pathlab::bench

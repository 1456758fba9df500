// What an image file says about itself besides its pixels, for `pathlab info`: the format, the
// channels, and every piece of metadata, read generically: an EXR's header attributes (each
// with its type: render settings a writer added come out as they are, whatever their names),
// a Radiance file's header lines, a PFM's scale line, a PNG's text chunks.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace pathlab {

struct ImageHeader {
    std::string format;                 // "OpenEXR", "Radiance RGBE", "PFM", "PNG"
    int width = 0, height = 0;
    std::vector<std::string> channels;  // "R (float)", ...
    // name, value as text (with the type in brackets for EXR attributes), in file order
    std::vector<std::pair<std::string, std::string>> attributes;
};

// Reads the header of a file that read_image or read_png8 has read successfully (so it is
// known to be well formed); throws ImageIoError naming the file otherwise.
ImageHeader read_image_header(const std::string& path);

}  // namespace pathlab

// What the readers of emitters that read files or need an orientation share: where files are
// found, and the rotation of a to_world.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "core/frame.hpp"
#include "core/properties.hpp"

namespace pathlab {

class Texture;

// Where scene-file emitters find their files, and the texture nested in the emitter.
struct EmitterContext {
    std::string base_dir = ".";  // relative file names are resolved against it
    bool allow_files = true;     // false: emitters that read files are an error (the fuzzer)
    // Where else relative file names are searched, in order (the scene file's folder and its
    // <path> folders); base_dir when empty.
    std::vector<std::string> search_dirs = {};
    // If set, every file found is appended (the scene's identity hashes the files it read).
    std::vector<std::string>* files_read = nullptr;
    // A nested <texture name="texture"> (or a <ref> to one): spot's projected texture.
    std::shared_ptr<const Texture> texture = {};
};

// The path of the emitter's required `filename`, resolved against the search folders;
// a PropertyError when it is missing or files may not be read. `what` names the emitter.
std::string emitter_file(Properties& p, const EmitterContext& ctx, const char* what);

// The frame of the emitter's to_world, which must be a rotation (a uniform scale and a
// translation are allowed and ignored here; a reflection is kept): the images of the x, y and
// z axes, normalised. A PropertyError at to_world for a shear or a non-uniform scale, which
// would distort the emitter's angular distribution. The identity without a to_world.
Frame rotation_frame(Properties& p, const char* what);

}  // namespace pathlab

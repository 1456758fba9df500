// The texture plugins of scene files (<texture type="bitmap">, <texture type="checkerboard">):
// each declares its parameters (Mitsuba 3's names) and reads them into a Texture. The scene-file
// reader binds a texture to a BSDF's parameter (nested <texture name="reflectance">, or <ref
// name="reflectance" id="..."/> to a top-level <texture id="...">).
#pragma once

#include <string>
#include <vector>

#include "core/properties.hpp"
#include "textures/texture.hpp"

namespace pathlab {

struct TextureContext {
    std::string base_dir = ".";  // relative file names are resolved against it
    bool allow_files = true;     // false: textures that read files are an error (the fuzzer)
    // Where relative file names are searched, in order (the scene file's folder and its <path>
    // folders); base_dir when empty.
    std::vector<std::string> search_dirs = {};
    std::vector<std::string>* files_read = nullptr;  // if given, gets each image file's path
};

struct TexturePlugin {
    const PluginInfo& (*info)();
    Texture (*read)(Properties&, const TextureContext&);
};

const std::vector<TexturePlugin>& texture_plugins();
const TexturePlugin* find_texture_plugin(const std::string& type);
std::string texture_type_names();  // "bitmap, checkerboard" for error messages

}  // namespace pathlab

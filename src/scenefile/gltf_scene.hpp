// glTF 2.0 scenes (.gltf and .glb, Blender's default export) as the Mitsuba XML they amount to.
//
// A glTF file is read by tinygltf and written out as a scene file of pathlab's Mitsuba subset:
// its meshes as .serialized files, its images (or images derived from them) beside, and the XML
// naming them. `pathlab scene.glb` renders that XML (converted into a private temporary folder,
// removed once loaded), so a glTF scene and its conversion are the same scene bit for bit. The
// mapping, each convention with its source, is in docs/scene-files.md ("glTF scenes"):
//   - nodes: their matrix or translation-rotation-scale, composed down the hierarchy, as each
//     shape's to_world (a mirroring transform reverses the winding, as glTF's spec says);
//   - the metallic-roughness material as `principled` (base colour, metallic, roughness, their
//     textures and factors, KHR_texture_transform as the bitmaps' to_uv, the normal texture as
//     `normalmap`, KHR_materials_transmission and
//     KHR_materials_ior), emissive (its factor, KHR_materials_emissive_strength and texture) as
//     an area emitter;
//   - the first camera of the scene (perspective: yfov on the y axis; orthographic: xmag by ymag),
//     else one framing the scene;
//   - KHR_lights_punctual point, spot and directional lights, candela and lux read with
//     683 lm/W as Blender's importer does (intensity I cd -> I / 683 W/sr).
// What it cannot render is refused with the file's name and the reason (a required extension
// it lacks, lines and points, a second uv set); what it leaves out
// (alpha, other extensions) is a warning.
#pragma once

#include <string>
#include <vector>

#include "scenefile/scene_file.hpp"

namespace pathlab {

// True for a path ending in .gltf or .glb (any case).
bool is_gltf_path(const std::string& path);

struct GltfConversion {
    std::vector<std::string> files;     // the glTF file, then the files it refers to (buffers, images)
    std::vector<std::string> warnings;  // what of the file the scene leaves out
};

// Writes the Mitsuba XML a glTF scene amounts to at `xml_path`, with its meshes and images in
// the folder "<xml_path's stem>_files" beside it. Throws SceneFileError naming the glTF file.
GltfConversion convert_gltf_scene(const std::string& gltf_path, const std::string& xml_path);

// Loads a glTF scene as load_scene_file loads XML: converted into a temporary folder, loaded,
// the folder removed. Warnings go to stderr. `inputs` gets the glTF's files (not the temporary ones).
SceneDescription load_gltf_scene(const std::string& path, const SceneDefines& defines = {}, SceneFileInputs* inputs = nullptr);

}  // namespace pathlab

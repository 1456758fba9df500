// Scene files: a documented subset of Mitsuba 3's XML format (docs/scene-files.md).
//
//   <scene version="3.0.0">
//     <default name="spp" value="64"/>
//     <integrator type="path"> <integer name="max_depth" value="8"/> </integrator>
//     <sensor type="perspective"> <float name="fov" value="45"/>
//       <transform name="to_world"> <lookat origin="0,-4,0" target="0,0,0" up="0,0,1"/> </transform>
//       <film type="hdrfilm"> <integer name="width" value="512"/> <integer name="height" value="512"/> </film>
//       <sampler type="independent"> <integer name="sample_count" value="$spp"/> </sampler>
//     </sensor>
//     <bsdf type="diffuse" id="white"> <rgb name="reflectance" value="0.8"/> </bsdf>
//     <shape type="obj"> <string name="filename" value="floor.obj"/> <ref id="white"/> </shape>
//     <shape type="sphere"> <point name="center" value="0,0,0"/> <float name="radius" value="0.5"/>
//       <emitter type="area"> <rgb name="radiance" value="10"/> </emitter> </shape>
//   </scene>
//
// Every error is a SceneFileError naming file, line and column; nothing is silently ignored.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/scene_description.hpp"

namespace pathlab {

struct SceneFileError : std::runtime_error {
    SceneFileError(std::string file_, int line_, int column_, const std::string& message_);
    std::string file;
    int line = 0, column = 0;  // 1-based; 0 when the error concerns the whole file
    std::string message;
};

// Values for $name substitution: command-line -D name=value pairs; a <default> in the file
// applies only to names not given here.
using SceneDefines = std::map<std::string, std::string>;
// The $name parameters a scene file uses, each with the value it took (-D, else <default>).
using SceneParameters = std::map<std::string, std::string>;

// What a scene was made of, for its identity (the scene hash): the $name parameters it used,
// with the values they took, and every file it read, in order: the scene file (by
// load_scene_file), its <include>s, spectrum files, meshes and emitters' files (envmap, ies).
struct SceneFileInputs {
    SceneParameters parameters;
    std::vector<std::string> files;
};

// Loads a scene file; relative mesh paths are resolved against the file's directory. `inputs`,
// if given, receives the parameters and files the scene used.
SceneDescription load_scene_file(const std::string& path, const SceneDefines& defines = {}, SceneFileInputs* inputs = nullptr);

// Loads a scene from text (`file_name` is used in messages). With allow_files = false, shapes
// that read files (obj) are an error: the fuzzer uses this.
SceneDescription load_scene_text(const std::string& text, const std::string& file_name, const std::string& base_dir,
                                 const SceneDefines& defines = {}, bool allow_files = true, SceneFileInputs* inputs = nullptr);

}  // namespace pathlab

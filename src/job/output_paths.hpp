// What a command writes, checked before any work starts: every output can be written, none is
// one of the command's inputs (a scene file, a reference image, a mapping file), and no two
// outputs are the same file. Without this, `--stats scene.xml` replaced the scene and
// `check --json refs/0.pfm` the reference it was about to read. Paths are compared after
// resolving ".", ".." and symbolic links, so two spellings of one file are caught.
#pragma once

#include <string>
#include <vector>

namespace pathlab {

struct SceneChoice;

class OutputPaths {
public:
    // A file the command reads; `what` names it in messages ("the scene file").
    void input(const std::string& path, const std::string& what);
    // A scene's files: the scene file and every file it reads (includes, meshes, textures,
    // environment maps, light profiles, spectra, grids), which no output may replace.
    void scene_inputs(const SceneChoice& scene);
    // A file the command will write. Image outputs must have a known extension. Throws
    // UsageError naming both paths when it is an input or another output, or cannot be written.
    void output(const std::string& path, const std::string& what, bool image);

private:
    struct Entry {
        std::string path, key, what;
    };
    static std::string key(const std::string& path);
    std::vector<Entry> inputs_, outputs_;
};

}  // namespace pathlab

// What a reference image is a reference of. `pathlab reference` (and `report`, for the
// reference it renders) records every image it writes in manifest.json beside it: the scene
// (built-in index and name, or the scene file with its hash: its bytes and the $parameters it
// took), the size, and the estimator's family (what its image converges to: direct or global
// illumination, the depth limit). `check` and `report` read the record of the reference they
// are given and refuse one of another scene, size or family (exit code 2, saying which),
// instead of judging a render against the wrong image.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "job/scene_choice.hpp"

namespace pathlab {

struct ReferenceRecord {
    std::string file;                   // the image's file name, in the manifest's directory
    std::string scene;                  // {scene}: the built-in name or the scene file's stem
    std::optional<int> index;           // a built-in scene's course index
    std::string scene_file;             // a scene file, as it was given
    std::string scene_hash;             // scene_hash() of that scene (job/scene_choice.hpp)
    std::map<std::string, std::string> parameters;  // the scene file's $name values
    std::string algorithm;
    std::string family;                 // integrator_family()
    int max_depth = -1;
    int width = 0, height = 0;
    uint64_t spp = 0, seed = 0;
    double seconds = 0;
    uint64_t invalid_samples = 0;
    bool interrupted = false;
    std::string stderr_file, preview;   // companions (may be empty)
};

nlohmann::json to_json(const ReferenceRecord& r);
// Missing fields (manifests of older versions) stay empty; the family then follows from the
// algorithm and the depth.
ReferenceRecord reference_record_from_json(const nlohmann::json& j);

// A manifest.json that exists but is not one (not JSON, not an object, "scenes" not an array
// of records, a field of the wrong type): what() names the file and the problem. A corrupt
// manifest cannot be ignored: a reference it would have refused would then judge a render.
struct ManifestError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// The record of `image_path` in the manifest.json of its directory; nullopt when there is no
// manifest or it does not list the file; ManifestError for a corrupt one.
std::optional<ReferenceRecord> find_reference_record(const std::string& image_path);

// Throws ManifestError if DIR/manifest.json exists and is corrupt (before anything is rendered into DIR).
void check_manifest(const std::string& dir);

// Adds the record to DIR/manifest.json (replacing one of the same file; others kept), sorted
// by course index, then file name; ManifestError for a corrupt one (left as it is).
void record_reference(const std::string& dir, const ReferenceRecord& record);

// Empty when the recorded reference fits a render of `scene` by an estimator of `family` at
// width x height; otherwise why not, in a sentence that names `image_path`.
std::string reference_mismatch(const ReferenceRecord& record, const std::string& image_path, const SceneChoice& scene,
                               const std::string& family, int width, int height);

}  // namespace pathlab

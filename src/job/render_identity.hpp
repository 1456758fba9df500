// What a render's samples are a function of, field by field: the scene (its name and its
// scene_hash(): every file it read, its parameters, its geometry), the integrator and its
// options, the resolution, the seed and the sampler. Two renders with equal identities and disjoint passes are parts of one render; a
// checkpoint is resumed only by a render of the same identity, and `merge` combines renders
// whose identities differ in the seed alone. The fields are kept apart so that a refusal can say
// which differ.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "integrators/integrator.hpp"
#include "job/pass_set.hpp"
#include "scene/scene_description.hpp"

namespace pathlab {

class RenderJob;

struct RenderIdentity {
    std::vector<std::pair<std::string, std::string>> fields;  // in a fixed order (kIdentityFields)

    // The field's value ("" when absent).
    std::string value(const std::string& key) const;
    // "key=value" lines, in order.
    std::string to_text() const;
    // The lines of to_text(); unknown keys are kept (a newer file), malformed lines are skipped.
    static RenderIdentity from_text(const std::string& text);
    // XXH3 of to_text(), as 16 hex digits.
    std::string hash() const;
    // "" when every field in `keys` is equal, else one line per difference:
    // "  seed: 1234 in <theirs_name>, 99 in <ours_name>".
    std::string differences(const RenderIdentity& ours, const std::vector<std::string>& keys, const std::string& theirs_name,
                            const std::string& ours_name) const;
};

// The fields, in order: scene, scene hash, integrator, options, resolution, seed, sampler.
extern const std::vector<std::string> kIdentityFields;
// ... all but the seed: what renders that `merge` combines must share.
extern const std::vector<std::string> kMergeFields;

// The integrator options that change its samples, as "name=value" words (floats exactly, in hex).
std::string options_text(const IntegratorOptions& o);

// The EXR header attributes of a render: "pathlab:" + each identity field in camelCase
// (pathlab:scene, pathlab:sceneHash, pathlab:integrator, pathlab:options, pathlab:resolution,
// pathlab:seed, pathlab:sampler), pathlab:spp (passes in the image), pathlab:firstSample (the
// smallest), pathlab:passes (PassSet text), pathlab:invalidSamples and pathlab:version.
std::vector<std::pair<std::string, std::string>> render_metadata(const RenderIdentity& identity, const PassSet& passes,
                                                                 uint64_t invalid_samples,
                                                                 const std::vector<IntegratorStatistic>& statistics = {});
// The attribute name of an identity field ("scene hash" -> "pathlab:sceneHash").
std::string metadata_key(const std::string& field);

// The identity of `job` (the scene is not built); its scene hash is scene_hash() of the job's
// scene (job/scene_choice.hpp: every file it read, its parameters, its geometry), the one that
// reference manifests record.
RenderIdentity render_identity(RenderJob& job, int width, int height);

}  // namespace pathlab

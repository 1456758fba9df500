// Plain data describing a scene, produced by the built-in scenes and by scene-file loaders,
// consumed by Scene::build. Nothing here knows about Embree or sampling.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bsdfs/material.hpp"
#include "cameras/camera.hpp"
#include "core/reconstruction_filter.hpp"
#include "geometry/shape.hpp"
#include "lights/light_sampler.hpp"
#include "lights/registry.hpp"
#include "media/medium.hpp"
#include "spectral/emission_spectrum.hpp"

namespace pathlab {

struct SceneDescription {
    std::string name;
    Camera camera;
    int width = 512, height = 512;
    std::vector<Material> materials;
    std::vector<MeshDesc> meshes;
    std::vector<SphereDesc> spheres;
    std::vector<ShapeGroupDesc> groups;  // placed by instances
    std::vector<InstanceDesc> instances;
    std::vector<FreeLight> lights;
    // Participating media (shapes refer to them by index, MediumInterface) and the one the
    // camera sits in (-1: none).
    std::vector<Medium> media;
    int32_t camera_medium = -1;
    // How messages name each medium (by index in `media`; the vector may be shorter): its type
    // and a scene file's id ("homogeneous medium 'fog'"), or where the file declares it.
    std::vector<std::string> medium_labels;
    std::vector<std::string> medium_ids;  // a scene file's id of each medium ("" for none; may be shorter)
    // Ids of the materials (by index in `materials`) and free lights (by index in `lights`), ""
    // for unnamed ones (either vector may be shorter): the names of differentiable parameters
    // (diff/parameters.hpp), as scene files' id attributes give them. Shapes carry their own id.
    std::vector<std::string> material_ids;
    std::vector<std::string> light_ids;
    // Emitters whose scene file gives a spectrum (a black body, a tabulated spectrum), seen with
    // it in spectral mode: free lights by index in `lights`, area emitters by index in `meshes`
    // and `spheres` (each vector may be shorter than the one it follows; null: RGB only).
    std::vector<std::shared_ptr<const EmissionSpectrum>> light_spectra, mesh_emission_spectra, sphere_emission_spectra;
    // Area emitters whose radiance is a texture (<texture name="radiance">), by index in
    // `meshes` (the vector may be shorter; null: the mesh's constant emission). Such a mesh's
    // `emission` is the texture's largest value (it says that the mesh emits).
    std::vector<std::shared_ptr<const Texture>> mesh_emission_textures;
    // Render settings a scene file may suggest; command-line options override them.
    std::optional<std::string> algorithm;
    // A scene file's integrator that pathlab does not have: its type, and where the file gives it
    // ("file:line:column"). A render of the scene needs -a, which replaces it (render_job.cpp).
    std::string unknown_integrator, unknown_integrator_at;
    std::optional<int> spp, max_depth, rr_depth;  // depths in pathlab's bounces
    std::optional<int64_t> photons;               // sppm, pm: light paths (per iteration for sppm)
    std::optional<float> photon_radius;           // sppm: the first iteration's radius
    std::optional<double> photon_alpha;           // sppm: the radius reduction
    std::optional<bool> volume_beam;              // sppm, ppm, pm in media: beams (true) or points
    std::optional<int> pbgi_surfels, pbgi_bounces, pbgi_resolution, pbgi_direct_samples, pbgi_spacing;  // pbgi
    std::optional<float> pbgi_cutoff;                                                     // pbgi
    std::optional<int> ic_rays;                                                            // ic
    std::optional<float> ic_error;
    std::optional<bool> ic_gradients, ic_clamp_screen, ic_clamp_neighbours;
    std::optional<int> guiding_spp;                                                        // ppg: training_spp
    std::optional<bool> guiding_rr;                                                        // ppg: guiding_rr
    std::optional<std::string> guiding_fraction;                                           // ppg: guiding_fraction
    std::optional<std::string> guiding;  // ppg: guiding (sd-tree or vmm)
    std::optional<std::string> estimators;                                                 // upbp: estimators
    std::optional<int64_t> photon_beams;                                                   // upbp: photon_beams
    std::optional<float> beam_radius;                                                      // upbp: beam_radius
    bool spectral = false;                        // <default name="mode" value="spectral"/>: spectral mode
    // How next-event estimation chooses a light (--light-sampler; not a scene-file setting).
    LightSamplerKind light_sampler = LightSamplerKind::Power;
    int ris_candidates = kDefaultRisCandidates;  // --ris-candidates (ris)
    float light_split = 0;                        // --light-split (bvh; 0: no splitting)
    std::optional<bool> hide_emitters;            // paths of no bounce (emitters seen directly) left out
    std::optional<bool> skip_null_events;         // --null-depth skip (a Mitsuba <integrator type="volpath">)
    // The film: its reconstruction filter, the format of the default output (hdrfilm's
    // file_format: "openexr", "rgbe" or "pfm"), and extra outputs an integrator asks for
    // (moment: the second moment; aov: depth, position, normals, albedo).
    FilterDesc filter;
    std::string file_format = "openexr";
    bool moment = false;
    std::vector<std::pair<std::string, std::string>> aovs;  // (channel name, kind)
    // What the loader accepted but ignored, or changed ("file:line:column: note: ..."), for the
    // command line to print.
    std::vector<std::string> notes;
};

}  // namespace pathlab

// pathlab benchmarks (not tests); each subcommand prints Markdown tables.
//
//   pathlab_bench perf     throughput, thread scaling, Embree's bound, scene growth, memory and
//                          pt-mis efficiency over time (`make bench`; also writes JSON)
//   pathlab_bench direct   RMSE of 1, 2a, 2b, 2c, 3 at equal spp and equal time
//   pathlab_bench pt       the same for the path tracers 4a, 4b, 4c
//   pathlab_bench lt       light tracing: paths/s next to pt-mis, and splat accumulation
//   pathlab_bench bdpt     bdpt against pt-mis: equal-time RMSE, and samples per second
//   pathlab_bench bidir    pt-mis, bdpt, bpm, vcm on SmallVCM's kind of scene: time per iteration, MSE per sample, efficiency
//   pathlab_bench pm       photons per second; hashed grid against k-d tree (build, query)
//   pathlab_bench ic       irradiance caching and pbgi against pt-mis and bdpt at short budgets
//   pathlab_bench pbgi-gather  pbgi's gather against a ray-traced truth per cutoff and micro-buffer
//   pathlab_bench volumes  volpath: samples/s, equal-time RMSE with and without MIS, optical thickness
//   pathlab_bench distributed  2 MPI ranks against 1 process, film reduction, checkpoints
//   pathlab_bench many-lights   light samplers (uniform, power, bvh, bvh with splitting, ris) at equal time; the light BVH's build time and memory
//   pathlab_bench lights   an environment map's cost per sample against the constant environment; spot and IES
//   pathlab_bench textures textured against constant materials per sample; texture lookups
//   pathlab_bench diff     a gradient's cost (path replay) relative to a primal render, its memory vs spp and depth
//   pathlab_bench display  the cost of --display-server (samples/s with and without a viewer), time to the first image
//   pathlab_bench spectral the spectral layer's building blocks: wavelength sampling, RGB upsampling, the XYZ film estimator
#include <CLI/CLI.hpp>

#include "bidir_efficiency.hpp"
#include "bidirectional.hpp"
#include "differentiable.hpp"
#include "display.hpp"
#include "distributed.hpp"
#include "estimator_efficiency.hpp"
#include "light_tracing.hpp"
#include "irradiance_caching.hpp"
#include "lights.hpp"
#include "many_lights.hpp"
#include "photon_mapping.hpp"
#include "performance.hpp"
#include "spectral.hpp"
#include "spectral_mode.hpp"
#include "volumes.hpp"
#include "textures.hpp"

int main(int argc, char** argv) {
    using namespace pathlab::bench;
    CLI::App app{"pathlab benchmarks"};
    app.require_subcommand(1);

    PerfOptions p;
    CLI::App* perf = app.add_subcommand("perf", "Throughput, scaling, Embree bound, scene growth, efficiency over time");
    perf->add_option("--size", p.size, "Image width and height for throughput")->capture_default_str();
    perf->add_option("--seconds", p.seconds, "Seconds per timed render")->capture_default_str();
    perf->add_option("--repeats", p.repeats, "Timed renders per figure (median reported)")->capture_default_str();
    perf->add_option("--scenes", p.scenes, "Scene indices")->delimiter(',')->capture_default_str();
    perf->add_option("--mesh-sizes", p.mesh_sizes, "Triangle counts for the growth table (0: plain box)")
        ->delimiter(',')
        ->capture_default_str();
    perf->add_option("--efficiency-ref-spp", p.efficiency_ref_spp, "Reference spp for the efficiency table")
        ->capture_default_str();
    perf->add_option("--checkpoints", p.checkpoints, "Seconds at which pt-mis RMSE is measured")
        ->delimiter(',')
        ->capture_default_str();
    perf->add_option("--json", p.json, "JSON output file ('' for none)")->capture_default_str();
    perf->add_option("--sections", p.sections, "The tables to measure")
        ->delimiter(',')
        ->check(CLI::IsMember({"throughput", "bound", "growth", "efficiency"}))
        ->capture_default_str();

    EfficiencyOptions e;
    std::vector<CLI::App*> tables = {app.add_subcommand("direct", "Direct-illumination estimators 1, 2a, 2b, 2c, 3"),
                                     app.add_subcommand("pt", "Path tracers 4a, 4b, 4c")};
    for (CLI::App* sub : tables) {
        sub->add_option("--size", e.size, "Image width and height")->capture_default_str();
        sub->add_option("--ref-spp", e.ref_spp, "Samples per pixel of the reference")->capture_default_str();
        sub->add_option("--spp", e.spp, "Samples per pixel for the equal-spp column")->capture_default_str();
        sub->add_option("--seconds", e.seconds, "Time per render for the equal-time column")->capture_default_str();
        sub->add_option("--repeats", e.repeats, "Timed runs per cell (median reported)")->capture_default_str();
        sub->add_option("--scenes", e.scenes, "Comma-separated scene indices")->capture_default_str();
    }
    LightTracingOptions l;
    CLI::App* lt = app.add_subcommand("lt", "Light tracing: lt paths/s next to pt-mis, and splat accumulation");
    lt->add_option("--size", l.size, "Image width and height for the throughput table")->capture_default_str();
    lt->add_option("--seconds", l.seconds, "Seconds per timed render")->capture_default_str();
    lt->add_option("--repeats", l.repeats, "Timed pairs per scene (median reported)")->capture_default_str();
    lt->add_option("--scenes", l.scenes, "Scene indices")->delimiter(',')->capture_default_str();
    BidirectionalOptions b;
    CLI::App* bd = app.add_subcommand("bdpt", "bdpt against pt-mis: equal-time RMSE, and samples per second");
    bd->add_option("--size", b.size, "Image width and height for the equal-time table")->capture_default_str();
    bd->add_option("--seconds", b.seconds, "Seconds per timed render")->capture_default_str();
    bd->add_option("--repeats", b.repeats, "Timed pairs per scene (median reported)")->capture_default_str();
    bd->add_option("--ref-spp", b.ref_spp, "Samples per pixel of each reference (bdpt)")->capture_default_str();
    bd->add_option("--scenes", b.scenes, "Course scene indices and scene files of scenes/")->delimiter(',')->capture_default_str();
    BidirEfficiencyOptions be;
    CLI::App* bec = app.add_subcommand("bidir", "pt-mis, bdpt, bpm and vcm on SmallVCM's kind of scene: time per iteration, MSE per sample, efficiency");
    bec->add_option("--size", be.size, "Image width and height")->capture_default_str();
    bec->add_option("--iterations", be.iterations, "Iterations (samples per pixel) per timed render")->capture_default_str();
    bec->add_option("--repeats", be.repeats, "Timed renders per method (median reported)")->capture_default_str();
    bec->add_option("--ref-spp", be.ref_spp, "Samples per pixel of each reference (bdpt)")->capture_default_str();
    bec->add_option("--scenes", be.scenes, "Scene files of scenes/")->delimiter(',')->capture_default_str();
    bec->add_option("--algorithms", be.algorithms, "Methods (the efficiencies are relative to the first); NAME:radius=R (the photon methods' first radius), NAME:max_depth=D, NAME:rr_depth=R, ppg:guiding_spp=N, ppg:guiding_rr=1, ppg:guiding_fraction=learned, upbp:estimators=bpt+pb2d")
        ->delimiter(',')->capture_default_str();
    bec->add_option("--samplers", be.samplers, "Pixel samplers: independent (the course's), sobol")->delimiter(',')->capture_default_str();
    bec->add_option("--max-depth", be.max_depth, "Bounces at most, for every method and the reference (-1: unlimited)")->capture_default_str();
    bec->add_option("--judge", be.judge,
                    "Images of the first scene from elsewhere (e.g. SmallVCM's .hdr), judged against its reference: LABEL:ITERATIONS:SECONDS=FILE")
        ->delimiter(',');
    PhotonMappingOptions pm;
    CLI::App* pmc = app.add_subcommand("pm", "Photons per second; hashed grid against k-d tree");
    pmc->add_option("--light-paths", pm.light_paths, "Light paths traced per scene")->capture_default_str();
    pmc->add_option("--size", pm.size, "Queries: one per pixel of a size x size image")->capture_default_str();
    pmc->add_option("--repeats", pm.repeats, "Timed repeats (median reported)")->capture_default_str();
    IrradianceCachingOptions icopt;
    CLI::App* icc = app.add_subcommand("ic", "Irradiance caching and pbgi against pt-mis and bdpt at short budgets");
    icc->add_option("--size", icopt.size, "Image width and height")->capture_default_str();
    icc->add_option("--budgets", icopt.budgets, "Seconds per render")->delimiter(',')->capture_default_str();
    icc->add_option("--repeats", icopt.repeats, "Rounds (median reported)")->capture_default_str();
    icc->add_option("--scenes", icopt.scenes, "Course scene indices")->delimiter(',')->capture_default_str();
    VolumesOptions vo;
    CLI::App* vol = app.add_subcommand("volumes", "volpath: samples/s, equal-time RMSE with and without MIS, optical thickness");
    vol->add_option("--size", vo.size, "Image width and height")->capture_default_str();
    vol->add_option("--seconds", vo.seconds, "Seconds per timed render")->capture_default_str();
    vol->add_option("--repeats", vo.repeats, "Rounds (median reported)")->capture_default_str();
    vol->add_option("--ref-spp", vo.ref_spp, "Samples per pixel of each reference")->capture_default_str();
    vol->add_option("--scenes", vo.scenes, "Scene files of scenes/ with media")->delimiter(',')->capture_default_str();
    vol->add_option("--plain-scenes", vo.plain_scenes, "Scene files of scenes/ without media")->delimiter(',')->capture_default_str();
    vol->add_option("--fixed-spp", vo.fixed_spp, "Samples per pixel of the renders without media")->capture_default_str();
    GatherAccuracyOptions gopt;
    CLI::App* gat = app.add_subcommand("pbgi-gather", "pbgi's gather against brute force: error and time per cutoff and micro-buffer");
    gat->add_option("--scenes", gopt.scenes, "Course scene indices")->delimiter(',')->capture_default_str();
    gat->add_option("--points", gopt.points, "First hits per scene")->capture_default_str();
    gat->add_option("--surfels", gopt.surfels, "Surfels (about)")->capture_default_str();
    gat->add_option("--cutoffs", gopt.cutoffs, "Cutoff solid angles")->delimiter(',')->capture_default_str();
    gat->add_option("--resolutions", gopt.resolutions, "Micro-buffer sides")->delimiter(',')->capture_default_str();
    LightsOptions lo;
    DisplayOptions dso;
    CLI::App* dsc = app.add_subcommand("display", "The cost of --display-server: samples/s with and without a viewer, time to the first image");
    dsc->add_option("--size", dso.size, "Image width and height")->capture_default_str();
    dsc->add_option("--seconds", dso.seconds, "Seconds per timed render")->capture_default_str();
    dsc->add_option("--repeats", dso.repeats, "Interleaved pairs (medians reported)")->capture_default_str();
    dsc->add_option("--algorithms", dso.algorithms, "Integrators")->delimiter(',')->capture_default_str();
    dsc->add_option("--scene", dso.scene, "Scene")->capture_default_str();
    CLI::App* lic = app.add_subcommand("lights", "An environment map's cost per sample against the constant environment; spot and IES");
    lic->add_option("--size", lo.size, "Image width and height")->capture_default_str();
    lic->add_option("--seconds", lo.seconds, "Seconds per timed render")->capture_default_str();
    lic->add_option("--repeats", lo.repeats, "Interleaved rounds (median reported)")->capture_default_str();
    lic->add_option("--scenes", lo.scenes, "Course scene indices with an environment")->delimiter(',')->capture_default_str();
    lic->add_option("--map-width", lo.map_width, "Width of the constant environment map")->capture_default_str();
    ManyLightsOptions mlo;
    CLI::App* mlc = app.add_subcommand("many-lights", "Light samplers (uniform, power, bvh, bvh with splitting, ris) at equal time; the light BVH's build time and memory");
    mlc->add_option("--size", mlo.size, "Image width and height")->capture_default_str();
    mlc->add_option("--seconds", mlo.seconds, "Seconds per timed render")->capture_default_str();
    mlc->add_option("--repeats", mlo.repeats, "Interleaved rounds (medians reported)")->capture_default_str();
    mlc->add_option("--ref-spp", mlo.ref_spp, "Samples per pixel of each reference")->capture_default_str();
    mlc->add_option("--scene-files", mlo.scene_files, "Scene files of scenes/")->delimiter(',')->capture_default_str();
    mlc->add_option("--scenes", mlo.scenes, "Course scene indices")->delimiter(',')->capture_default_str();
    mlc->add_option("--algorithms", mlo.algorithms, "Integrators that sample lights")->delimiter(',')->capture_default_str();
    mlc->add_option("--split", mlo.split, "The --light-split of the splitting bvh column")->capture_default_str();
    DistributedOptions dopt;
    CLI::App* dist = app.add_subcommand("distributed", "2 MPI ranks against 1 process, film reduction, checkpoint write and size");
    dist->add_option("--size", dopt.size, "Image width and height of the speedup renders")->capture_default_str();
    dist->add_option("--spp", dopt.spp, "Their samples per pixel")->capture_default_str();
    dist->add_option("--scene", dopt.scene, "Their scene")->capture_default_str();
    dist->add_option("--repeats", dopt.repeats, "Timed runs per figure (median reported)")->capture_default_str();
    dist->add_option("--film-sizes", dopt.film_sizes, "Film sizes reduced and checkpointed")->delimiter(',')->capture_default_str();
    CLI::App* worker = app.add_subcommand("distributed-reduce-worker", "(run by `distributed` under mpirun)");
    worker->group("");
    worker->add_option("--film-sizes", dopt.film_sizes)->delimiter(',');
    worker->add_option("--repeats", dopt.repeats);
    TexturesOptions tx;
    CLI::App* txc = app.add_subcommand("textures", "Textured against constant materials per sample; texture lookups");
    txc->add_option("--size", tx.size, "Image width and height")->capture_default_str();
    txc->add_option("--seconds", tx.seconds, "Seconds per timed render")->capture_default_str();
    txc->add_option("--repeats", tx.repeats, "Interleaved rounds (medians reported)")->capture_default_str();
    txc->add_option("--lookups", tx.lookups, "Texture lookups per timing")->capture_default_str();
    txc->add_option("--scene", tx.scene_file, "The textured scene file (default: scenes/textures.xml)");
    DifferentiableOptions dfo;
    CLI::App* dfc = app.add_subcommand("diff", "A gradient's cost relative to a primal render at equal spp; its memory vs spp and depth");
    dfc->add_option("--size", dfo.size, "Image width and height")->capture_default_str();
    dfc->add_option("--spp", dfo.spp, "Samples per pixel")->capture_default_str();
    dfc->add_option("--repeats", dfo.repeats, "Interleaved rounds (median reported)")->capture_default_str();
    dfc->add_option("--scenes", dfo.scenes, "Course scene indices")->delimiter(',')->capture_default_str();
    dfc->add_option("--texture-scene", dfo.texture_scene, "A scene file with a bitmap texture: a row with its texels bound (\"\": none)");
    dfc->add_option("--media-scene", dfo.media_scene, "A scene file with a homogeneous medium: a row with its sigma_t and albedo bound (\"\": none)");
    SpectralOptions spo;
    CLI::App* spc = app.add_subcommand("spectral", "ns per call of the spectral layer's building blocks (docs/spectral.md)");
    spc->add_option("--count", spo.count, "Calls per timing")->capture_default_str();
    spc->add_option("--repeats", spo.repeats, "Timings per figure (median reported)")->capture_default_str();
    SpectralModeOptions smo;
    CLI::App* smc = app.add_subcommand("spectral-mode", "Spectral mode's cost per sample relative to RGB mode (docs/spectral.md)");
    smc->add_option("--scenes", smo.scenes, "Course scene indices")->delimiter(',')->capture_default_str();
    CLI::Option* sm_files = smc->add_option("--scene-files", smo.scene_files, "Scene files (then course scenes only if --scenes is given)")->delimiter(',');
    smc->add_option("--algorithms", smo.algorithms, "Integrators that render spectrally")->delimiter(',')->capture_default_str();
    smc->add_option("--size", smo.size, "Image width and height")->capture_default_str();
    smc->add_option("--spp", smo.spp, "Samples per pixel per render")->capture_default_str();
    smc->add_option("--repeats", smo.repeats, "Interleaved rounds (medians reported)")->capture_default_str();
    // Under mpirun this program is one rank of the reduction benchmark.
    std::vector<std::string> args(argv, argv + argc);
    CLI11_PARSE(app, argc, argv);
    if (*worker) {
        distributed_reduce_worker(dopt.film_sizes, dopt.repeats, argc, argv);
        return 0;
    }
    if (*gat) pbgi_gather_suite(gopt);
    if (*dist) distributed_suite(dopt, args[0]);
    if (*smc && sm_files->count() > 0 && smc->count("--scenes") == 0) smo.scenes.clear();
    if (*dfc) differentiable_suite(dfo);
    if (*lic) lights_suite(lo);
    if (*dsc) display_suite(dso);
    if (*mlc) many_lights_suite(mlo);
    if (*vol) volumes_suite(vo);
    if (*txc) textures_suite(tx);
    if (*spc) spectral_suite(spo);
    if (*smc) spectral_mode_suite(smo);
    if (*icc) irradiance_caching_suite(icopt);
    if (*pmc) photon_mapping_suite(pm);
    if (*bd) bidirectional_suite(b);
    if (*bec) bidir_efficiency_suite(be);
    if (*lt) light_tracing_suite(l);
    if (*perf) performance_suite(p);
    if (*tables[0]) efficiency_table(e, {"direct-light", "direct-uniform", "direct-cosine", "direct-brdf", "direct-mis"}, "direct-mis");
    if (*tables[1]) efficiency_table(e, {"pt-naive", "pt-mis3", "pt-mis"}, "pt-mis");
    return 0;
}

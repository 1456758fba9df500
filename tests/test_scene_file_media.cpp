// Media in scene files: <medium> at the top level and nested, interior/exterior references, the
// null BSDF and BSDF-less boundaries, the sensor's medium, grid volumes from .vol and .vdb files
// with to_world, and bad input (named with file:line, grid problems naming the grid file, exit
// code 2 from the command line), and every integrator but those that render media refusing a
// scene with one.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <fstream>

#include "cli_runner.hpp"
#include "integrators/integrator.hpp"
#include "job/render_job.hpp"
#include "job/usage_error.hpp"
#include "media/grid_files.hpp"
#include "scene/scene.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {
namespace fs = std::filesystem;

class SceneFileMedia : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::temp_directory_path() / ("pathlab-scene-media-" + std::to_string(::getpid()));
        fs::create_directories(dir_);
        VoxelGrid g;
        g.res = {2, 2, 2};
        g.data = {0, 1, 2, 3, 4, 5, 6, 7};
        write_vol_file(path("grid.vol"), g);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    SceneDescription load(const std::string& body) const {
        return load_scene_text("<scene version=\"3.0.0\">\n" + body + "\n</scene>\n", path("test.xml"), dir_.string());
    }
    // The message of the SceneFileError that loading `body` throws.
    std::string error(const std::string& body) const {
        try {
            load(body);
        } catch (const SceneFileError& e) {
            return e.what();
        }
        ADD_FAILURE() << "no error for " << body;
        return "";
    }
    fs::path dir_;
};

TEST_F(SceneFileMedia, HomogeneousMediaAttachedToShapesAndTheSensor) {
    const SceneDescription d = load(R"(
        <medium type="homogeneous" id="fog">
            <rgb name="sigma_a" value="0.1, 0.2, 0.3"/> <rgb name="sigma_s" value="0.5"/> <float name="scale" value="2"/>
            <phase type="hg"><float name="g" value="0.25"/></phase>
        </medium>
        <sensor type="perspective"><ref name="medium" id="fog"/></sensor>
        <shape type="cube"><bsdf type="null"/><ref name="interior" id="fog"/></shape>
        <shape type="sphere"><bsdf type="dielectric"/>
            <medium type="homogeneous" name="interior"><rgb name="sigma_t" value="3"/><rgb name="albedo" value="0.5"/></medium>
            <ref name="exterior" id="fog"/></shape>
        <shape type="rectangle"><ref name="exterior" id="fog"/></shape>
        <shape type="disk"/>)");
    ASSERT_EQ(d.media.size(), 2u);
    const auto& fog = std::get<HomogeneousMedium>(d.media[0]);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(fog.sigma_t[c], 2 * (0.1f * float(c + 1) + 0.5f), 1e-6f);
        EXPECT_NEAR(fog.sigma_s[c], 1.0f, 1e-6f);
    }
    EXPECT_FLOAT_EQ(std::get<HgPhase>(fog.phase).g, 0.25f);
    const auto& inner = std::get<HomogeneousMedium>(d.media[1]);
    EXPECT_EQ(inner.sigma_s, Rgb(1.5f));
    EXPECT_TRUE(std::holds_alternative<IsotropicPhase>(inner.phase));
    EXPECT_EQ(d.camera_medium, 0);
    ASSERT_EQ(d.meshes.size(), 3u);
    // The null BSDF: an index-matched boundary.
    EXPECT_TRUE(d.meshes[0].media.index_matched);
    EXPECT_EQ(d.meshes[0].media.interior, 0);
    EXPECT_EQ(d.meshes[0].media.exterior, -1);
    // Media but no BSDF: index-matched too (Mitsuba 0.6's reading).
    EXPECT_TRUE(d.meshes[1].media.index_matched);
    EXPECT_EQ(d.meshes[1].media.exterior, 0);
    // No media: an ordinary surface.
    EXPECT_FALSE(d.meshes[2].media.index_matched);
    EXPECT_FALSE(d.meshes[2].media.changes_medium());
    // Glass between two media.
    ASSERT_EQ(d.spheres.size(), 1u);
    EXPECT_FALSE(d.spheres[0].media.index_matched);
    EXPECT_EQ(d.spheres[0].media.interior, 1);
    EXPECT_EQ(d.spheres[0].media.exterior, 0);
    EXPECT_TRUE(d.materials[d.spheres[0].material].is_dielectric());
    EXPECT_NO_THROW(Scene::build(d));
}

TEST_F(SceneFileMedia, NamedNullBsdfAndNestedSensorMedium) {
    const SceneDescription d = load(R"(
        <bsdf type="null" id="boundary"/>
        <sensor type="perspective"><medium type="homogeneous"><rgb name="sigma_t" value="0.5"/></medium></sensor>
        <shape type="sphere"><ref id="boundary"/></shape>)");
    EXPECT_EQ(d.camera_medium, 0);
    EXPECT_TRUE(d.spheres[0].media.index_matched);
    const auto& m = std::get<HomogeneousMedium>(d.media[0]);
    EXPECT_EQ(m.sigma_s, Rgb(0.375f));  // albedo 0.75 by default
}

TEST_F(SceneFileMedia, GridVolumesFromVolAndVdbFilesWithToWorld) {
    write_vdb_file(path("grid.vdb"), [] {
        VoxelGrid g;
        g.res = {2, 2, 2};
        g.data = {1, 1, 2, 3, 4, 5, 6, 7};
        return g;
    }(), "density", 1.0);
    const SceneDescription d = load(R"(
        <medium type="heterogeneous" id="smoke">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value="grid.vol"/>
                <transform name="to_world"><scale value="2"/><translate x="1"/></transform></volume>
            <volume type="constvolume" name="albedo"><rgb name="value" value="0.5, 0.6, 0.7"/></volume>
            <float name="scale" value="3"/>
        </medium>
        <medium type="heterogeneous" id="vdb">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value="grid.vdb"/></volume>
            <rgb name="albedo" value="0.9"/>
        </medium>
        <shape type="cube"><ref name="interior" id="smoke"/></shape>)");
    ASSERT_EQ(d.media.size(), 2u);
    // The unit cube scaled by 2 and moved by x + 1: voxel (1, 0, 1) (value 5) has its centre
    // at unit (0.75, 0.25, 0.75), world (2.5, 0.5, 1.5); the grid's centre (value 3.5) at (2, 1, 1).
    const MediumCoefficients c = medium_coefficients(d.media[0], {2.5f, 0.5f, 1.5f});
    EXPECT_FLOAT_EQ(c.sigma_t.x, 15.0f);
    EXPECT_FLOAT_EQ(c.sigma_s.z, 0.7f * 15.0f);
    EXPECT_FLOAT_EQ(medium_coefficients(d.media[0], {2, 1, 1}).sigma_t.y, 3.5f * 3);
    EXPECT_EQ(medium_coefficients(d.media[0], {0.9f, 1, 1}).sigma_t, Rgb(0.0f));  // outside the grid
    // The .vdb grid: OpenVDB puts voxel (i, j, k) at (i, j, k).
    EXPECT_FLOAT_EQ(medium_coefficients(d.media[1], {1, 0, 1}).sigma_t.x, 5.0f);
    EXPECT_FLOAT_EQ(medium_coefficients(d.media[1], {0.5f, 0.5f, 0.5f}).sigma_t.x, 3.625f);
}

// A constvolume's to_world bounds the medium to the unit cube it places, as in Mitsuba 3 (its
// test_hetero_spectral_sigmat_no_scattering); without one the value is everywhere.
TEST_F(SceneFileMedia, APlacedConstvolumeIsZeroOutsideItsCube) {
    const SceneDescription d = load(R"(
        <medium type="heterogeneous" id="placed">
            <volume type="constvolume" name="sigma_t"><rgb name="value" value="0.5, 0.4, 0.3"/>
                <transform name="to_world"><scale value="2"/><translate x="-1" y="-1" z="-1"/></transform></volume>
            <float name="scale" value="5"/>
        </medium>
        <medium type="heterogeneous" id="everywhere">
            <volume type="constvolume" name="sigma_t"><rgb name="value" value="0.5"/></volume>
        </medium>
        <shape type="cube"><ref name="interior" id="placed"/></shape>)");
    ASSERT_EQ(d.media.size(), 2u);
    for (const Vec3f p : {Vec3f(0.0f), Vec3f(-0.99f, 0.5f, 0.99f), Vec3f(0.9f, -0.9f, 0.0f)}) {
        const Rgb s = medium_coefficients(d.media[0], p).sigma_t;
        EXPECT_FLOAT_EQ(s.x, 2.5f);
        EXPECT_FLOAT_EQ(s.y, 2.0f);
        EXPECT_FLOAT_EQ(s.z, 1.5f);
    }
    for (const Vec3f p : {Vec3f(1.01f, 0.0f, 0.0f), Vec3f(0.0f, -1.2f, 0.0f), Vec3f(3.0f)})
        EXPECT_EQ(medium_coefficients(d.media[0], p).sigma_t, Rgb(0.0f));
    EXPECT_EQ(medium_coefficients(d.media[1], Vec3f(30.0f)).sigma_t, Rgb(0.5f));
}

TEST_F(SceneFileMedia, MistakesAreNamedWithTheirLine) {
    const auto has = [](const std::string& message, const std::string& part) {
        EXPECT_NE(message.find(part), std::string::npos) << message;
    };
    has(error(R"(<shape type="cube"><ref name="interior" id="nothing"/></shape>)"), "test.xml:2:");
    has(error(R"(<shape type="cube"><ref name="interior" id="nothing"/></shape>)"), "no <medium> with id 'nothing'");
    has(error(R"(<medium type="homogeneous" id="m"/><shape type="cube"><ref name="inside" id="m"/></shape>)"),
        "'m' is a medium: refer to it with name=\"interior\"");
    has(error(R"(<medium type="homogeneous" id="m"/><shape type="cube"><ref id="m"/></shape>)"),
        "'m' is a medium: refer to it with name=\"interior\"");
    has(error(R"(<shape type="cube"><medium type="homogeneous" name="side"/></shape>)"), "interior or exterior, not 'side'");
    has(error(R"(<medium type="cloudy"/>)"), "unsupported medium type 'cloudy'; supported: homogeneous, heterogeneous");
    has(error(R"(<medium type="homogeneous"><phase type="rayleigh"/></medium>)"), "supported: isotropic, hg");
    has(error(R"(<medium type="homogeneous"><phase type="hg"><float name="g" value="1"/></phase></medium>)"), "strictly between -1 and 1");
    has(error(R"(<medium type="homogeneous"><rgb name="sigma_t" value="1"/><rgb name="sigma_a" value="1"/></medium>)"),
        "either sigma_a and sigma_s or sigma_t and albedo");
    has(error(R"(<medium type="homogeneous"><rgb name="albedo" value="1.5"/></medium>)"), "albedo must lie in [0, 1]");
    has(error(R"(<medium type="homogeneous"><float name="density" value="1"/></medium>)"), "density");
    has(error(R"(<medium type="heterogeneous"><volume type="gridvolume" name="density"/></medium>)"), "sigma_t or albedo, not 'density'");
    has(error(R"(<medium type="heterogeneous"><volume type="gridvolume" name="sigma_t"/></medium>)"), "needs <string name=\"filename\"");
    has(error(R"(<medium type="heterogeneous"><volume type="gridvolume" name="sigma_t"><string name="filename" value="g.vol"/>
                 <boolean name="use_grid_bbox" value="true"/></volume></medium>)"), "use_grid_bbox = true is not supported");
    has(error(R"(<medium type="heterogeneous"><rgb name="sigma_t" value="1"/>
                 <volume type="constvolume" name="sigma_t"/></medium>)"), "sigma_t is given twice");
    has(error(R"(<shape type="cube"><bsdf type="null"/><emitter type="area"/></shape>)"), "cannot emit");
    has(error(R"(<shape type="cube"><bsdf type="twosided"><bsdf type="null"/></bsdf></shape>)"), "nothing wraps it");
    has(error(R"(<sensor type="perspective"><ref id="nothing"/></sensor>)"), "no <medium> with id 'nothing'");
}

TEST_F(SceneFileMedia, BadGridFilesNameTheSceneLineAndTheGridFile) {
    std::string bytes;
    {
        std::ifstream in(path("grid.vol"), std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    std::ofstream(path("short.vol"), std::ios::binary) << bytes.substr(0, bytes.size() - 1);
    std::ofstream(path("magic.vol"), std::ios::binary) << "LOV" << bytes.substr(3);
    std::string negative = bytes;
    const float minus = -1;
    std::memcpy(negative.data() + 48 + 4, &minus, 4);
    std::ofstream(path("negative.vol"), std::ios::binary) << negative;
    for (const auto& [file, problem] : std::vector<std::pair<std::string, std::string>>{
             {"short.vol", "truncated"}, {"magic.vol", "'VOL'"}, {"negative.vol", "voxel (1, 0, 0) channel 0 is -1"}, {"none.vol", "no such file"}}) {
        const std::string message = error(R"(<medium type="heterogeneous">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value=")" + file + R"("/></volume></medium>)");
        EXPECT_NE(message.find("test.xml:3:"), std::string::npos) << message;
        EXPECT_NE(message.find(path(file)), std::string::npos) << message;
        EXPECT_NE(message.find(problem), std::string::npos) << message;
    }
    // From the command line: exit code 2, both files named.
    std::ofstream(path("scene.xml")) << R"(<scene version="3.0.0">
        <medium type="heterogeneous" id="smoke">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value="short.vol"/></volume>
        </medium>
        <shape type="cube"><ref name="interior" id="smoke"/></shape>
    </scene>)";
    const CliResult r = run({"--scene", path("scene.xml"), "-a", "volpath", "--spp", "1", "-o", path("out.exr")});
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(contains(r.err, path("scene.xml") + ":3:")) << r.err;
    EXPECT_TRUE(contains(r.err, path("short.vol"))) << r.err;
    EXPECT_TRUE(contains(r.err, "truncated")) << r.err;
}

// upbp's beam estimators need homogeneous media: with pb2d or bb1d among its estimators (the
// default) a scene with a grid is refused, saying which estimators and integrators render it;
// without them it renders it; the scene file's estimators are upbp's option. An unknown estimator is refused with the valid names, and
// --estimators is refused for another integrator.
TEST_F(SceneFileMedia, UpbpRefusesGridsForItsPointBeamEstimatorOnly) {
    const std::string rest = R"(<shape type="rectangle"><bsdf type="diffuse"/></shape>
        <shape type="sphere"><point name="center" value="0, 0, 2"/><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>)";
    const SceneDescription grid = load(R"(<medium type="heterogeneous" id="smoke">
            <volume type="gridvolume" name="sigma_t"><string name="filename" value="grid.vol"/></volume></medium>
        <shape type="cube"><bsdf type="null"/><ref name="interior" id="smoke"/></shape>)" + rest);
    const SceneDescription fog = load(R"(<medium type="homogeneous" id="fog"><rgb name="sigma_t" value="1"/></medium>
        <shape type="cube"><bsdf type="null"/><ref name="interior" id="fog"/></shape>)" + rest);
    const auto refusal = [](const SceneDescription& d, const std::string& algorithm, std::optional<std::string> estimators) {
        JobRequest r;
        r.algorithm = algorithm;
        r.estimators = std::move(estimators);
        try {
            RenderJob job(scene_choice_of(d), r);
        } catch (const UsageError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    for (const std::optional<std::string>& e :
         {std::optional<std::string>(), std::optional<std::string>("pb2d"), std::optional<std::string>("bpt,bb1d")}) {
        const std::string why = refusal(grid, "upbp", e);
        EXPECT_TRUE(contains(why, "beam estimators (pb2d, bb1d) need homogeneous media")) << why;
        EXPECT_TRUE(contains(why, "heterogeneous medium 'smoke'")) << why;
        EXPECT_TRUE(contains(why, "--estimators bpt,surf,pp3d")) << why;
        EXPECT_EQ(refusal(fog, "upbp", e), "");
    }
    EXPECT_EQ(refusal(grid, "upbp", std::string("bpt,surf,pp3d")), "");
    SceneDescription listed = fog;
    listed.estimators = "bb1d,bpt";
    JobRequest upbp;
    upbp.algorithm = "upbp";
    listed.photon_beams = 64;
    EXPECT_EQ(RenderJob(scene_choice_of(listed), upbp).integrator_options().estimators, "bpt,bb1d");
    EXPECT_EQ(RenderJob(scene_choice_of(listed), upbp).integrator_options().photon_beams, 64);
    listed.beam_radius = 0.5f;
    EXPECT_EQ(RenderJob(scene_choice_of(listed), upbp).integrator_options().beam_radius, 0.5f);
    JobRequest beams = upbp;
    beams.algorithm = "vcm";
    beams.photon_beams = 16;
    try {
        RenderJob job(scene_choice_of(fog), beams);
        ADD_FAILURE() << "--photon-beams accepted for vcm";
    } catch (const UsageError& e) {
        EXPECT_TRUE(contains(e.what(), "--photon-beams sets how many of upbp's light paths leave photon beams")) << e.what();
    }
    beams.photon_beams.reset();
    beams.beam_radius = 0.1f;
    try {
        RenderJob job(scene_choice_of(fog), beams);
        ADD_FAILURE() << "--beam-radius accepted for vcm";
    } catch (const UsageError& e) {
        EXPECT_TRUE(contains(e.what(), "--beam-radius sets the radius of upbp's beam estimators")) << e.what();
    }
    const std::string unknown = refusal(fog, "upbp", std::string("bpt,bb2d"));
    EXPECT_TRUE(contains(unknown, "unknown estimator 'bb2d'")) << unknown;
    EXPECT_TRUE(contains(unknown, "Valid estimators: bpt, surf, pp3d, pb2d, bb1d")) << unknown;
    EXPECT_TRUE(contains(refusal(fog, "vcm", std::string("pb2d")), "--estimators chooses the estimators upbp combines")) << refusal(fog, "vcm", std::string("pb2d"));
}

// No silent wrong answer: every integrator that does not render media refuses a scene whose
// shapes or camera refer to one (naming the medium, where it is, and the integrators that do),
// rather than render it as if the medium were not there; a medium declared and never used, or
// one of no extinction (a vacuum), changes nothing and is accepted.
TEST_F(SceneFileMedia, IntegratorsWithoutMediaRefuseScenesWithMedia) {
    const std::string rest = R"(<shape type="rectangle"><bsdf type="diffuse"/></shape>
        <shape type="sphere"><point name="center" value="0, 0, 2"/><emitter type="area"><rgb name="radiance" value="1"/></emitter></shape>)";
    const SceneDescription inside = load(R"(<medium type="homogeneous" id="fog"><rgb name="sigma_t" value="1"/></medium>
        <shape type="cube"><bsdf type="null"/><ref name="interior" id="fog"/></shape>)" + rest);
    const SceneDescription camera = load(R"(<sensor type="perspective"><medium type="homogeneous"/></sensor>)" + rest);
    const SceneDescription unused = load(R"(<medium type="homogeneous" id="fog"/>)" + rest);
    const SceneDescription vacuum = load(R"(<medium type="homogeneous" id="fog"><rgb name="sigma_t" value="0"/></medium>
        <shape type="cube"><bsdf type="null"/><ref name="interior" id="fog"/></shape>)" + rest);
    int refusing = 0;
    for (const IntegratorInfo& info : integrators()) {
        JobRequest request;
        request.algorithm = info.name;
        if (info.name == "mmlt") request.max_depth = 6;  // (its chains need a last length)
        EXPECT_NO_THROW(RenderJob(scene_choice_of(unused), request)) << info.name;
        EXPECT_NO_THROW(RenderJob(scene_choice_of(vacuum), request)) << info.name;
        for (const auto& [d, where] : {std::pair{&inside, std::string("homogeneous medium 'fog' (inside mesh")},
                                       std::pair{&camera, "homogeneous medium of " + path("test.xml") + ":2 (the camera is in it)"}}) {
            std::string message;
            try {
                RenderJob job(scene_choice_of(*d), request);
            } catch (const UsageError& e) {
                message = e.what();
            }
            if (info.media) {
                EXPECT_EQ(message, "") << info.name;
                continue;
            }
            EXPECT_TRUE(contains(message, info.name + " does not render participating media")) << message;
            EXPECT_TRUE(contains(message, where)) << message;
            EXPECT_TRUE(contains(message, "The integrators that render media: lt, bdpt, pm, ppm, sppm, bpm, vcm, upbp, volpath, pssmlt, mmlt, ppg")) << message;
            ++refusing;
        }
    }
    EXPECT_EQ(refusing, 2 * (int(integrators().size()) - 12));  // all but lt, bdpt, pm, ppm, sppm, bpm, vcm, upbp, volpath, pssmlt, mmlt, ppg
    // From the command line: exit code 2, and `pathlab algorithms` says which render media.
    std::ofstream(path("fog.xml")) << "<scene version=\"3.0.0\">\n<medium type=\"homogeneous\" id=\"fog\"/>\n"
                                      "<shape type=\"cube\"><ref name=\"interior\" id=\"fog\"/></shape>\n" + rest + "</scene>\n";
    for (const char* a : {"ic", "pt-mis"}) {
        const CliResult r = run({"--scene", path("fog.xml"), "-a", a, "--spp", "1", "--resolution", "8x8", "-o", path("out.exr")});
        EXPECT_EQ(r.code, 2) << r.err;
        EXPECT_TRUE(contains(r.err, "medium 'fog'")) << r.err;
        EXPECT_FALSE(fs::exists(path("out.exr")));
    }
    for (const char* a : {"volpath", "bdpt", "lt", "vcm", "bpm", "sppm", "ppm", "pm"})
        EXPECT_EQ(run({"--scene", path("fog.xml"), "-a", a, "--spp", "1", "--resolution", "8x8", "-q", "-o", path("out.exr")}).code, 0) << a;
    // sppm, ppm and pm's choice of volume estimate: a value they do not know, or another integrator, is refused.
    for (const char* a : {"sppm", "pm"})
        for (const char* v : {"beam", "points"})
            EXPECT_EQ(run({"--scene", path("fog.xml"), "-a", a, "--volume-estimate", v, "--spp", "1", "--resolution", "8x8", "-q", "-o",
                           path("out.exr")}).code, 0) << a << " " << v;
    const CliResult bad = run({"--scene", path("fog.xml"), "-a", "sppm", "--volume-estimate", "lines", "-o", path("bad.exr")});
    EXPECT_EQ(bad.code, 2);
    EXPECT_TRUE(contains(bad.err, "unknown volume estimate 'lines'. Valid estimates: beam, points")) << bad.err;
    const CliResult other = run({"--scene", path("fog.xml"), "-a", "vcm", "--volume-estimate", "points", "-o", path("bad.exr")});
    EXPECT_EQ(other.code, 2);
    EXPECT_TRUE(contains(other.err, "--volume-estimate chooses how sppm, ppm and pm gather photons in media")) << other.err;
    EXPECT_FALSE(fs::exists(path("bad.exr")));
    const CliResult list = run({"algorithms"});
    EXPECT_TRUE(contains(list.out, "Participating media (scenes with a <medium>): lt, bdpt, pm, ppm, sppm, bpm, vcm, upbp, volpath, pssmlt, mmlt, ppg;")) << list.out;
}

}  // namespace
}  // namespace pathlab::test

// Scene files as real Mitsuba scenes write them (docs/scene-format.md): includes, search paths,
// refs and aliases, reconstruction filters, spectra, PLY and serialized meshes, instancing,
// sensors, the new BSDFs and integrator wrappers, and a corpus of exporter-style files.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>

#include <fmt/format.h>
#include <tbb/global_control.h>

#include "core/spectrum.hpp"
#include "geometry/mesh_files.hpp"
#include "job/extra_channels.hpp"
#include "job/usage_error.hpp"
#include "render/pixel_filter.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab {
namespace {

std::string source_path(const std::string& relative) { return std::string(PATHLAB_SOURCE_DIR) + "/" + relative; }

// A fresh folder for one test's files.
std::string temp_dir(const std::string& name) {
    const std::string dir = ::testing::TempDir() + "/pathlab_format_" + name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}
void write_file(const std::string& path, const std::string& text) {
    std::filesystem::create_directories(std::filesystem::path(path).parent_path());
    std::ofstream(path, std::ios::binary) << text;
}

// The error a scene text gives (empty: none).
std::string error_of(const std::string& text, const std::string& dir = ".") {
    try {
        load_scene_text(text, "bad.xml", dir);
    } catch (const SceneFileError& e) {
        return e.what();
    }
    return "";
}

// The z-score bound for `tests` two-sided tests at family-wise false-alarm rate 0.01 (Sidak).
double sidak_z(size_t tests) {
    const double alpha = 1 - std::pow(1 - 0.01, 1.0 / double(tests));
    // Inverse normal tail by bisection on erfc.
    double lo = 0, hi = 10;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (std::erfc(mid / std::sqrt(2.0)) > alpha ? lo : hi) = mid;
    }
    return hi;
}

// ---- structure -------------------------------------------------------------------------------

TEST(SceneFileStructure, IncludesNestedDefaultsAndLoops) {
    const std::string dir = temp_dir("include");
    write_file(dir + "/main.xml", R"(<scene version="3.0.0">
  <include filename="parts/materials.xml"/>
  <shape type="sphere"><float name="radius" value="$r"/><ref id="red"/></shape>
</scene>)");
    // Included from parts/: its own include is relative to it; its <default> applies afterwards.
    write_file(dir + "/parts/materials.xml", R"(<scene version="3.0.0">
  <default name="r" value="2.5"/>
  <include filename="colours.xml"/>
</scene>)");
    write_file(dir + "/parts/colours.xml", R"(<scene version="3.0.0">
  <bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.8, 0.1, 0.1"/></bsdf>
</scene>)");
    const SceneDescription d = load_scene_file(dir + "/main.xml");
    ASSERT_EQ(d.spheres.size(), 1u);
    EXPECT_EQ(d.spheres[0].radius, 2.5f);
    EXPECT_EQ(std::get<PhongMaterial>(d.materials[d.spheres[0].material].model).diffuse, Rgb(0.8f, 0.1f, 0.1f));
    // -D wins over the included default.
    EXPECT_EQ(load_scene_file(dir + "/main.xml", {{"r", "4"}}).spheres[0].radius, 4.0f);

    // A loop is reported with its chain of files, at the include that closes it.
    write_file(dir + "/a.xml", "<scene version=\"3.0.0\">\n  <include filename=\"b.xml\"/>\n</scene>");
    write_file(dir + "/b.xml", "<scene version=\"3.0.0\">\n\n  <include filename=\"a.xml\"/>\n</scene>");
    try {
        load_scene_file(dir + "/a.xml");
        ADD_FAILURE() << "no error for an include loop";
    } catch (const SceneFileError& e) {
        EXPECT_NE(e.message.find("include loop: a.xml includes b.xml includes a.xml"), std::string::npos) << e.what();
        EXPECT_EQ(std::filesystem::path(e.file).filename().string(), "b.xml");
        EXPECT_EQ(e.line, 3);
    }
    // Fan-out without a loop: each level includes the next 8 times, 6 levels deep (8^6 = 262144
    // includes; it ran for minutes and grew without bound): refused at the 4097th include.
    for (int level = 0; level < 6; ++level) {
        std::string text = "<scene version=\"3.0.0\">\n";
        for (int k = 0; k < 8; ++k) text += fmt::format("  <include filename=\"fan{}.xml\"/>\n", level + 1);
        write_file(dir + fmt::format("/fan{}.xml", level), text + "</scene>");
    }
    write_file(dir + "/fan6.xml", "<scene version=\"3.0.0\"><bsdf type=\"diffuse\"/></scene>");
    try {
        load_scene_file(dir + "/fan0.xml");
        ADD_FAILURE() << "no error for an include tree that fans out";
    } catch (const SceneFileError& e) {
        EXPECT_NE(e.message.find("more than 4096 includes in all"), std::string::npos) << e.what();
    }
    // Within the count, too many bytes: a 1 MiB file included 8 x 8 x 8 times (512 MiB).
    write_file(dir + "/big.xml", "<scene version=\"3.0.0\"><!--" + std::string(1 << 20, 'x') + "--></scene>");
    for (int level = 0; level < 3; ++level) {
        std::string text = "<scene version=\"3.0.0\">\n";
        for (int k = 0; k < 8; ++k) text += level < 2 ? fmt::format("  <include filename=\"big{}.xml\"/>\n", level + 1) : "  <include filename=\"big.xml\"/>\n";
        write_file(dir + fmt::format("/big{}.xml", level), text + "</scene>");
    }
    try {
        load_scene_file(dir + "/big0.xml");
        ADD_FAILURE() << "no error for 512 MiB of includes";
    } catch (const SceneFileError& e) {
        EXPECT_NE(e.message.find("the includes bring more than 256 MiB of scene text in all"), std::string::npos) << e.what();
    }
    // A file including itself.
    write_file(dir + "/self.xml", "<scene version=\"3.0.0\"><include filename=\"self.xml\"/></scene>");
    EXPECT_THROW(load_scene_file(dir + "/self.xml"), SceneFileError);
    // An error inside an included file names that file.
    write_file(dir + "/broken.xml", "<scene version=\"3.0.0\">\n<shape type=\"teapot\"/></scene>");
    write_file(dir + "/uses-broken.xml", "<scene version=\"3.0.0\"><include filename=\"broken.xml\"/></scene>");
    try {
        load_scene_file(dir + "/uses-broken.xml");
        ADD_FAILURE();
    } catch (const SceneFileError& e) {
        EXPECT_EQ(std::filesystem::path(e.file).filename().string(), "broken.xml");
        EXPECT_EQ(e.line, 2);
    }
}

TEST(SceneFileStructure, PathsAreSearchedForEveryFile) {
    const std::string dir = temp_dir("paths");
    write_file(dir + "/assets/meshes/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    write_file(dir + "/assets/spectra/flat.spd", "# flat\n360 0.5\n830 0.5\n");
    write_file(dir + "/scene.xml", R"(<scene version="3.0.0">
  <path value="assets/meshes"/>
  <path value="assets/spectra"/>
  <shape type="obj"><string name="filename" value="tri.obj"/>
    <bsdf type="diffuse"><spectrum name="reflectance" filename="flat.spd"/></bsdf></shape>
</scene>)");
    const SceneDescription d = load_scene_file(dir + "/scene.xml");
    ASSERT_EQ(d.meshes.size(), 1u);
    EXPECT_EQ(d.meshes[0].triangles.size(), 1u);
    const Rgb rho = std::get<PhongMaterial>(d.materials[d.meshes[0].material].model).diffuse;
    EXPECT_NEAR(rho.x, 0.5, 2e-3);
    EXPECT_NEAR(rho.y, 0.5, 2e-3);
    EXPECT_NEAR(rho.z, 0.5, 2e-3);
    // Without the <path>, the error lists the folders searched.
    write_file(dir + "/nopath.xml", R"(<scene version="3.0.0"><shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" filename="flat.spd"/></bsdf></shape></scene>)");
    try {
        load_scene_file(dir + "/nopath.xml");
        ADD_FAILURE();
    } catch (const SceneFileError& e) {
        EXPECT_NE(e.message.find("cannot find spectrum file 'flat.spd' (searched: "), std::string::npos) << e.what();
    }
    EXPECT_NE(error_of("<scene version=\"3\"><path value=\"no/such/folder\"/><shape type=\"sphere\"/></scene>", dir).find("folder"),
              std::string::npos);
    // A spectrum file over 16 MiB is refused (it was read cut at 16 MiB, silently).
    std::string big = "# big\n360 0.5\n";
    while (big.size() <= (size_t(1) << 24)) big += "# padding padding padding padding padding padding padding padding\n";
    write_file(dir + "/assets/spectra/big.spd", big + "830 0.5\n");
    write_file(dir + "/big.xml", R"(<scene version="3.0.0"><path value="assets/spectra"/><shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" filename="big.spd"/></bsdf></shape></scene>)");
    try {
        load_scene_file(dir + "/big.xml");
        ADD_FAILURE() << "a 16 MiB spectrum file was read";
    } catch (const SceneFileError& e) {
        EXPECT_NE(e.message.find("at most 16 MiB are read"), std::string::npos) << e.what();
    }
}

TEST(SceneFileStructure, RefsAliasesAndVersions) {
    const SceneDescription d = load_scene_text(R"(<scene version="0.6.0">
  <bsdf type="diffuse" id="white"><rgb name="reflectance" value="0.7"/></bsdf>
  <alias id="white" as="wall"/>
  <shape type="sphere"><ref name="bsdf" id="wall"/></shape>
  <shape type="sphere"><bsdf type="twosided"><ref id="white"/></bsdf></shape>
</scene>)", "t.xml", ".");
    EXPECT_EQ(d.spheres[0].material, d.spheres[0].material);
    EXPECT_EQ(std::get<PhongMaterial>(d.materials[d.spheres[0].material].model).diffuse, Rgb(0.7f));
    EXPECT_TRUE(d.materials[d.spheres[1].material].two_sided);
    for (const char* v : {"0.5.0", "0.6", "2.1.0", "3", "3.5.2"})
        EXPECT_EQ(error_of(fmt::format("<scene version=\"{}\"><shape type=\"sphere\"/></scene>", v)), "") << v;
    for (const char* v : {"0.4.0", "4.0.0", "three", "3.0.0.1", "0"})
        EXPECT_NE(error_of(fmt::format("<scene version=\"{}\"><shape type=\"sphere\"/></scene>", v)).find("unsupported scene version"),
                  std::string::npos) << v;
    // A ref to an object of another kind says what it is.
    const std::string e = error_of(R"(<scene version="3"><shape type="shapegroup" id="g"><shape type="cube"/></shape>
<shape type="sphere"><bsdf type="twosided"><ref id="g"/></bsdf></shape></scene>)");
    EXPECT_NE(e.find("'g' is a <shapegroup>"), std::string::npos) << e;
    // Mitsuba 0.6 camelCase names.
    const SceneDescription old = load_scene_text(R"(<scene version="0.6.0">
  <integrator type="path"><integer name="maxDepth" value="5"/><boolean name="hideEmitters" value="true"/></integrator>
  <sensor type="perspective"><float name="fov" value="30"/><string name="fovAxis" value="y"/>
    <transform name="toWorld"><lookat origin="0,0,5" target="0,0,0" up="0,1,0"/></transform>
    <sampler type="ldsampler"><integer name="sampleCount" value="16"/></sampler>
    <film type="hdrfilm"><integer name="width" value="32"/><integer name="height" value="24"/>
      <string name="fileFormat" value="pfm"/><boolean name="banner" value="false"/><rfilter type="box"/></film></sensor>
  <shape type="obj"><string name="filename" value="scenes/meshes/floor.obj"/><boolean name="faceNormals" value="true"/></shape>
</scene>)", "old.xml", source_path(""));
    EXPECT_EQ(old.max_depth, 4);
    EXPECT_EQ(old.hide_emitters, true);
    EXPECT_EQ(old.spp, 16);
    EXPECT_EQ(old.file_format, "pfm");
    EXPECT_EQ(old.camera.fov_axis, FovAxis::Y);
    EXPECT_FALSE(old.notes.empty());  // ldsampler's pattern is noted
}

TEST(SceneFileStructure, RefusalsNameTheMissingFeature) {
    struct Case {
        std::string body, message;
    };
    const std::vector<Case> cases = {
        {"<sensor type=\"perspective\"><film type=\"hdrfilm\"><rfilter type=\"sinc\"/></film></sensor>",
         "unsupported rfilter type 'sinc'; supported: box, tent, gaussian, mitchell, catmullrom, lanczos"},
        {"<sensor type=\"perspective\"><film type=\"hdrfilm\"><string name=\"pixel_format\" value=\"xyz\"/></film></sensor>",
         "supported: rgb, rgba"},
        {"<integrator type=\"direct\"><integer name=\"emitter_samples\" value=\"4\"/></integrator>", "must be 1"},
        {"<integrator type=\"aov\"><string name=\"aovs\" value=\"a:curvature\"/></integrator>", "unsupported aov kind 'curvature'"},
    };
    for (const Case& c : cases) {
        const std::string e = error_of("<scene version=\"3.0.0\">\n" + c.body + "\n<shape type=\"sphere\"/></scene>");
        EXPECT_NE(e.find(c.message), std::string::npos) << c.body << "\n" << e;
        EXPECT_EQ(e.rfind("bad.xml:2:", 0), 0u) << e;  // file and line
    }
}

// ---- reconstruction filters --------------------------------------------------------------------

TEST(SceneFileFilters, WeightsAndFootprintsAsMitsuba) {
    const auto f = [](const char* type) {
        FilterDesc d;
        d.type = type;
        if (d.type == "tent") d.radius = 1;
        if (d.type == "gaussian") d.radius = 2;
        if (d.type == "mitchell") d.radius = 2;
        if (d.type == "lanczos") d.radius = 3;
        return d;
    };
    EXPECT_EQ(f("box").eval(0.49), 1);
    EXPECT_EQ(f("box").eval(0.51), 0);
    EXPECT_DOUBLE_EQ(f("tent").eval(0.25), 0.75);
    EXPECT_EQ(f("tent").eval(1.0), 0);
    // Mitsuba's gaussian: exp(-x^2 / (2 * 0.25)) - exp(-8), cut at 4 stddev = 2.
    EXPECT_NEAR(f("gaussian").eval(0.5), std::exp(-0.5) - std::exp(-8.0), 1e-12);
    EXPECT_EQ(f("gaussian").eval(2.01), 0);
    // Mitchell-Netravali with B = C = 1/3: 8/9 at 0, 0 at 2, negative between 1 and 2.
    EXPECT_NEAR(f("mitchell").eval(0), 8.0 / 9, 1e-12);
    EXPECT_NEAR(f("mitchell").eval(1), 1.0 / 18, 1e-12);
    EXPECT_LT(f("mitchell").eval(1.5), 0);
    EXPECT_NEAR(f("lanczos").eval(0), 1, 1e-12);
    EXPECT_NEAR(f("lanczos").eval(1), 0, 1e-12);
    EXPECT_NEAR(f("lanczos").eval(0.5), std::sin(M_PI / 2) * std::sin(M_PI / 6) / (M_PI / 2 * M_PI / 6), 1e-12);

    // Partitions of unity (the lattice sums of a pass are 1 in the interior): box, tent, mitchell.
    for (const char* type : {"tent", "mitchell"})
        for (double u : {0.0, 0.13, 0.5, 0.77, 0.999}) {
            double sum = 0;
            for (int o = -3; o <= 3; ++o) sum += f(type).eval(o + u - 0.5);
            EXPECT_NEAR(sum, 1, 1e-12) << type << " u=" << u;
        }
    // Every pass's weights sum to 1 for every pixel, borders included (a flat image stays flat).
    for (const char* type : {"box", "tent", "gaussian", "mitchell", "lanczos"}) {
        FilterDesc d = f(type);
        if (d.type == "box") d.radius = 1.5;
        const PixelFilter pf(d, 7, 5);
        std::vector<Vec3d> flat(35, Vec3d(2.0)), out;
        pf.filter_pass(flat, Vec2f(0.3f, 0.8f), out);
        for (const Vec3d& v : out) EXPECT_NEAR(v.x, 2.0, 1e-12) << type;
        std::vector<Vec3d> splatted(35, Vec3d(0.0));
        pf.splat(Vec2f(0.2f, 4.9f), Vec3d(1.0), splatted);  // a corner
        pf.splat(Vec2f(3.5f, 2.25f), Vec3d(1.0), splatted);
        double total = 0;
        for (const Vec3d& v : splatted) total += v.x;
        EXPECT_GT(total, 0) << type;
    }
}

// An orthographic view of emissive unit squares aligned with the pixels: the image is constant
// within each pixel, so the box image is exact and the tent image's expectation is the box
// image convolved with the tent integrated over a pixel, [1/8, 3/4, 1/8] in each axis.
SceneDescription pixel_squares_scene(const std::string& rfilter) {
    std::string shapes;
    const int lit[][3] = {{2, 2, 4}, {3, 2, 1}, {4, 3, 7}, {2, 5, 2}, {5, 5, 3}};
    for (const auto& s : lit)
        shapes += fmt::format(R"(<shape type="rectangle"><transform name="to_world"><scale value="0.5"/><translate x="{}" y="{}"/></transform>
  <emitter type="area"><rgb name="radiance" value="{}"/></emitter></shape>
)", s[0] - 4 + 0.5, 4 - s[1] - 0.5, s[2]);
    return load_scene_text(fmt::format(R"(<scene version="3.0.0">
  <sensor type="orthographic">
    <transform name="to_world"><scale value="4"/><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="8"/><integer name="height" value="8"/>{}</film>
  </sensor>
  {}
</scene>)", rfilter, shapes), "squares.xml", ".");
}

TEST(SceneFileFilters, TentImageIsTheBoxImageConvolvedWithTheTent) {
    const RenderResult box = test::render_scene(pixel_squares_scene("<rfilter type=\"box\"/>"), "direct-mis", 8, 8, 16, 5);
    const RenderResult tent = test::render_scene(pixel_squares_scene("<rfilter type=\"tent\"/>"), "direct-mis", 8, 8, 256, 5);
    const Image b = box.film.mean(), t = tent.film.mean(), se = tent.film.standard_error();
    // The box image is the squares' radiance, exactly.
    int lit = 0;
    for (size_t i = 0; i < b.pixel_count(); ++i) {
        EXPECT_TRUE(b[i].x == 0 || b[i].x == 1 || b[i].x == 2 || b[i].x == 3 || b[i].x == 4 || b[i].x == 7) << b[i].x;
        lit += b[i].x > 0;
    }
    EXPECT_EQ(lit, 5);
    const double k[3] = {0.125, 0.75, 0.125};
    const double z = sidak_z(64);
    int tested = 0;
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            double expected = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx)
                    if (x + dx >= 0 && x + dx < 8 && y + dy >= 0 && y + dy < 8)
                        expected += k[dx + 1] * k[dy + 1] * b[size_t((y + dy) * 8 + x + dx)].x;
            const size_t i = size_t(y * 8 + x);
            if (se[i].x == 0) {
                EXPECT_NEAR(t[i].x, expected, 1e-6) << x << "," << y;
            } else {
                EXPECT_LT(std::abs(t[i].x - expected) / se[i].x, z) << x << "," << y << ": " << t[i].x << " vs " << expected;
                ++tested;
            }
        }
    EXPECT_GT(tested, 20);
}

// A <film> without an <rfilter> has Mitsuba's default filter, the Gaussian of standard deviation
// 0.5 pixels (Mitsuba 3 and 0.6 render such a scene so); a scene without a <film> renders on
// pathlab's own film (box).
TEST(SceneFileFilters, AFilmWithoutAnRfilterHasMitsubasGaussian) {
    const auto filter_of = [](const std::string& film) {
        return load_scene_text("<scene version=\"3.0.0\"><sensor type=\"perspective\">" + film + "</sensor><shape type=\"sphere\"/></scene>",
                               "f.xml", ".")
            .filter;
    };
    const FilterDesc unnamed = filter_of("<film type=\"hdrfilm\"/>"), given = filter_of("<film type=\"hdrfilm\"><rfilter type=\"gaussian\"/></film>");
    EXPECT_EQ(unnamed.type, "gaussian");
    EXPECT_EQ(unnamed.stddev, 0.5);
    EXPECT_EQ(unnamed.radius, 2.0);
    EXPECT_EQ(given.type, unnamed.type);
    EXPECT_EQ(given.stddev, unnamed.stddev);
    EXPECT_EQ(given.radius, unnamed.radius);
    EXPECT_TRUE(filter_of("").is_box());
    EXPECT_EQ(filter_of("").radius, 0.5);
    EXPECT_TRUE(filter_of("<film type=\"hdrfilm\"><rfilter type=\"box\"/></film>").is_box());
}

TEST(SceneFileFilters, BoxIsTodaysFilmAndFilteredRendersAreDeterministic) {
    const SceneDescription plain = load_scene_file(source_path("scenes/3-ceiling-glossy.xml"));
    SceneDescription boxed = plain;
    boxed.filter = FilterDesc{};  // <rfilter type="box"/>: radius 0.5
    EXPECT_TRUE(test::bit_identical(test::render_scene(plain, "pt-mis", 16, 16, 2, 3).film.mean(),
                                    test::render_scene(boxed, "pt-mis", 16, 16, 2, 3).film.mean()));
    SceneDescription gauss = plain;
    gauss.filter.type = "gaussian";
    gauss.filter.radius = 2;
    const Image one = [&] {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        return test::render_scene(gauss, "pt-mis", 16, 12, 3, 3).film.mean();
    }();
    const Image two = [&] {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        return test::render_scene(gauss, "pt-mis", 16, 12, 3, 3).film.mean();
    }();
    EXPECT_TRUE(test::bit_identical(one, two));
    // Integrators that add samples without the filter refuse it.
    JobRequest r;
    r.algorithm = "sppm";
    EXPECT_THROW(RenderJob(scene_choice_of(gauss), r), UsageError);
}

// The pixel-channels where two renders of a 10 x 10 image differ by more than sidak_z(300) (a
// family-wise false-alarm rate of 0.01 over its 300 channels) of their joint standard error.
int channels_apart(const RenderResult& x, const RenderResult& y) {
    const Image a = x.film.mean(), b = y.film.mean(), sa = x.film.standard_error(), sb = y.film.standard_error();
    const double z = sidak_z(300);
    int apart = 0;
    for (size_t i = 0; i < a.pixel_count(); ++i)
        for (int c = 0; c < 3; ++c) {
            const double s = std::sqrt(double(sa[i][c]) * sa[i][c] + double(sb[i][c]) * sb[i][c]);
            if (s > 0 && std::abs(double(a[i][c]) - b[i][c]) / s > z) ++apart;
        }
    return apart;
}

// Light tracing splats through the same filter weights g_q(r) as the camera side's lattice, so
// with a tent filter, and with Mitsuba's default Gaussian (whose lattice sums are not 1), lt and
// pt-mis estimate the same filtered image (per-pixel z-tests, Sidak over the pixels; the course's
// diffuse scene, which lt sees whole).
TEST(SceneFileFilters, LightTracingAndPathTracingAgreeThroughTheFilter) {
    for (const FilterDesc& filter : {FilterDesc{"tent", 1.0}, FilterDesc{"gaussian", 2.0, 0.5}}) {
        SceneDescription d = load_scene_file(source_path("scenes/2-ceiling-diffuse.xml"));
        d.filter = filter;
        const RenderResult pt = test::render_scene(d, "pt-mis", 10, 10, 128, 21);
        const RenderResult lt = test::render_scene(d, "lt", 10, 10, 512, 22);
        EXPECT_EQ(channels_apart(pt, lt), 0) << filter.type;
    }
}

// ---- spectra ---------------------------------------------------------------------------------

TEST(SceneFileSpectrum, FlatD65AndTheCieIntegral) {
    // The 5 nm CIE 1931 table's integral of ybar (the 1 nm table's is 106.857).
    EXPECT_NEAR(cie_y_integral(), 106.86, 0.05);
    SampledSpectrum flat{{360, 830}, {0.4, 0.4}};
    const Vec3d grey = spectrum_to_linear_srgb(flat, SpectrumUse::Reflectance);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(grey[c], 0.4, 2e-4) << c;  // D65 is sRGB's white
    // A flat illuminant has the luminance of its value and illuminant E's colour.
    const Vec3d e = spectrum_to_xyz(flat, SpectrumUse::Illuminant);
    EXPECT_NEAR(e.y, 0.4, 1e-6);
    EXPECT_NEAR(e.x / e.y, 1.0, 2e-3);
    EXPECT_NEAR(e.z / e.y, 1.0, 2e-3);
    // A flat reflectance over part of the range: the CIE integral over that part.
    SampledSpectrum part{{500, 600}, {1, 1}};
    double d65y = 0;
    for (double l = 500.025; l < 600; l += 0.05) d65y += cie_d65(l) * cie1931_xyz_bar(l).y * 0.05;
    EXPECT_NEAR(spectrum_to_xyz(part, SpectrumUse::Reflectance).y, d65y / cie_d65_y_integral(), 1e-5);
    // The D65 illuminant itself is white.
    SampledSpectrum d65;
    for (double l = 360; l <= 830; l += 5) d65.wavelengths.push_back(l), d65.values.push_back(cie_d65(l) / 100);
    const Vec3d white = spectrum_to_linear_srgb(d65, SpectrumUse::Illuminant);
    EXPECT_NEAR(white.x / white.y, 1.0, 2e-3);
    EXPECT_NEAR(white.z / white.y, 1.0, 2e-3);
    // Parsing: pairs, files; errors named.
    SampledSpectrum s;
    EXPECT_EQ(parse_spectrum_pairs("400:0.1, 500:0.2 600:0.3", s), "");
    EXPECT_EQ(s.values.size(), 3u);
    EXPECT_NE(parse_spectrum_pairs("400:0.1, 300:0.2", s).find("increase"), std::string::npos);
    EXPECT_NE(parse_spectrum_pairs("400:0.1", s).find("at least two"), std::string::npos);
    EXPECT_EQ(parse_spectrum_file("# c\n400 1\n\n700 2 # x\n", s), "");
    EXPECT_NE(parse_spectrum_file("400 1\n700\n", s).find("line 2"), std::string::npos);
}

TEST(SceneFileSpectrum, ElementsConvertAsMitsubasRgbMode) {
    const SceneDescription d = load_scene_text(R"(<scene version="3.0.0">
  <shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" value="360:0.3, 830:0.3"/></bsdf>
    <emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape>
  <shape type="sphere"><bsdf type="diffuse"><srgb name="reflectance" value="#808080"/></bsdf></shape>
  <shape type="sphere"><bsdf type="diffuse"><spectrum name="reflectance" value="0.25"/></bsdf></shape>
</scene>)", "s.xml", ".");
    const Rgb rho = std::get<PhongMaterial>(d.materials[d.spheres[0].material].model).diffuse;
    EXPECT_NEAR(rho.x, 0.3, 1e-3);
    EXPECT_NEAR(rho.z, 0.3, 1e-3);
    // Mitsuba 3: an emitter's uniform spectrum is illuminant E in sRGB (0.6 kept it grey).
    const Vec3d e = xyz_to_linear_srgb(Vec3d(1.0)) * 2.0;
    EXPECT_NEAR(d.spheres[0].emission.x, e.x, 1e-5);
    EXPECT_NEAR(d.spheres[0].emission.z, e.z, 1e-5);
    EXPECT_NEAR(std::get<PhongMaterial>(d.materials[d.spheres[1].material].model).diffuse.x, 0.2158605, 1e-5);  // sRGB 128/255 decoded
    EXPECT_EQ(std::get<PhongMaterial>(d.materials[d.spheres[2].material].model).diffuse, Rgb(0.25f));
    const SceneDescription old = load_scene_text(
        R"(<scene version="0.6.0"><shape type="sphere"><emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape></scene>)", "o.xml", ".");
    EXPECT_EQ(old.spheres[0].emission, Rgb(2.0f));
}

// ---- meshes ------------------------------------------------------------------------------------

// A small mesh with normals and uvs (a bent strip), as OBJ, ASCII PLY, binary PLY, serialized.
struct MeshFiles {
    std::string obj, ply_ascii, ply_binary, serialized;
};
MeshFiles write_mesh_files(const std::string& dir) {
    MeshDesc m;
    for (int i = 0; i < 5; ++i)
        for (int j = 0; j < 2; ++j) {
            // Dyadic numbers: every parser reads them to the same float (Assimp's ASCII PLY
            // reader is not correctly rounded for others); normals need not be unit length.
            const float x = -1.0f + 0.5f * float(i), z = 0.25f * float((i * i) % 3) - 0.25f;
            m.positions.push_back({x, float(j) * 1.5f - 0.75f, z});
            m.normals.push_back(Vec3f(0.25f * float(i) - 0.5f, 0.125f, 1.0f));
            m.uvs.push_back({0.25f * float(i), float(j)});
        }
    for (uint32_t i = 0; i < 4; ++i) {
        m.triangles.push_back({2 * i, 2 * i + 2, 2 * i + 3});
        m.triangles.push_back({2 * i, 2 * i + 3, 2 * i + 1});
    }
    MeshFiles f{dir + "/m.obj", dir + "/m_ascii.ply", dir + "/m_binary.ply", dir + "/m.serialized"};
    std::string obj, ply_header = fmt::format("ply\nformat {{}} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n"
                                              "property float nx\nproperty float ny\nproperty float nz\nproperty float u\nproperty float v\n"
                                              "element face {}\nproperty list uchar int vertex_indices\nend_header\n",
                                              m.positions.size(), m.triangles.size());
    // OBJ flips v on reading (as Mitsuba): write 1 - v so both files hold the same uvs.
    for (size_t i = 0; i < m.positions.size(); ++i)
        obj += fmt::format("v {:.9g} {:.9g} {:.9g}\nvn {:.9g} {:.9g} {:.9g}\nvt {:.9g} {:.9g}\n", m.positions[i].x, m.positions[i].y,
                           m.positions[i].z, m.normals[i].x, m.normals[i].y, m.normals[i].z, m.uvs[i].x, 1 - m.uvs[i].y);
    for (const auto& t : m.triangles)
        obj += fmt::format("f {0}/{0}/{0} {1}/{1}/{1} {2}/{2}/{2}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    write_file(f.obj, obj);
    std::string ascii = fmt::format(fmt::runtime(ply_header), "ascii");
    for (size_t i = 0; i < m.positions.size(); ++i)
        ascii += fmt::format("{:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g}\n", m.positions[i].x, m.positions[i].y, m.positions[i].z,
                             m.normals[i].x, m.normals[i].y, m.normals[i].z, m.uvs[i].x, m.uvs[i].y);
    for (const auto& t : m.triangles) ascii += fmt::format("3 {} {} {}\n", t[0], t[1], t[2]);
    write_file(f.ply_ascii, ascii);
    std::string binary = fmt::format(fmt::runtime(ply_header), "binary_little_endian");
    for (size_t i = 0; i < m.positions.size(); ++i) {
        const float v[8] = {m.positions[i].x, m.positions[i].y, m.positions[i].z, m.normals[i].x, m.normals[i].y, m.normals[i].z, m.uvs[i].x, m.uvs[i].y};
        binary.append(reinterpret_cast<const char*>(v), sizeof v);
    }
    for (const auto& t : m.triangles) {
        binary += char(3);
        const int32_t idx[3] = {int32_t(t[0]), int32_t(t[1]), int32_t(t[2])};
        binary.append(reinterpret_cast<const char*>(idx), sizeof idx);
    }
    write_file(f.ply_binary, binary);
    write_file(f.serialized, serialized_mesh_bytes(m));
    return f;
}

SceneDescription mesh_scene(const std::string& shape, const std::string& dir) {
    return load_scene_text(fmt::format(R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="50"/>
    <transform name="to_world"><lookat origin="0.3, -0.4, 3" target="0, 0, 0" up="0, 1, 0"/></transform></sensor>
  {}
  <shape type="rectangle"><transform name="to_world"><scale value="5"/><translate z="-1"/></transform></shape>
  <emitter type="constant"><rgb name="radiance" value="1"/></emitter>
  <emitter type="point"><point name="position" value="1, 1, 2"/><rgb name="intensity" value="5"/></emitter>
</scene>)", shape), "m.xml", dir);
}

TEST(SceneFileMeshes, PlyAndSerializedRenderAsTheSameObj) {
    const std::string dir = temp_dir("meshes");
    const MeshFiles f = write_mesh_files(dir);
    const auto render = [&](const std::string& shape) {
        return test::render_scene(mesh_scene(shape, dir), "pt-mis", 20, 16, 2, 11).film.mean();
    };
    const std::string glossy = R"(<bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf>)";
    const Image obj = render(R"(<shape type="obj"><string name="filename" value="m.obj"/>)" + glossy + "</shape>");
    for (const char* s : {R"(<shape type="ply"><string name="filename" value="m_ascii.ply"/>)",
                                 R"(<shape type="ply"><string name="filename" value="m_binary.ply"/>)",
                                 R"(<shape type="serialized"><string name="filename" value="m.serialized"/>)"})
        EXPECT_TRUE(test::bit_identical(obj, render(s + glossy + "</shape>"))) << s;
    // The files' data, vertex for vertex (the loaders neither weld nor reorder).
    const MeshDesc a = load_ply_mesh(f.ply_binary), b = load_serialized_mesh(f.serialized, 0), c = load_ply_mesh(f.ply_ascii);
    ASSERT_EQ(a.triangles.size(), b.triangles.size());
    ASSERT_EQ(c.triangles.size(), b.triangles.size());
    for (size_t t = 0; t < a.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) {  // corner by corner, whatever the vertex numbering
            EXPECT_EQ(a.positions[a.triangles[t][size_t(k)]], b.positions[b.triangles[t][size_t(k)]]);
            EXPECT_EQ(a.normals[a.triangles[t][size_t(k)]], b.normals[b.triangles[t][size_t(k)]]);
            EXPECT_EQ(c.uvs[c.triangles[t][size_t(k)]], b.uvs[b.triangles[t][size_t(k)]]);
        }
    // A wrong shape index and a corrupt file are named.
    EXPECT_THROW(load_serialized_mesh(f.serialized, 1), MeshLoadError);
    write_file(dir + "/bad.serialized", std::string("\x1c\x04\x04\x00garbage garbage\x00\x00\x00\x00\x00\x00\x00\x00\x01\x00\x00\x00", 32));
    EXPECT_THROW(load_serialized_mesh(dir + "/bad.serialized", 0), MeshLoadError);
    write_file(dir + "/bad.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n");
    EXPECT_THROW(load_ply_mesh(dir + "/bad.ply"), MeshLoadError);
}

// Hostile PLY files are refused before Assimp reads them (issue 45): a header that never ends
// (Assimp hung on it), a misspelled end_header in a binary file (Assimp crashed), counts that the
// file cannot hold (a 198-byte file claiming 1e9 vertices grew to 9.8 GB; a list's count),
// unknown lines.
TEST(SceneFileMeshes, HostilePlyHeadersAreRefusedWithTheirProblem) {
    const std::string dir = temp_dir("hostile-ply");
    const auto refused = [&](const std::string& name, const std::string& bytes, const std::string& problem) {
        write_file(dir + "/" + name, bytes);
        try {
            load_ply_mesh(dir + "/" + name);
            ADD_FAILURE() << name << " was accepted";
        } catch (const MeshLoadError& e) {
            EXPECT_NE(std::string(e.what()).find(problem), std::string::npos) << name << ": " << e.what();
            EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
        }
    };
    const std::string vertex = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
    std::string endless = "ply\nformat ascii 1.0\n" + vertex;
    for (int i = 0; i < 1000; ++i) endless += "0 0 0\n";
    refused("endless.ply", endless, "header line 7: unknown header line '0 0 0'");
    refused("unended.ply", "ply\nformat ascii 1.0\n" + vertex, "no end_header line");
    std::string misspelled = "ply\nformat binary_little_endian 1.0\n" + vertex + "end_headr\n";
    misspelled.append(36, '\0');
    refused("misspelled.ply", misspelled, "unknown header line 'end_headr'");
    refused("billion.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\nend_header\n", "too large");
    refused("claims.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 1000000\nproperty float x\nend_header\n0000",
            "need at least 4000000 bytes, the file holds 4 after it");
    refused("ascii-claims.ply", "ply\nformat ascii 1.0\n" + vertex + "end_header\n0 0 0\n", "need at least 17 bytes");
    refused("no-format.ply", "ply\n" + vertex + "end_header\n", "no format line");
    refused("not-ply.ply", "PLY\nformat ascii 1.0\nend_header\n", "starts with the line 'ply'");
    refused("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\nend_header\n0\n", "unknown property type 'real'");
    // Lists whose count the file cannot hold: an ASCII face claiming 20 million indices, followed
    // by 3, became a polygon of 20 million zeros (2.8 GB, exit 0); binary ones too, and negative,
    // non-integer and cut-short counts.
    const std::string faces = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
    const std::string ascii = "ply\nformat ascii 1.0\n" + vertex + faces + "0 0 0\n1 0 0\n0 1 0\n";
    refused("ascii-list.ply", ascii + "20000000 0 1 2\n", "its list 'vertex_indices' claims 20000000 values, more than the file holds");
    refused("ascii-short.ply", ascii + "5 0 1 2\n", "the file ends inside element 'face' (item 1 of 1), in its list 'vertex_indices' of 5 values");
    refused("ascii-count.ply", ascii + "3.5 0 1 2\n", "its list 'vertex_indices' has the count '3.5', not a count");
    refused("ascii-negative.ply", ascii + "-3 0 1 2\n", "has the count '-3', not a count");
    // ASCII values that are no numbers (Assimp read "-1" and control characters as -1 and leaked
    // its parser's state: the fuzzer's finding), in a vertex and in a list.
    refused("ascii-value.ply", "ply\nformat ascii 1.0\n" + vertex + faces + "0 0 0\n1 0 0\n-1\x12\x12 1 0\n3 0 1 2\n",
            "element 'vertex' (item 3 of 3): its property 'x' is '-1\\x12\\x12', not a number");
    refused("ascii-index.ply", ascii + "3 0 one 2\n", "element 'face' (item 1 of 1): its property 'vertex_indices' is 'one', not a number");
    const auto binary = [&](const std::string& count_type, const std::string& count) {
        std::string b = "ply\nformat binary_little_endian 1.0\n" + vertex + "element face 1\nproperty list " + count_type +
                        " int vertex_indices\nend_header\n";
        b.append(36, '\0');
        return b + count + std::string(12, '\0');
    };
    refused("binary-list.ply", binary("uint", std::string("\x00\xca\x9a\x3b", 4)), "claims 1000000000 values, more than the file holds after it (12 bytes)");
    refused("binary-negative.ply", binary("int", "\xfd\xff\xff\xff"), "claims -1 values");
    // A list whose values take the bytes of the elements after it (the file is as long as the
    // header's smallest body, so only the walk finds it).
    std::string eaten = "ply\nformat binary_little_endian 1.0\nelement face 1\nproperty list uchar int vertex_indices\n" + vertex + "end_header\n";
    eaten += std::string("\x09", 1) + std::string(36, '\0');
    refused("list-eats-vertices.ply", eaten, "the file ends inside element 'vertex' (3 items of 12 bytes)");
    EXPECT_EQ(load_ply_mesh((write_file(dir + "/binary.ply", binary("uchar", "\x03")), dir + "/binary.ply")).triangles.size(), 1u);
    // The smallest body the header allows is accepted (3 ASCII values need 5 bytes: "0 0 0").
    write_file(dir + "/tight.ply", "ply\nformat ascii 1.0\n" + vertex + "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                  "0 0 0\n1 0 0\n0 1 0\n3 0 1 2");
    EXPECT_EQ(load_ply_mesh(dir + "/tight.ply").triangles.size(), 1u);
}

TEST(SceneFileMeshes, InstancesRenderAsTheGeometryWrittenOut) {
    const std::string dir = temp_dir("instances");
    write_mesh_files(dir);
    // Transforms whose object-space rays are exact (identity, powers of two, sign flips), so
    // Embree's hits are the same bits as on the flattened meshes.
    // (A translation is exact only for some coordinates, so none is used: the copies overlap, but
    // none of their faces are coplanar.)
    const char* transforms[] = {"", "<scale value=\"0.5\"/>", "<scale x=\"-1\" z=\"-1\"/>"};
    std::string instanced = R"(<shape type="shapegroup" id="g"><shape type="obj"><string name="filename" value="m.obj"/>
      <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>
      <shape type="cube"><transform name="to_world"><scale value="0.25"/><translate z="0.5"/></transform></shape></shape>)";
    std::string flat;
    for (const char* t : transforms) {
        instanced += fmt::format(R"(<shape type="instance"><ref id="g"/><transform name="to_world">{}</transform></shape>)", t);
        flat += fmt::format(R"(<shape type="obj"><string name="filename" value="m.obj"/><transform name="to_world">{}</transform>
          <bsdf type="roughconductor"><float name="alpha" value="0.3"/></bsdf></shape>
          <shape type="cube"><transform name="to_world"><scale value="0.25"/><translate z="0.5"/>{}</transform></shape>)", t, t);
    }
    const SceneDescription a = mesh_scene(instanced, dir), b = mesh_scene(flat, dir);
    EXPECT_EQ(a.instances.size(), 3u);
    EXPECT_EQ(a.groups.size(), 1u);
    const RenderResult ra = test::render_scene(a, "pt-mis", 24, 20, 2, 4), rb = test::render_scene(b, "pt-mis", 24, 20, 2, 4);
    EXPECT_TRUE(test::bit_identical(ra.film.mean(), rb.film.mean()));
    EXPECT_EQ(ra.stats.rays, rb.stats.rays);
    // A rotated instance (not exact in object space) agrees within the noise.
    // An exact sphere in a group: each instance places a copy (Mitsuba's instancing test has one),
    // the same sphere as written out; an instance that would make it an ellipsoid is refused.
    const SceneDescription placed = load_scene_text(R"(<scene version="3"><shape type="shapegroup" id="g">
          <shape type="sphere"><transform name="to_world"><scale value="0.5"/><translate x="-1"/></transform></shape></shape>
        <shape type="instance"><ref id="g"/></shape>
        <shape type="instance"><ref id="g"/><transform name="to_world"><rotate y="1" angle="90"/><scale value="2"/><translate z="3"/></transform></shape>
        </scene>)", "s.xml", ".");
    const SceneDescription written = load_scene_text(R"(<scene version="3">
        <shape type="sphere"><transform name="to_world"><scale value="0.5"/><translate x="-1"/></transform></shape>
        <shape type="sphere"><transform name="to_world"><scale value="0.5"/><translate x="-1"/><rotate y="1" angle="90"/><scale value="2"/>
          <translate z="3"/></transform></shape></scene>)", "s.xml", ".");
    ASSERT_EQ(placed.spheres.size(), 2u);
    EXPECT_TRUE(placed.instances.empty());  // a group of spheres only: nothing for Embree to instance
    for (size_t i = 0; i < 2; ++i) {
        EXPECT_NEAR(length(placed.spheres[i].center - written.spheres[i].center), 0.0f, 1e-5f) << i;
        EXPECT_NEAR(placed.spheres[i].radius, written.spheres[i].radius, 1e-6f) << i;
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(length(placed.spheres[i].axes[size_t(k)] - written.spheres[i].axes[size_t(k)]), 0.0f, 1e-5f) << i;
    }
    EXPECT_NEAR(placed.spheres[1].radius, 1.0f, 1e-6f);
    EXPECT_NE(error_of(R"(<scene version="3"><shape type="shapegroup" id="g"><shape type="sphere"/></shape>
        <shape type="instance"><ref id="g"/><transform name="to_world"><scale x="2"/></transform></shape></scene>)")
                  .find("an instance can only rotate, scale uniformly and translate"),
              std::string::npos);
    EXPECT_NE(error_of(R"(<scene version="3"><shape type="shapegroup" id="g"><shape type="cube"><emitter type="area"/></shape></shape></scene>)")
                  .find("cannot emit"),
              std::string::npos);
}

TEST(SceneFileMeshes, CylinderAndFlippedNormals) {
    const SceneDescription d = load_scene_text(R"(<scene version="3.0.0">
  <shape type="cylinder"><point name="p0" value="0, 0, -1"/><point name="p1" value="0, 0, 1"/><float name="radius" value="0.5"/></shape>
  <shape type="cylinder"><boolean name="flip_normals" value="true"/></shape>
</scene>)", "c.xml", ".");
    ASSERT_EQ(d.meshes.size(), 2u);
    double area = 0;
    for (const auto& t : d.meshes[0].triangles) {
        const Vec3f& a = d.meshes[0].positions[t[0]];
        const Vec3f n = cross(d.meshes[0].positions[t[1]] - a, d.meshes[0].positions[t[2]] - a);
        area += 0.5 * length(Vec3d(n));
        // Outward: the winding normal points away from the axis.
        const Vec3f c = (a + d.meshes[0].positions[t[1]] + d.meshes[0].positions[t[2]]) / 3.0f;
        EXPECT_GT(n.x * c.x + n.y * c.y, 0);
    }
    // 128 sides of width 2 r sin(pi / 128) and height 2: 0.01% short of 2 pi r h.
    EXPECT_NEAR(area, 128 * 2 * 0.5 * std::sin(M_PI / 128) * 2, 1e-5);
    EXPECT_GT(-dot(d.meshes[1].normals[0], Vec3f(d.meshes[1].positions[0].x, d.meshes[1].positions[0].y, 0)), 0);
}

// ---- sensors ---------------------------------------------------------------------------------

TEST(SceneFileSensors, WindowsClippingLensAndOrthographicRays) {
    Camera c = Camera::look_at({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 40, FovAxis::X);
    const PerspectiveCamera full(c, 64, 48);
    // A crop window renders the same rays as those pixels of the full film.
    Camera crop = c;
    crop.window_x0 = 16.0f / 64, crop.window_x1 = 48.0f / 64, crop.window_y0 = 8.0f / 48, crop.window_y1 = 40.0f / 48;
    const PerspectiveCamera part(crop, 32, 32);
    for (const Vec2f& r : {Vec2f(0.5f, 0.5f), Vec2f(31.25f, 7.5f), Vec2f(12.0f, 30.9f)}) {
        const Vec3f a = part.generate(r.x, r.y).d, b = full.generate(r.x + 16, r.y + 8).d;
        EXPECT_NEAR(length(a - b), 0, 1e-6);
        const auto back = part.raster_of(a);
        ASSERT_TRUE(back);
        EXPECT_NEAR(back->x, r.x, 1e-3);
        EXPECT_NEAR(back->y, r.y, 1e-3);
    }
    EXPECT_NEAR(part.image_plane_area(), full.image_plane_area() / 3, 1e-6);  // a third of the film
    // A principal point offset shifts the image by that fraction of the film.
    Camera shifted = c;
    shifted.principal_x = 0.25f;
    const PerspectiveCamera ps(shifted, 64, 48);
    EXPECT_NEAR(length(ps.generate(16, 24).d - full.generate(32, 24).d), 0, 1e-6);
    // A thin lens with no aperture is the pinhole, bit for bit; with one, rays meet at the focus.
    Camera lens = c;
    lens.kind = CameraKind::ThinLens;
    const PerspectiveCamera pin(lens, 64, 48);
    const Ray p0 = pin.generate(10.5f, 20.25f, Vec2f(0.3f, 0.9f)), q0 = full.generate(10.5f, 20.25f);
    EXPECT_EQ(p0.d, q0.d);
    EXPECT_EQ(p0.o, q0.o);
    lens.aperture_radius = 0.2f, lens.focus_distance = 4;
    const PerspectiveCamera thin(lens, 64, 48);
    const Ray a = thin.generate(10.5f, 20.25f, Vec2f(0.1f, 0.2f)), b = thin.generate(10.5f, 20.25f, Vec2f(0.8f, 0.6f));
    EXPECT_GT(length(a.o - b.o), 0.01f);
    const Vec3f fa = a.o + a.d * (4 / dot(a.d, c.forward)), fb = b.o + b.d * (4 / dot(b.d, c.forward));
    EXPECT_NEAR(length(fa - fb), 0, 1e-5);
    // Near and far clipping: rays start at depth near and end at depth far.
    Camera clipped = c;
    clipped.near_clip = 1, clipped.far_clip = 3;
    const Ray r = PerspectiveCamera(clipped, 64, 48).generate(3, 40);
    EXPECT_NEAR(dot(r.o - c.position, c.forward), 1, 1e-5);
    EXPECT_NEAR(dot(r.o + r.d * r.tmax - c.position, c.forward), 3, 1e-5);
    // Orthographic: parallel rays over [-half, half] of the view.
    Camera ortho = c;
    ortho.kind = CameraKind::Orthographic, ortho.ortho_half_x = 2, ortho.ortho_half_y = 2;
    const PerspectiveCamera o(ortho, 64, 32);
    EXPECT_EQ(o.generate(0, 0).d, c.forward);
    EXPECT_NEAR(o.generate(64, 16).o.x, 2, 1e-6);
    EXPECT_NEAR(o.generate(32, 0).o.y, 1, 1e-6);  // half height = 2 / aspect
    // Integrators that connect to the pinhole refuse the other sensors.
    SceneDescription d = load_scene_file(source_path("scenes/example.xml"));
    d.camera.kind = CameraKind::ThinLens;
    for (const char* name : {"lt", "bdpt", "vcm", "sppm", "ic", "pbgi"}) {
        JobRequest req;
        req.algorithm = name;
        EXPECT_THROW(RenderJob(scene_choice_of(d), req), UsageError) << name;
    }
}

// Without fov, Mitsuba 3 takes a 50 mm lens on a 36 x 24 mm film and spans the film's diagonal
// (sensor.cpp, parse_fov): on a square film the horizontal field of view is 34.0 degrees, not the
// 39.6 that 36 mm across would give. focal_length does the same for other lenses; fov_axis is
// ignored with it (a note); a scene without a sensor gets the same camera.
TEST(SceneFileSensors, DefaultFieldOfViewIsMitsubasFiftyMillimetreLensOnTheDiagonal) {
    const auto camera_of = [](const std::string& sensor, int w, int h) {
        return load_scene_text(fmt::format(R"(<scene version="3.0.0"><sensor type="perspective">{}
            <film type="hdrfilm"><integer name="width" value="{}"/><integer name="height" value="{}"/><rfilter type="box"/></film></sensor><shape type="sphere"/></scene>)",
                                           sensor, w, h),
                               "s.xml", ".")
            .camera;
    };
    const auto diagonal_tan = [](double mm) { return std::sqrt(36.0 * 36 + 24 * 24) / (2 * mm); };  // tan(half the diagonal fov)
    for (const auto& [sensor, mm] : {std::pair("", 50.0), std::pair(R"(<string name="focal_length" value="25mm"/>)", 25.0),
                                     std::pair(R"(<string name="focal_length" value="85"/>)", 85.0)})
        for (const auto& [w, h] : {std::pair(48, 48), std::pair(96, 48), std::pair(30, 60)}) {
            const Camera cam = camera_of(sensor, w, h);
            EXPECT_EQ(cam.fov_axis, FovAxis::Diagonal);
            EXPECT_NEAR(cam.fov_degrees, 2 * std::atan(diagonal_tan(mm)) * 180 / M_PI, 1e-4);
            // The ray through the middle of the right edge: tan(half the fov along x) = the diagonal's tan * w / sqrt(w^2 + h^2).
            const Vec3f d = PerspectiveCamera(cam, w, h).generate(float(w), 0.5f * float(h)).d;
            const double tan_x = std::abs(double(dot(d, cam.right))) / double(dot(d, cam.forward));
            EXPECT_NEAR(tan_x, diagonal_tan(mm) * w / std::hypot(double(w), double(h)), 1e-5) << sensor << " " << w << "x" << h;
        }
    // On a square film: 34.0 degrees across, where 36 mm across (the old rule) gave 39.6.
    EXPECT_NEAR(2 * std::atan(diagonal_tan(50) / std::sqrt(2.0)) * 180 / M_PI, 34.02, 0.01);
    // Without a sensor: the same lens.
    const SceneDescription bare = load_scene_text(R"(<scene version="3.0.0"><shape type="sphere"/></scene>)", "s.xml", ".");
    EXPECT_EQ(bare.camera.fov_axis, FovAxis::Diagonal);
    EXPECT_NEAR(bare.camera.fov_degrees, 2 * std::atan(diagonal_tan(50)) * 180 / M_PI, 1e-4);
    // fov keeps its axis (x by default).
    EXPECT_EQ(camera_of(R"(<float name="fov" value="30"/>)", 48, 48).fov_axis, FovAxis::X);
}

TEST(SceneFileSensors, LightTracerAgreesWithPathTracingInACropWindow) {
    // The window's image plane area is in the light tracer's importance: with a wrong area its
    // pixels would be off by the window's fraction of the film (here 1/4).
    SceneDescription d = load_scene_file(source_path("scenes/2-ceiling-diffuse.xml"));
    d.camera.window_x0 = 0.25f, d.camera.window_x1 = 0.75f, d.camera.window_y0 = 0.1f, d.camera.window_y1 = 0.6f;
    d.camera.principal_x = 0.05f;
    const RenderResult pt = test::render_scene(d, "pt-mis", 10, 10, 128, 2);
    const RenderResult lt = test::render_scene(d, "lt", 10, 10, 512, 3);
    EXPECT_EQ(channels_apart(pt, lt), 0);
}

// ---- integrators -------------------------------------------------------------------------------

TEST(SceneFileIntegrators, HideEmittersMomentAndAovs) {
    const std::string text = R"(<scene version="3.0.0">
  <integrator type="moment"><integrator type="path"><boolean name="hide_emitters" value="$hide"/></integrator></integrator>
  <sensor type="perspective"><transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform></sensor>
  <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="3"/></emitter></shape>
</scene>)";
    const SceneDescription shown = load_scene_text(text, "h.xml", ".", {{"hide", "false"}});
    const SceneDescription hidden = load_scene_text(text, "h.xml", ".", {{"hide", "true"}});
    EXPECT_TRUE(shown.moment);
    EXPECT_EQ(shown.algorithm, "pt-mis");
    for (const char* algorithm : {"pt-mis", "pt-naive", "direct-mis", "direct-light", "lt", "bdpt", "vcm", "sppm", "pm", "ic"}) {
        const Image a = test::render_scene(shown, algorithm, 8, 8, 4, 1).film.mean();
        const Image b = test::render_scene(hidden, algorithm, 8, 8, 4, 1).film.mean();
        double sa = 0, sb = 0;
        for (size_t i = 0; i < a.pixel_count(); ++i) sa += a[i].x, sb += b[i].x;
        EXPECT_GT(sa / 64, 1.5) << algorithm;  // the light fills most of the image
        EXPECT_EQ(sb, 0.0) << algorithm;       // and nothing else is there
    }
    const RenderResult r = test::render_scene(shown, "pt-mis", 4, 4, 8, 1);
    const std::vector<ExrChannel> m = moment_channels(r.film);
    ASSERT_EQ(m.size(), 6u);
    EXPECT_EQ(m[0].name, "m2.R");
    for (size_t i = 0; i < 16; ++i) EXPECT_NEAR(m[0].values[i], r.film.sum_of_squares(i).x / 8, 1e-6);
    const auto scene = Scene::build(load_scene_text(R"(<scene version="3.0.0">
  <sensor type="perspective"><transform name="to_world"><lookat origin="0,0,3" target="0,0,0" up="0,1,0"/></transform></sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="10"/></transform><bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.4, 0.6"/></bsdf></shape>
</scene>)", "a.xml", "."));
    const std::vector<ExrChannel> aov = aov_channels(*scene, {{"dd.y", "depth"}, {"nn", "sh_normal"}, {"albedo", "albedo"}}, 4, 4, 4, 1);
    ASSERT_EQ(aov.size(), 7u);
    EXPECT_EQ(aov[0].name, "dd.y");
    EXPECT_NEAR(aov[0].values[5], 3 / std::cos(0.0), 0.2);  // near the centre
    EXPECT_NEAR(aov[3].values[0], 1, 1e-6);                  // nn.Z
    EXPECT_NEAR(aov[6].values[0], 0.6, 1e-6);                // albedo.B
}

// --null-depth skip (Mitsuba's volpath): a straight pass through thin glass or a mask's hole is no
// bounce. Twin scenes: a floor lit by a light above it, seen by the camera, with and without two
// sheets that let everything through (a thindielectric of index 1 between the light and the
// floor, a mask of opacity 0 between the camera and the floor), at a depth of one and of two
// bounces. With skip the sheets change nothing (per-pixel z-tests); counted as bounces, they take
// the direct light away. Also in fog (volpath's media loop) and through a scene file's volpath.
TEST(SceneFileIntegrators, NullDepthSkipPassesStraightThroughWithoutABounce) {
    const auto scene = [](bool sheets, bool fog, const std::string& integrator) {
        return load_scene_text(fmt::format(R"(<scene version="3.0.0">
  {0}
  <medium type="homogeneous" id="fog"><rgb name="sigma_t" value="0.3"/><rgb name="albedo" value="0.8"/></medium>
  <sensor type="perspective"><float name="fov" value="40"/>
    <transform name="to_world"><lookat origin="0,-3,1.5" target="0,0,0" up="0,0,1"/></transform></sensor>
  <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform><bsdf type="diffuse"><rgb name="reflectance" value="0.7"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.5"/><rotate x="1" angle="180"/><translate z="2"/></transform>
    <emitter type="area"><rgb name="radiance" value="8"/></emitter></shape>
  {1}
  {2}
</scene>)",
                                           integrator,
                                           sheets ? R"(<shape type="rectangle"><transform name="to_world"><scale value="3"/><translate z="1.75"/></transform>
    <bsdf type="thindielectric"><float name="int_ior" value="1"/><float name="ext_ior" value="1"/></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="3"/><rotate x="1" angle="80"/><translate y="-1.5" z="0.7"/></transform>
    <bsdf type="mask"><float name="opacity" value="0"/><bsdf type="diffuse"/></bsdf></shape>)"
                                                  : "",
                                           fog ? R"(<shape type="cube"><transform name="to_world"><scale x="1" y="1" z="0.4"/><translate z="0.5"/></transform>
    <bsdf type="null"/><ref name="interior" id="fog"/></shape>)"
                                               : ""),
                               "null.xml", ".");
    };
    const auto render = [](const SceneDescription& d, const std::string& algorithm, int depth, std::optional<bool> skip, uint64_t seed) {
        JobRequest r;
        r.algorithm = algorithm;
        r.spp = 128;
        r.max_depth = depth;
        r.width = r.height = 12;
        r.seed = seed;
        r.skip_null_events = skip;
        return RenderJob(scene_choice_of(d), r).run();
    };
    const auto agree = [](const RenderResult& a, const RenderResult& b) {
        return test_agreement(a.film.mean(), a.film.standard_error(), b.film.mean(), b.film.standard_error(), AgreementOptions{1e-3, 1e-4});
    };
    for (const bool fog : {false, true})
        for (const int depth : {1, 2}) {
            const SceneDescription with = scene(true, fog, ""), without = scene(false, fog, "");
            const std::string algorithm = fog ? "volpath" : "pt-mis";
            const RenderResult twin = render(without, algorithm, depth, std::nullopt, 2);
            const AgreementResult skipped = agree(render(with, algorithm, depth, true, 1), twin);
            EXPECT_TRUE(skipped.agree) << algorithm << " depth " << depth << ": " << skipped.describe();
            const AgreementResult counted = agree(render(with, algorithm, depth, std::nullopt, 1), twin);
            EXPECT_FALSE(counted.agree) << algorithm << " depth " << depth << " (the test's power): " << counted.describe();
        }
    // A scene file's volpath counts depth as Mitsuba's volpath does (its max_depth 3: two bounces).
    const SceneDescription file = scene(true, true, R"(<integrator type="volpath"><integer name="max_depth" value="3"/></integrator>)");
    EXPECT_TRUE(file.skip_null_events.value_or(false));
    const AgreementResult from_file = agree(render(file, "volpath", 2, std::nullopt, 1), render(scene(false, true, ""), "volpath", 2, std::nullopt, 2));
    EXPECT_TRUE(from_file.agree) << from_file.describe();
    // The integrators that count it as a bounce refuse skip where it would change their image.
    const auto refusal = [&](const std::string& algorithm, int depth, bool sheets) {
        JobRequest r;
        r.algorithm = algorithm;
        r.max_depth = depth;
        r.skip_null_events = true;
        try {
            RenderJob job(scene_choice_of(scene(sheets, false, "")), r);
        } catch (const UsageError& e) {
            return std::string(e.what());
        }
        return std::string();
    };
    EXPECT_NE(refusal("bdpt", 2, true).find("--null-depth count"), std::string::npos) << refusal("bdpt", 2, true);
    EXPECT_NE(refusal("lt", 2, true).find("pt-mis"), std::string::npos);
    EXPECT_EQ(refusal("bdpt", -1, true), "");  // unlimited: the two conventions agree
    EXPECT_EQ(refusal("bdpt", 2, false), "");  // nothing to pass through
    EXPECT_EQ(refusal("pt-mis3", 2, true), "");
}

// ---- BSDFs -------------------------------------------------------------------------------------

TEST(SceneFileBsdfs, ThinDielectricBlendMaskAndTwoSidedPairs) {
    const SceneDescription d = load_scene_text(R"(<scene version="3.0.0">
  <bsdf type="diffuse" id="red"><rgb name="reflectance" value="0.9, 0.1, 0.1"/></bsdf>
  <shape type="rectangle"><bsdf type="thindielectric"/></shape>
  <shape type="rectangle"><bsdf type="blendbsdf"><float name="weight" value="0.25"/><ref id="red"/><bsdf type="conductor"/></bsdf></shape>
  <shape type="rectangle"><bsdf type="mask"><float name="opacity" value="0.3"/><ref id="red"/></bsdf></shape>
  <shape type="rectangle"><bsdf type="twosided"><ref id="red"/><bsdf type="diffuse"><rgb name="reflectance" value="0.1, 0.9, 0.1"/></bsdf></bsdf></shape>
</scene>)", "b.xml", ".");
    const Material& thin = d.materials[d.meshes[0].material];
    const auto& td = std::get<ThinDielectricMaterial>(thin.model);
    EXPECT_TRUE(thin.is_delta());
    // Energy: R' + T' = 1, and R' = 2R / (1 + R) with R the one-face Fresnel term.
    const float R = fresnel_dielectric(0.6f, td.int_ior / td.ext_ior);
    EXPECT_NEAR(td.reflectance(0.6f), 2 * R / (1 + R), 1e-6);
    const Vec3f wi = normalize(Vec3f(0.8f, 0, 0.6f));
    const auto refl = thin.sample(wi, Vec2f(0.0f, 0.5f)), trans = thin.sample(wi, Vec2f(0.99f, 0.5f));
    ASSERT_TRUE(refl && trans);
    EXPECT_NEAR(refl->pdfW + trans->pdfW, 1, 1e-6);
    EXPECT_EQ(trans->wo, -wi);
    // Blend: eval mixes; the conductor (delta) part is sampled with probability = weight.
    const Material& blend = d.materials[d.meshes[1].material];
    const Vec3f wo = normalize(Vec3f(-0.3f, 0.2f, 0.9f));
    EXPECT_NEAR(blend.eval(wi, wo).x, 0.75f * 0.9f / M_PI, 1e-6);
    const auto bs = blend.sample(wi, Vec2f(0.1f, 0.5f));
    ASSERT_TRUE(bs);
    EXPECT_TRUE(bs->delta);
    EXPECT_NEAR(bs->pdfW, 0.25, 1e-6);
    // Mask: opacity times the BSDF; the rest straight through.
    const Material& mask = d.materials[d.meshes[2].material];
    EXPECT_NEAR(mask.eval(wi, wo).x, 0.3f * 0.9f / M_PI, 1e-6);
    const auto ms = mask.sample(wi, Vec2f(0.5f, 0.5f));
    ASSERT_TRUE(ms);
    EXPECT_EQ(ms->wo, -wi);
    EXPECT_NEAR(ms->pdfW, 0.7, 1e-6);
    // Two different sides.
    const Material& front = d.materials[d.meshes[3].material];
    ASSERT_GE(front.back, 0);
    EXPECT_EQ(std::get<PhongMaterial>(d.materials[size_t(front.back)].model).diffuse, Rgb(0.1f, 0.9f, 0.1f));
}

TEST(SceneFileBsdfs, MaskedAndBlendedSurfacesAgreeAcrossEstimators) {
    // A furnace-like check of the new lobes in a closed box: pt-mis and pt-naive agree.
    const SceneDescription d = load_scene_text(R"(<scene version="3.0.0">
  <sensor type="perspective"><float name="fov" value="60"/><transform name="to_world"><lookat origin="0,0,0" target="0,0,1" up="0,1,0"/></transform></sensor>
  <shape type="cube"><transform name="to_world"><scale value="2"/></transform><boolean name="flip_normals" value="true"/>
    <bsdf type="blendbsdf"><float name="weight" value="0.4"/><bsdf type="diffuse"><rgb name="reflectance" value="0.6"/></bsdf>
      <bsdf type="roughconductor"><float name="alpha" value="0.2"/></bsdf></bsdf></shape>
  <shape type="rectangle"><transform name="to_world"><scale value="0.6"/><translate z="1.2"/></transform>
    <bsdf type="mask"><float name="opacity" value="0.5"/><bsdf type="twosided"><bsdf type="diffuse"/></bsdf></bsdf></shape>
  <shape type="sphere"><point name="center" value="0.8, 0.8, 1.5"/><float name="radius" value="0.2"/>
    <emitter type="area"><rgb name="radiance" value="10"/></emitter></shape>
</scene>)", "f.xml", ".");
    const RenderResult a = test::render_scene(d, "pt-mis", 8, 8, 256, 3), b = test::render_scene(d, "pt-naive", 8, 8, 1024, 4);
    double sa = 0, sb = 0, var = 0;
    const Image ma = a.film.mean(), mb = b.film.mean(), ea = a.film.standard_error(), eb = b.film.standard_error();
    for (size_t i = 0; i < ma.pixel_count(); ++i) {
        sa += ma[i].x, sb += mb[i].x;
        var += double(ea[i].x) * ea[i].x + double(eb[i].x) * eb[i].x;
    }
    EXPECT_LT(std::abs(sa - sb) / std::sqrt(var), sidak_z(1)) << sa << " vs " << sb;
}

// ---- the corpus of exporter-style files -------------------------------------------------------

TEST(SceneFileCorpus, ExporterStyleScenesLoadAndRender) {
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(source_path("tests/data/scenes/mitsuba"))) {
        if (entry.path().extension() != ".xml" || entry.path().filename().string().rfind("part-", 0) == 0) continue;
        SCOPED_TRACE(entry.path().filename().string());
        const SceneDescription d = load_scene_file(entry.path().string());
        JobRequest r;
        r.spp = 2;
        r.width = 12, r.height = 10;
        RenderJob job(scene_choice_of(d), r);
        const RenderResult res = job.run();
        const Image img = res.film.mean();
        double sum = 0;
        for (size_t i = 0; i < img.pixel_count(); ++i) sum += img[i].x + img[i].y + img[i].z;
        EXPECT_TRUE(std::isfinite(sum));
        EXPECT_GT(sum, 0);
        ++files;
    }
    EXPECT_GE(files, 4);
}

}  // namespace
}  // namespace pathlab

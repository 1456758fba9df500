// IES photometric files (lights/ies_profile.hpp) and the ies emitter (lights/ies.hpp), on the
// test files of tests/data/ies/ (written by make_ies.py from analytic distributions, one per
// horizontal symmetry of type C): the parsed candela table of each file matches its formula,
// interpolation at the table's angles is exact, symmetric files expand to the full circle, the
// flux integrated from the profile matches the file's lumens, emission sampling follows its
// pdf (chi-square) with bounded weights, a render of an IES light over a diffuse plane matches
// E = I cos / d^2 per pixel (and fails for the other horizontal orientation), and broken files
// are refused naming the file and the line (exit code 2 from the command line).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include <fmt/format.h>

#include "chi2.hpp"
#include "cli_runner.hpp"
#include "judge/image_statistics.hpp"
#include "lights/light.hpp"
#include "render_helpers.hpp"
#include "scenefile/scene_file.hpp"

namespace pathlab::test {
namespace {

const double kAlpha = suite_chi2_alpha();
const SceneSphere kSphere{{0, 0, 0}, 3};

std::string ies_path(const std::string& name) { return std::string(PATHLAB_SOURCE_DIR) + "/tests/data/ies/" + name; }

double cosd(double a) { return std::cos(a * M_PI / 180); }
double sind(double a) { return std::sin(a * M_PI / 180); }

// The files and the distributions make_ies.py tabulated (true candela, g vertical, c horizontal).
struct IesCase {
    const char* file;
    const char* version;
    double lumens;  // the flux the formula has
    std::function<double(double, double)> candela;
    std::vector<double> expanded;  // the horizontal angles after expansion to the full circle
};

std::vector<double> steps(double step) {
    std::vector<double> v;
    for (double a = 0; a <= 360 + 1e-9; a += step) v.push_back(a);
    return v;
}

const std::vector<IesCase>& cases() {
    static const std::vector<IesCase> c = {
        {"downlight-rotational.ies", "LM-63-2002", 1000, [](double g, double) { return 1000 / M_PI * cosd(g); }, {0, 360}},
        {"corridor-quadrant.ies", "LM-63-1995", 2850,
         [](double g, double c) { return 2850 / M_PI * cosd(g) * (1 + 0.5 * cosd(2 * c)); }, steps(22.5)},
        {"wallwasher-bilateral.ies", "LM-63-2002", 2400,
         [](double g, double c) { return 2400 / (1.4 * M_PI) * (0.1 + std::max(cosd(g), 0.0) * (1 + 0.6 * cosd(c))); }, steps(30)},
        {"asymmetric-full.ies", "LM-63-2002", 1800, [](double g, double c) { return 1800 / M_PI * cosd(g) * (1 + 0.4 * cosd(c - 60)); },
         steps(30)},
        {"bilateral-90-270.ies", "LM-63-1995", 1200, [](double g, double c) { return 1200 / M_PI * cosd(g) * (1 + 0.5 * sind(c)); },
         steps(30)},
    };
    return c;
}

class IesFiles : public ::testing::TestWithParam<size_t> {
protected:
    const IesCase& c() const { return cases()[GetParam()]; }
};

TEST_P(IesFiles, TheParsedTableIsTheFilesFormula) {
    const IesProfile p = read_ies_file(ies_path(c().file));
    EXPECT_EQ(p.version, c().version);
    EXPECT_EQ(p.photometric_type, 1);
    ASSERT_TRUE(p.rated_lumens());
    EXPECT_DOUBLE_EQ(*p.rated_lumens(), c().lumens);
    ASSERT_EQ(p.values.size(), p.vertical.size() * p.horizontal.size());
    // Two decimals in the file: within 0.005 of the formula, in file units.
    for (size_t h = 0; h < p.horizontal.size(); ++h)
        for (size_t v = 0; v < p.vertical.size(); ++v)
            ASSERT_NEAR(p.value(h, v) * p.candela_scale(), c().candela(p.vertical[v], p.horizontal[h]), 0.0051 * p.candela_scale())
                << c().file << " at " << p.vertical[v] << ", " << p.horizontal[h];
}

TEST_P(IesFiles, InterpolationIsExactAtTheTablesAnglesAndSymmetricFilesExpand) {
    const IesProfile p = read_ies_file(ies_path(c().file));
    const IesDistribution d(p);
    ASSERT_EQ(d.horizontal().size(), c().expanded.size()) << c().file;
    for (size_t i = 0; i < c().expanded.size(); ++i) EXPECT_NEAR(d.horizontal()[i], c().expanded[i], 1e-9) << c().file;
    // At every angle of the file, and at its mirror images, the file's value exactly.
    for (size_t h = 0; h < p.horizontal.size(); ++h)
        for (size_t v = 0; v < p.vertical.size(); ++v) {
            const float expected = float(p.value(h, v) * p.candela_scale());
            const double g = p.vertical[v], a = p.horizontal[h];
            std::vector<double> images = {a};
            if (p.horizontal.size() == 1) images = {0, 45, 123.4, 300};
            else if (p.horizontal.front() == 90) images = {a, 180 - a};
            else if (p.horizontal.back() == 90) images = {a, 180 - a, 180 + a, 360 - a};
            else if (p.horizontal.back() == 180) images = {a, 360 - a};
            for (const double m : images) ASSERT_EQ(d.candela(g, m), expected) << c().file << " at " << g << ", " << m;
        }
    // Between the table's angles: bilinear, close to the formula (the table's interpolation
    // error: a few percent of the peak at most for these steps), and as symmetric as the file.
    double peak = 0;
    for (size_t i = 0; i < p.values.size(); ++i) peak = std::max(peak, p.values[i] * p.candela_scale());
    Sampler rng(5, 0, 0);
    for (int i = 0; i < 2000; ++i) {
        const double g = 180 * rng.next1d(), a = 360 * rng.next1d();
        const double truth = p.vertical.back() < g ? 0.0 : c().candela(g, a);
        EXPECT_NEAR(d.candela(g, a), truth, 0.03 * peak) << c().file << " at " << g << ", " << a;
        // The luminaire's frame: the same value through a direction.
        EXPECT_NEAR(d.candela(IesDistribution::direction(g, a)), d.candela(g, a), 1e-3 * peak);
    }
}

TEST_P(IesFiles, TheFluxIntegratedFromTheProfileMatchesTheLumens) {
    const IesProfile p = read_ies_file(ies_path(c().file));
    const IesDistribution d(p);
    // flux() is the exact integral of the interpolant: a fine midpoint rule over the sphere agrees.
    double integral = 0;
    const int nt = 1800, np = 720;
    for (int i = 0; i < nt; ++i) {
        const double g = 180.0 * (i + 0.5) / nt;
        double ring = 0;
        for (int j = 0; j < np; ++j) ring += d.candela(g, 360.0 * (j + 0.5) / np);
        integral += ring / np * 2 * M_PI * sind(g) * (M_PI / nt);
    }
    EXPECT_NEAR(d.flux(), integral, 2e-3 * integral) << c().file;
    // ... and matches the lumens within the table's interpolation error (under 1% here).
    RecordProperty("flux_over_lumens", fmt::format("{:.5f}", d.flux() / c().lumens));
    EXPECT_NEAR(d.flux() / c().lumens, 1.0, 0.01) << c().file << ": " << d.flux() << " lm";
}

INSTANTIATE_TEST_SUITE_P(Files, IesFiles, ::testing::Range(size_t(0), cases().size()), [](const auto& info) {
    std::string n = cases()[info.param].file;
    n = n.substr(0, n.find('.'));
    for (char& ch : n) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    return n;
});

// A frame turning the luminaire: its nadir towards -z (down), horizontal angle 0 turned 30
// degrees about the vertical.
Frame turned_down_frame() {
    const Transform t = Transform::rotate({0, 0, 1}, 30) * Transform::rotate({1, 0, 0}, 180);
    Frame f;
    f.s = Vec3f(t.vector({1, 0, 0})), f.t = Vec3f(t.vector({0, 1, 0})), f.n = Vec3f(t.vector({0, 0, 1}));
    return f;
}

IesLight make_ies_light(const std::string& file, const Vec3f& position, Rgb intensity = Rgb(1.0f)) {
    return IesLight{position, turned_down_frame(), intensity / kLumensPerWatt,
                    std::make_shared<const IesDistribution>(read_ies_file(ies_path(file)))};
}

class IesEmission : public ::testing::TestWithParam<const char*> {};

TEST_P(IesEmission, DirectionsFollowTheProfilesPdfWithBoundedWeights) {
    const Light light = make_ies_light(GetParam(), {0.1f, 0.2f, 0.3f}, Rgb(683.0f));  // 1 W/sr per candela
    const IesLight& ies = std::get<IesLight>(light);
    const IesDistribution& d = *ies.profile;
    // The bound the cell maxima promise: the sum over cells of (largest corner) x (solid angle).
    double bound = 0;
    for (size_t h = 0; h + 1 < d.horizontal().size(); ++h)
        for (size_t v = 0; v + 1 < d.vertical().size(); ++v)
            bound += std::max({d.grid_value(h, v), d.grid_value(h + 1, v), d.grid_value(h, v + 1), d.grid_value(h + 1, v + 1)}) *
                     (d.horizontal()[h + 1] - d.horizontal()[h]) * M_PI / 180 * (cosd(d.vertical()[v]) - cosd(d.vertical()[v + 1]));
    double worst_pdf = 0, worst_weight = 0;
    const Chi2Result r = chi2_directions(
        [&](Vec2f u) -> std::optional<Vec3f> {
            const auto s = sample_emission(light, {0.5f, 0.5f}, u, kSphere);
            if (!s) return std::nullopt;
            const EmissionPdf p = pdf_emission(light, s->origin, s->normal, s->direction, kSphere);
            worst_pdf = std::max(worst_pdf, std::abs(double(p.pdfW) / s->pdfW - 1));
            worst_weight = std::max(worst_weight, double(s->Le.x) / s->pdfW / bound);
            EXPECT_NEAR(s->Le.x, d.candela(ies.frame.to_local(s->direction)), 1e-3f * s->Le.x + 1e-3f);
            return s->direction;
        },
        [&](const Vec3f& w) { return pdf_emission(light, ies.position, w, w, kSphere).pdfW; }, ies.frame.n, Chi2Options{.theta_bins = 36, .phi_bins = 72});
    EXPECT_GT(r.p_value, kAlpha) << GetParam() << ": " << r.describe();
    EXPECT_NEAR(r.pdf_integral, 1.0, 1e-3) << GetParam();
    EXPECT_EQ(worst_pdf, 0.0) << GetParam();
    EXPECT_LE(worst_weight, 1.0 + 1e-4) << GetParam();
    EXPECT_NEAR(std::get<IesLight>(light).power(kSphere), d.flux(), 1e-3 * d.flux());  // 683 x flux / 683
}
INSTANTIATE_TEST_SUITE_P(Files, IesEmission, ::testing::Values("asymmetric-full.ies", "wallwasher-bilateral.ies"), [](const auto& info) {
    std::string n = info.param;
    n = n.substr(0, n.find('.'));
    for (char& ch : n) if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
    return n;
});

// ---- the closed form: an IES light over a diffuse plane ------------------------------------------

constexpr float kRho = 0.5f;
const Vec3f kLightAt(0.3f, -0.2f, 1.5f);
const char* const kRenderFile = "asymmetric-full.ies";

SceneDescription ies_over_plane() {
    SceneDescription d;
    d.name = "ies-plane";
    d.width = d.height = 32;
    d.camera = Camera::look_along({0.1f, 0.0f, 3.0f}, {0, 0, -1}, {0, 1, 0}, 70.0f, FovAxis::EachAxis);
    d.materials = {make_phong(Rgb(kRho))};
    MeshDesc plane;
    plane.positions = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
    plane.triangles = {{0, 1, 2}, {2, 3, 0}};
    d.meshes.push_back(plane);
    d.lights.emplace_back(make_ies_light(kRenderFile, kLightAt, Rgb(20.0f)));
    return d;
}

// rho / pi * E with E = I(g, C) cos / d^2, the angles found by undoing the luminaire's turn by
// hand (flip the vertical, turn -30 degrees): horizontal angle C from local +x towards local -y.
// `mirrored` measures C the other way (towards +y): the wrong orientation.
double closed_form(const IesDistribution& profile, double x, double y, bool mirrored) {
    const double dx = x - kLightAt.x, dy = y - kLightAt.y, dz = -kLightAt.z;
    const double d2 = dx * dx + dy * dy + dz * dz, dist = std::sqrt(d2);
    // World to local: rotate by -30 degrees about z, then by 180 degrees about x.
    const double c30 = cosd(-30), s30 = sind(-30);
    const double lx = c30 * dx - s30 * dy, ly = -(s30 * dx + c30 * dy), lz = -dz;
    const double g = std::acos(lz / dist) * 180 / M_PI;
    double c = std::atan2(mirrored ? ly : -ly, lx) * 180 / M_PI;
    if (c < 0) c += 360;
    const double intensity = 20.0 / 683 * profile.candela(g, c);
    return kRho / M_PI * intensity * (-dz / dist) / d2;
}

std::pair<double, double> plane_hit(const PerspectiveCamera& cam, float sx, float sy) {
    const Ray r = cam.generate(sx, sy);
    const double t = -double(r.o.z) / double(r.d.z);
    return {r.o.x + t * r.d.x, r.o.y + t * r.d.y};
}

AgreementResult render_against_closed_form(bool mirrored) {
    const SceneDescription desc = ies_over_plane();
    const RenderResult r = render_scene(desc, "direct-light", 32, 32, 16, 7);
    const IesDistribution profile(read_ies_file(ies_path(kRenderFile)));
    const PerspectiveCamera cam(Scene::build(desc)->camera(), 32, 32);
    Image exact(32, 32);
    constexpr int kSub = 16;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            double sum = 0;
            for (int j = 0; j < kSub; ++j)
                for (int i = 0; i < kSub; ++i) {
                    const auto [px, py] = plane_hit(cam, x + (i + 0.5f) / kSub, y + (j + 0.5f) / kSub);
                    sum += closed_form(profile, px, py, mirrored);
                }
            exact.at(x, y) = Rgb(float(sum / (kSub * kSub)));
        }
    return test_agreement(r.film.mean(), r.film.standard_error(), exact, Image());
}

TEST(IesOverPlane, RenderMatchesTheClosedFormPerPixel) {
    const AgreementResult a = render_against_closed_form(false);
    RecordProperty("agreement", a.describe());
    EXPECT_TRUE(a.agree) << a.describe();
    // The test of the test: the horizontal angle measured the other way round is seen.
    EXPECT_FALSE(render_against_closed_form(true).agree);
}

// ---- bad files ---------------------------------------------------------------------------------

std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// A valid file with its line `line` (1-based) replaced.
std::string with_line(const std::string& text, int line, const std::string& replacement) {
    std::vector<std::string> lines;
    size_t start = 0;
    for (size_t e; (e = text.find('\n', start)) != std::string::npos; start = e + 1) lines.push_back(text.substr(start, e - start));
    lines[size_t(line - 1)] = replacement;
    std::string out;
    for (const auto& l : lines) out += l + "\n";
    return out;
}

TEST(IesBadFiles, EachProblemIsNamedWithTheFileAndTheLine) {
    // corridor-quadrant.ies: line 1 version, 10 TILT, 11 counts, 12 ballast, 13 vertical, 14 horizontal, 15-19 values.
    const std::string good = read_text(ies_path("corridor-quadrant.ies"));
    ASSERT_NO_THROW(parse_ies(good, "x.ies"));
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"", "x.ies:1: the file ends without a TILT= line"},
        {"\x89PNG\r\n\x1a\n\x01\x02", "x.ies:3: the file ends without a TILT= line"},
        {with_line(good, 1, "IESNA:LM-63-2005"), "x.ies:1: unsupported version line 'IESNA:LM-63-2005'"},
        {with_line(good, 10, "TILT=lamp.tlt"), "x.ies:10: TILT=lamp.tlt (tilt data in another file) is not supported"},
        {with_line(good, 11, "2 1500 0.5 10 5 2 2 0.1 0.1 0.02"), "x.ies:11: photometric type 2 (type B) is not supported"},
        {with_line(good, 11, "2 1500 0.5 10.5 5 1 2 0.1 0.1 0.02"), "x.ies:11: the number of vertical angles must be a whole number"},
        {with_line(good, 12, "0.95 1 5x2"), "x.ies:12: expected a number for the input watts, found '5x2'"},
        {with_line(good, 13, "0 10 20 30 40 50 60 70 90 80"), "x.ies:13: the vertical angles must increase: 80 follows 90"},
        {with_line(good, 14, "0 22.5 45 67.5 120"), "x.ies:14: the horizontal angles of type C photometry run from 0 to 0, 90, 180 or 360"},
        {with_line(good, 16, "2585.10 2545.82 -2429.20 2238.76 1980.30 1661.67 1292.55 884.16 448.90 0.00"),
         "x.ies:16: a negative candela value"},
        {with_line(good, 16, "2585.10 2545.82 2429.20 2238.76 1980.30 1661.67 1292.55 884.16 448.90 nan"),
         "x.ies:16: expected a number for the candela values, found 'nan'"},
        {good.substr(0, good.find("1909.86")), "x.ies:17: the file ends after 35 of the 65 numbers"},
        {good + "7\n", "x.ies:20: unexpected '7' after the 10 x 5 candela values"},
    };
    for (const auto& [text, message] : bad) {
        try {
            (void)parse_ies(text, "x.ies");
            ADD_FAILURE() << "parsed: " << message;
        } catch (const IesError& e) {
            EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what() << "\nexpected: " << message;
        }
    }
    // Every prefix of every test file parses (when only trailing characters are cut) or fails
    // with an IesError naming the file; none crashes.
    for (const IesCase& c : cases()) {
        const std::string text = read_text(ies_path(c.file));
        for (size_t n = 0; n < text.size(); ++n) {
            try {
                (void)IesDistribution(parse_ies(text.substr(0, n), "cut.ies"));
            } catch (const IesError& e) {
                ASSERT_EQ(std::string(e.what()).rfind("cut.ies:", 0), 0u) << e.what();
            }
        }
    }
}

// The hostile files of tests/data/ies_regressions/ (hand-made, and what the fuzzer finds:
// scripts/fuzz.sh ies): each is refused with an IesError naming it, or parses into a
// distribution with a finite, non-negative flux (a cell 1e-6 degrees thin once gave a negative
// one: the closed form of its integral cancelled).
TEST(IesBadFiles, RegressionCorpusFailsCleanly) {
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(std::string(PATHLAB_SOURCE_DIR) + "/tests/data/ies_regressions")) {
        ++files;
        try {
            const IesDistribution d(read_ies_file(entry.path().string()));
            EXPECT_TRUE(std::isfinite(d.flux()) && d.flux() >= 0) << entry.path();
        } catch (const IesError& e) {
            EXPECT_NE(std::string(e.what()).find(entry.path().filename().string()), std::string::npos) << e.what();
        }
    }
    EXPECT_GE(files, 4);
}

TEST(IesBadFiles, SceneFilesWithBrokenIesFilesExitWithCode2) {
    const auto dir = std::filesystem::temp_directory_path() / fmt::format("pathlab-ies-{}", ::getpid());
    std::filesystem::create_directories(dir);
    const std::string good = read_text(ies_path("corridor-quadrant.ies"));
    std::ofstream(dir / "cut.ies", std::ios::binary) << good.substr(0, good.find("2585.10"));
    std::ofstream(dir / "typeb.ies", std::ios::binary) << with_line(good, 11, "2 1500 0.5 10 5 2 2 0.1 0.1 0.02");
    for (const auto& [file, message] : {std::pair{"cut.ies", "cut.ies:16: the file ends after 25 of the 65 numbers"},
                                        {"typeb.ies", "typeb.ies:11: photometric type 2"},
                                        {"missing.ies", "missing.ies: cannot read the IES file: no such file"},
                                        {".", "not a regular file"}}) {
        const std::string scene = (dir / "scene.xml").string();
        std::ofstream(scene) << "<scene version=\"3.0.0\"><shape type=\"sphere\"/>\n<emitter type=\"ies\"><string name=\"filename\" value=\""
                             << file << "\"/></emitter></scene>\n";
        const CliResult r = run({"--scene", scene, "--spp", "1", "-q", "-o", (dir / "out.pfm").string()});
        EXPECT_EQ(r.code, 2) << file << ": " << r.err;
        EXPECT_TRUE(contains(r.err, message)) << r.err << "\nexpected: " << message;
        EXPECT_TRUE(contains(r.err, "scene.xml:2:")) << r.err;
    }
    std::filesystem::remove_all(dir);
}

TEST(IesProfiles, TiltIncludeIsReadAndThe90To270SymmetryMirrors) {
    const IesProfile p = read_ies_file(ies_path("wallwasher-bilateral.ies"));
    EXPECT_EQ(p.tilt, "INCLUDE");
    EXPECT_EQ(p.vertical.size(), 19u);
    const IesDistribution d(read_ies_file(ies_path("bilateral-90-270.ies")));
    for (const double g : {5.0, 33.0, 71.0})
        for (const double c : {10.0, 47.0, 95.0, 200.0, 300.0}) EXPECT_NEAR(d.candela(g, c), d.candela(g, 180 - c), 1e-3 * d.candela(g, c));
}

}  // namespace
}  // namespace pathlab::test

// Every estimator's image is exactly what it was before the integrator architecture was
// rebuilt (issue 14): tests/data/golden/ holds images rendered by the old per-pixel core
// (see make.sh there, which also lists the settings), and each is rendered again here through
// the command line and compared bit for bit.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>

#include <unistd.h>

#include "cli_runner.hpp"
#include "image/image_io.hpp"

namespace pathlab::test {
namespace {

namespace fs = std::filesystem;

struct Golden {
    std::string file;               // in tests/data/golden/
    std::vector<std::string> args;  // the pathlab command that rendered it (without -o)
};

std::vector<Golden> golden_images() {
    const std::vector<std::string> algorithms = {"eyelight",    "direct-light", "direct-uniform", "direct-cosine", "direct-brdf",
                                                 "direct-mis", "pt-naive",     "pt-mis3",        "pt-mis"};
    const std::vector<std::string> files = {"example",          "materials/plastic",         "materials/roughconductor-beckmann",
                                            "materials/roughconductor", "materials/roughdielectric", "materials/roughplastic",
                                            "materials/smooth"};
    std::vector<Golden> out;
    for (const std::string& a : algorithms) {
        for (int s = 0; s < 8; ++s)
            out.push_back({std::to_string(s) + "-" + a + ".pfm",
                           {"--scene", std::to_string(s), "-a", a, "--resolution", "16x16", "--spp", "4", "--seed", "7"}});
        for (const std::string& f : files)
            out.push_back({fs::path(f).filename().string() + "-" + a + ".pfm",
                           {"--scene", std::string(PATHLAB_SOURCE_DIR) + "/scenes/" + f + ".xml", "-a", a, "--resolution",
                            "16x12", "--spp", "4", "--seed", "7"}});
    }
    out.push_back({"3-pt-mis-sobol.pfm",
                   {"--scene", "3", "-a", "pt-mis", "--sampler", "sobol", "--resolution", "16x16", "--spp", "8", "--seed", "7"}});
    out.push_back({"5-pt-mis3-depth2-rr0.pfm",
                   {"--scene", "5", "-a", "pt-mis3", "--max-depth", "2", "--rr-depth", "0", "--resolution", "16x16", "--spp",
                    "8", "--seed", "7"}});
    out.push_back({"smooth-pt-naive-depth5.pfm",
                   {"--scene", std::string(PATHLAB_SOURCE_DIR) + "/scenes/materials/smooth.xml", "-a", "pt-naive", "--max-depth",
                    "5", "--resolution", "16x12", "--spp", "8", "--seed", "7"}});
    return out;
}

TEST(GoldenImages, EveryEstimatorRendersBitForBitAsBeforeTheIntegratorRework) {
    const fs::path dir = fs::path(PATHLAB_SOURCE_DIR) / "tests/data/golden";
    const fs::path out = fs::temp_directory_path() / ("pathlab_golden_" + std::to_string(::getpid()));
    fs::create_directories(out);
    const std::vector<Golden> images = golden_images();
    ASSERT_EQ(images.size(), 9u * 15u + 3u);
    for (const Golden& g : images) {
        std::vector<std::string> args = g.args;
        args.insert(args.end(), {"-q", "-o", (out / g.file).string()});
        const CliResult r = run(args);
        ASSERT_EQ(r.code, 0) << g.file << ": " << r.err;
        const Image expected = read_image((dir / g.file).string());
        const Image got = read_image((out / g.file).string());
        ASSERT_EQ(got.pixel_count(), expected.pixel_count()) << g.file;
        size_t differing = 0;
        for (size_t i = 0; i < got.pixel_count(); ++i) differing += std::memcmp(&got[i], &expected[i], sizeof(Rgb)) != 0;
        EXPECT_EQ(differing, 0u) << g.file << ": " << differing << " of " << got.pixel_count() << " pixels differ";
    }
    fs::remove_all(out);
}

}  // namespace
}  // namespace pathlab::test

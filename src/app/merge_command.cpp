// `pathlab merge OUT.exr IN...`: one image from several renders of the same scene and settings
// whose samples are independent: disjoint pass ranges (--first-sample) of one seed, or other
// seeds. Each input is a render's EXR (its mean, its "stderr" layer and its pathlab:*
// attributes, job/render_identity.hpp) or a checkpoint (job/checkpoint.hpp).
//
// Per pixel, each input is n samples (its spp), a mean m and a standard error s, i.e. the sum of
// squared deviations M2 = s^2 n (n - 1); two parts combine as (Chan, Golub and LeVeque)
//   n = n_a + n_b,  m = m_a + (m_b - m_a) n_b / n,  M2 = M2_a + M2_b + (m_b - m_a)^2 n_a n_b / n,
// in double, which stays accurate where the variance is small next to the mean (adding sums of
// squares would cancel). EXRs store floats, so a merge of EXRs equals the one-shot render to
// float precision; checkpoints hold the exact film, so a merge of checkpoints only equals it bit
// for bit.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "app/tool_commands.hpp"
#include "image/image_io.hpp"
#include "job/checkpoint.hpp"
#include "job/output_paths.hpp"
#include "job/render_identity.hpp"
#include "job/usage_error.hpp"

namespace pathlab {
namespace {

// One input: what it is of, its passes per seed and its pixels as (n, mean, M2), or its film.
struct MergeInput {
    std::string path;
    RenderIdentity identity;
    std::map<uint64_t, PassSet> parts;  // passes per seed (one seed, unless it was merged before)
    uint64_t spp = 0;
    int width = 0, height = 0;
    uint64_t invalid_samples = 0;
    std::optional<Film> film;           // a checkpoint
    Image mean, standard_error;         // an EXR
};

MergeInput read_input(const std::string& path) {
    MergeInput in;
    in.path = path;
    if (is_checkpoint_file(path)) {
        Checkpoint c;
        try {
            c = read_checkpoint(path);
        } catch (const CheckpointError& e) {
            throw UsageError(e.what());
        }
        in.identity = c.info.identity;
        const std::string seed = in.identity.value("seed");
        char* end = nullptr;
        const uint64_t s = std::strtoull(seed.c_str(), &end, 10);
        if (seed.empty() || *end) throw UsageError(fmt::format("{}: invalid seed '{}'", path, seed));
        in.parts[s] = c.info.passes;
        in.width = c.info.width, in.height = c.info.height;
        in.film = std::move(c.film);
    } else {
        ExrExtras extras;
        try {
            in.mean = read_exr(path, extras);
        } catch (const ImageIoError& e) {
            throw UsageError(e.what());
        }
        std::map<std::string, std::string> attributes(extras.attributes.begin(), extras.attributes.end());
        const auto attribute = [&](const std::string& key) {
            const auto it = attributes.find(key);
            if (it == attributes.end())
                throw UsageError(fmt::format("{}: not a pathlab render to merge: no {} attribute (renders write it since pathlab's "
                                             "checkpoints; re-render, or merge checkpoints)",
                                             path, key));
            return it->second;
        };
        for (const std::string& field : kIdentityFields) in.identity.fields.emplace_back(field, attribute(metadata_key(field)));
        // pathlab:parts ("seed:passes;...") in a merged image, else pathlab:seed and pathlab:passes.
        const std::string parts = attributes.count("pathlab:parts") ? attributes["pathlab:parts"]
                                                                     : attribute("pathlab:seed") + ":" + attribute("pathlab:passes");
        for (size_t a = 0; a <= parts.size();) {
            size_t b = parts.find(';', a);
            if (b == std::string::npos) b = parts.size();
            const std::string part = parts.substr(a, b - a);
            const size_t colon = part.find(':');
            char* end = nullptr;
            const uint64_t seed = colon == std::string::npos ? 0 : std::strtoull(part.c_str(), &end, 10);
            const std::optional<PassSet> passes = colon == std::string::npos ? std::nullopt : PassSet::parse(part.substr(colon + 1));
            if (!passes || end != part.c_str() + colon || colon == 0 || in.parts.count(seed))
                throw UsageError(fmt::format("{}: invalid passes '{}' in its pathlab attributes", path, part));
            in.parts[seed] = *passes;
            a = b + 1;
        }
        in.invalid_samples = std::strtoull(attribute("pathlab:invalidSamples").c_str(), nullptr, 10);
        for (auto& [layer, image] : extras.layers)
            if (layer == "stderr") in.standard_error = std::move(image);
        if (in.standard_error.width() != in.mean.width() || in.standard_error.height() != in.mean.height())
            throw UsageError(fmt::format("{}: no standard-error layer (stderr.R, stderr.G, stderr.B) of the image's size", path));
        in.width = in.mean.width(), in.height = in.mean.height();
    }
    for (const auto& [seed, passes] : in.parts) in.spp += passes.count();
    if (in.spp == 0) throw UsageError(fmt::format("{}: holds no samples", path));
    return in;
}

}  // namespace

CLI::App* add_merge_command(CLI::App& app, MergeOptions& o) {
    CLI::App* cmd = app.add_subcommand("merge",
                                       "Combine renders of the same scene and settings with disjoint samples (--first-sample ranges, "
                                       "other seeds) into one EXR with its standard errors, weighting by sample counts");
    cmd->add_option("OUT", o.output, "The merged image (.exr: mean, the stderr layer and the pathlab:* attributes)")->required();
    cmd->add_option("IN", o.inputs, "Renders' EXRs (as pathlab writes them) or checkpoints (exact); two or more")->required();
    cmd->add_flag("-q,--quiet", o.quiet, "No summary");
    return cmd;
}

int run_merge_command(const MergeOptions& o) {
    OutputPaths paths;
    for (const std::string& p : o.inputs) paths.input(p, "an input");
    if (std::filesystem::path(o.output).extension() != ".exr") throw UsageError(fmt::format("{}: the merged image must be an .exr", o.output));
    paths.output(o.output, "the output", /*image=*/true);
    if (o.inputs.size() < 2) throw UsageError("merge needs at least two inputs");

    std::vector<MergeInput> inputs;
    for (const std::string& p : o.inputs) inputs.push_back(read_input(p));
    const MergeInput& a = inputs.front();
    for (size_t i = 1; i < inputs.size(); ++i) {
        const MergeInput& b = inputs[i];
        if (b.width != a.width || b.height != a.height)
            throw UsageError(fmt::format("{} is {}x{} but {} is {}x{}: renders of different sizes do not merge", a.path, a.width, a.height,
                                         b.path, b.width, b.height));
        const std::string diff = b.identity.differences(a.identity, kMergeFields, b.path, a.path);
        if (!diff.empty()) throw UsageError(fmt::format("{} and {} are not renders of the same scene and settings:\n{}", a.path, b.path, diff));
        for (size_t k = 0; k < i; ++k)
            for (const auto& [seed, passes] : b.parts) {
                const auto other = inputs[k].parts.find(seed);
                if (other != inputs[k].parts.end() && other->second.intersects(passes))
                    throw UsageError(fmt::format("{} and {} both hold passes of seed {} ({} and {}): the same samples cannot be merged twice",
                                                 inputs[k].path, b.path, seed, other->second.to_string(), passes.to_string()));
            }
    }

    const size_t pixels = size_t(a.width) * size_t(a.height);
    Image mean(a.width, a.height), standard_error(a.width, a.height);
    bool all_films = true;
    for (const MergeInput& in : inputs) all_films &= in.film.has_value();
    if (all_films) {
        // Exact: the films' accumulators add up to the one-shot film.
        Film film = *inputs.front().film;
        for (size_t i = 1; i < inputs.size(); ++i) film.merge(*inputs[i].film);
        mean = film.mean(), standard_error = film.standard_error();
    } else {
        for (size_t p = 0; p < pixels; ++p)
            for (int c = 0; c < 3; ++c) {
                double n = 0, m = 0, m2 = 0;
                for (const MergeInput& in : inputs) {
                    double nb, mb, m2b;
                    if (in.film) {
                        const PixelSums& s = in.film->data()[p];
                        nb = double(s.count);
                        if (nb == 0) continue;
                        mb = s.sum_value()[c] / nb;
                        m2b = std::max(0.0, s.sumsq_value()[c] - nb * mb * mb);
                    } else {
                        nb = double(in.spp);
                        mb = in.mean[p][c];
                        const double se = in.standard_error[p][c];
                        m2b = se * se * nb * (nb - 1);
                    }
                    const double total = n + nb, delta = mb - m;
                    m += delta * nb / total;
                    m2 += m2b + delta * delta * n * nb / total;
                    n = total;
                }
                mean[p][c] = float(m);
                standard_error[p][c] = n >= 2 ? float(std::sqrt(m2 / (n - 1) / n)) : 0.0f;
            }
    }

    // The output's attributes: the shared identity, every seed, and the passes.
    std::vector<std::pair<std::string, std::string>> attributes;
    std::map<uint64_t, PassSet> parts;
    uint64_t spp = 0, invalid = 0;
    for (const MergeInput& in : inputs) {
        for (const auto& [seed, passes] : in.parts) parts[seed].insert(passes);
        spp += in.spp, invalid += in.invalid_samples;
    }
    std::string seeds, parts_text;
    for (const auto& [seed, set] : parts) {
        seeds += (seeds.empty() ? "" : ",") + fmt::format("{}", seed);
        parts_text += (parts_text.empty() ? "" : ";") + fmt::format("{}:{}", seed, set.to_string());
    }
    for (const auto& [field, value] : a.identity.fields)
        if (field != "seed") attributes.emplace_back(metadata_key(field), value);
    attributes.emplace_back("pathlab:seed", seeds);
    attributes.emplace_back("pathlab:spp", fmt::format("{}", spp));
    if (parts.size() == 1) {
        attributes.emplace_back("pathlab:firstSample", fmt::format("{}", parts.begin()->second.begin()));
        attributes.emplace_back("pathlab:passes", parts.begin()->second.to_string());
    }
    attributes.emplace_back("pathlab:parts", parts_text);
    attributes.emplace_back("pathlab:invalidSamples", fmt::format("{}", invalid));
    attributes.emplace_back("pathlab:mergedFrom", fmt::format("{}", inputs.size()));
    attributes.emplace_back("pathlab:version", PATHLAB_VERSION);
    write_exr(mean, ExrExtras{{{"stderr", standard_error}}, attributes, {}}, o.output);
    if (!o.quiet)
        fmt::print(stderr, "merged {} renders ({}): {} spp{} -> {}\n", inputs.size(), all_films ? "exact, from checkpoints" : "from float images",
                   spp, invalid ? fmt::format(", {} NaN/Inf samples had been discarded (weights assume every pixel has spp samples)", invalid) : "",
                   o.output);
    return 0;
}

}  // namespace pathlab

// `pathlab convert IN OUT` and `pathlab info IMG...`: image tools in the manner of pbrt's imgtool.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <filesystem>

#include <nlohmann/json.hpp>

#include <fmt/format.h>

#include "app/tool_commands.hpp"
#include "image/image_header.hpp"
#include "image/image_io.hpp"
#include "app/resumed_command.hpp"
#include "job/checkpoint.hpp"
#include "job/output_paths.hpp"
#include "job/render_identity.hpp"
#include "job/usage_error.hpp"
#include "scenefile/gltf_scene.hpp"

namespace pathlab {
namespace {

bool is_png(const std::string& path) { return image_format_for(path) == ImageFormat::Png; }

bool ends_with_xml(const std::string& path) { return std::filesystem::path(path).extension() == ".xml"; }

// Any supported image as linear RGB (a PNG's sRGB values decoded); unreadable files are
// UsageErrors naming them.
Image read_any(const std::string& path) {
    try {
        return is_png(path) ? from_srgb8(read_png8(path)) : read_image(path);
    } catch (const ImageIoError& e) {
        throw UsageError(e.what());
    }
}

struct ChannelSummary {
    double sum = 0, min = INFINITY, max = -INFINITY;
    long finite = 0, nan = 0, inf = 0;
};

}  // namespace

CLI::App* add_convert_command(CLI::App& app, ConvertOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "convert", "Convert an image between .exr .hdr .pfm .png, with an exposure and a crop; or a glTF scene (.gltf, .glb) to Mitsuba XML");
    cmd->add_option("IN", o.input, "Input image (.exr, .hdr, .pfm, or .png: its sRGB values are decoded to linear), or a glTF scene")->required();
    cmd->add_option("OUT", o.output,
                    "Output image; format by extension (.png: sRGB, 8 bits). For a glTF scene, an .xml file (its meshes and images go in "
                    "the folder OUT's-stem_files beside it)")
        ->required();
    cmd->add_option("--exposure", o.exposure, "Scale the values by 2^E (stops), for every output format")->capture_default_str();
    cmd->add_option("--crop", o.crop, "Keep only X,Y,W,H (pixels from the top left)");
    return cmd;
}

int run_convert_command(const ConvertOptions& o) {
    if (is_gltf_path(o.input)) {
        if (!o.crop.empty() || o.exposure != 0) throw UsageError("--crop and --exposure are for images, not for a glTF scene");
        if (!ends_with_xml(o.output)) throw UsageError(fmt::format("{}: a glTF scene converts to a Mitsuba scene file ending in .xml", o.output));
        OutputPaths paths;
        paths.input(o.input, "the input");
        paths.output(o.output, "the output", /*image=*/false);
        try {
            const GltfConversion c = convert_gltf_scene(o.input, o.output);
            for (const std::string& w : c.warnings) fmt::print(stderr, "pathlab: warning: {}: {}\n", o.input, w);
        } catch (const SceneFileError& e) {
            throw UsageError(e.what());
        }
        return 0;
    }
    if (!std::isfinite(o.exposure)) throw UsageError("--exposure must be a finite number of stops");
    std::optional<PixelRect> rect;
    if (!o.crop.empty()) rect = parse_crop_option(o.crop);
    OutputPaths paths;
    paths.input(o.input, "the input");
    paths.output(o.output, "the output", /*image=*/true);
    Image img = read_any(o.input);
    if (rect) {
        if (rect->x + rect->width > img.width() || rect->y + rect->height > img.height())
            throw UsageError(fmt::format("--crop {}: not inside the {}x{} image {}", o.crop, img.width(), img.height(), o.input));
        img = crop(img, *rect);
    }
    if (o.exposure != 0) {
        const float scale = std::exp2(o.exposure);
        for (size_t i = 0; i < img.pixel_count(); ++i) img[i] = img[i] * scale;
    }
    write_image(img, o.output);
    return 0;
}

CLI::App* add_info_command(CLI::App& app, InfoOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "info", "Size, channels, metadata (every header attribute: spp, seed, ... when written), per-channel mean/min/max, NaN/Inf counts; of a checkpoint, the render it holds");
    cmd->add_option("IMG", o.images, "Images (.exr, .hdr, .pfm, .png), or checkpoints (--checkpoint: the render they are of, their image so far)")->required();
    cmd->add_flag("--json", o.json, "Print the results as JSON");
    return cmd;
}

namespace {

// A checkpoint described as info describes an image: its render's identity as the metadata
// (the fields an EXR of that render carries, pathlab:scene ...), the passes it holds, the
// time spent and the version that wrote it; the image is the film's mean so far.
ImageHeader checkpoint_header(const CheckpointInfo& info) {
    ImageHeader h;
    h.format = "pathlab checkpoint";
    h.channels = {"R (mean so far)", "G (mean so far)", "B (mean so far)"};
    for (const auto& [key, value] : info.identity.fields) h.attributes.emplace_back(metadata_key(key), value);
    h.attributes.emplace_back("pathlab:spp", std::to_string(info.passes.count()));
    h.attributes.emplace_back("pathlab:passes", info.passes.to_string());
    h.attributes.emplace_back("pathlab:seconds", fmt::format("{:.3f}", info.seconds));
    h.attributes.emplace_back("pathlab:version", info.writer);
    // What continues it: `pathlab --resume FILE` runs this command (app/resumed_command.hpp).
    if (!info.command.empty()) h.attributes.emplace_back("pathlab:command", command_line(info.command));
    return h;
}

}  // namespace

int run_info_command(const InfoOptions& o) {
    nlohmann::json all = nlohmann::json::array();
    for (const std::string& path : o.images) {
        // A checkpoint (--checkpoint): what render it is of, and its image so far.
        std::optional<Checkpoint> checkpoint;
        if (is_checkpoint_file(path)) {
            try {
                checkpoint = read_checkpoint(path);
            } catch (const CheckpointError& e) {
                throw UsageError(e.what());
            }
        }
        const bool png = !checkpoint && [&] {
            try {
                return is_png(path);
            } catch (const ImageIoError& e) {
                throw UsageError(e.what());
            }
        }();
        // Pixels first: the reader validates the whole file before its header is looked at.
        Image img;
        Image8 img8;
        ImageHeader header;
        if (checkpoint) {
            img = checkpoint->film.mean();
            header = checkpoint_header(checkpoint->info);
        } else {
            try {
                if (png) img8 = read_png8(path);
                else img = read_image(path);
            } catch (const ImageIoError& e) {
                throw UsageError(e.what());
            }
            try {
                header = read_image_header(path);
            } catch (const ImageIoError& e) {
                throw UsageError(e.what());
            }
        }
        header.width = png ? img8.width : img.width();
        header.height = png ? img8.height : img.height();
        std::array<ChannelSummary, 3> ch;
        const size_t n = png ? size_t(img8.width) * size_t(img8.height) : img.pixel_count();
        for (size_t i = 0; i < n; ++i)
            for (int c = 0; c < 3; ++c) {
                // A PNG's values as stored (0-255); a linear image's as they are.
                const double v = png ? double(img8.rgb[i * 3 + size_t(c)]) : double(img[i][c]);
                ChannelSummary& s = ch[size_t(c)];
                if (std::isnan(v)) ++s.nan;
                else if (std::isinf(v)) ++s.inf;
                else s.sum += v, s.min = std::min(s.min, v), s.max = std::max(s.max, v), ++s.finite;
            }
        const auto mean = [](const ChannelSummary& s) { return s.finite ? s.sum / double(s.finite) : 0.0; };
        const long nan = ch[0].nan + ch[1].nan + ch[2].nan, inf = ch[0].inf + ch[1].inf + ch[2].inf;
        if (o.json) {
            nlohmann::json j = {{"file", path}, {"format", header.format}, {"width", header.width}, {"height", header.height},
                                {"channels", header.channels}, {"attributes", nlohmann::json::object()}, {"nan", nan}, {"inf", inf},
                                {"values", png ? "8-bit codes (0-255)" : "linear"}};
            for (const auto& [k, v] : header.attributes) j["attributes"][k] = v;
            for (int c = 0; c < 3; ++c)
                j["mean"].push_back(mean(ch[size_t(c)])), j["min"].push_back(ch[size_t(c)].finite ? ch[size_t(c)].min : 0.0),
                    j["max"].push_back(ch[size_t(c)].finite ? ch[size_t(c)].max : 0.0);
            all.push_back(j);
            continue;
        }
        fmt::print("{}: {}x{} {}\n", path, header.width, header.height, header.format);
        fmt::print("  channels: {}\n", fmt::join(header.channels, ", "));
        if (!header.attributes.empty()) {
            fmt::print("  metadata:\n");
            for (const auto& [k, v] : header.attributes) fmt::print("    {}: {}\n", k, v);
        }
        fmt::print("  {:<9}{:>13}{:>13}{:>13}{}\n", "", "R", "G", "B", png ? "   (8-bit codes, 0-255)" : "");
        fmt::print("  {:<9}{:>13.6g}{:>13.6g}{:>13.6g}\n", "mean", mean(ch[0]), mean(ch[1]), mean(ch[2]));
        fmt::print("  {:<9}{:>13.6g}{:>13.6g}{:>13.6g}\n", "min", ch[0].finite ? ch[0].min : 0.0, ch[1].finite ? ch[1].min : 0.0,
                   ch[2].finite ? ch[2].min : 0.0);
        fmt::print("  {:<9}{:>13.6g}{:>13.6g}{:>13.6g}\n", "max", ch[0].finite ? ch[0].max : 0.0, ch[1].finite ? ch[1].max : 0.0,
                   ch[2].finite ? ch[2].max : 0.0);
        fmt::print("  NaN/Inf pixel-channels: {} NaN, {} Inf{}\n", nan, inf, nan + inf ? " (left out of mean, min and max)" : "");
    }
    if (o.json) fmt::print("{}\n", all.size() == 1 ? all[0].dump(2) : all.dump(2));
    return 0;
}

}  // namespace pathlab

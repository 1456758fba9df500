// vcm and bpm in spectral mode (docs/spectral.md, "Spectral vcm and bpm"). vcm.cpp's iteration
// (the same light subpaths, camera subpaths, photons, radius schedule, random streams and MIS
// weights) with every path of a pass at the pass's wavelengths (pass_wavelengths, as the photon
// methods): a merge multiplies a camera throughput by a photon's power, and a connection two
// subpaths' throughputs, lane by lane, so the camera path of every pixel and the light paths of
// every pixel must carry the same wavelengths. The subpaths are bdpt's spectral ones
// (light_subpath_spectral, camera_subpath_spectral), the connections bdpt's connect_spectral with
// the merging strategies in their weights; only values are spectral, the weights are RGB mode's.
//
// Dispersion: a subpath that met a dispersive interface carries the hero alone. A connection
// through one is hero_only() in connect_spectral; a merge whose photon or camera vertex was
// reached through one counts lane 0 times 4, once for the whole path (SpectralMergeSum against
// the camera's wavelengths, then hero_only() when the camera side is the dispersed one).
// Each pixel's own contributions are summed at the wavelengths and converted once with the
// pass's wavelengths; each light-tracing splat (t = 1) on its own. A separate file so that
// vcm.cpp's RGB loops compile as they did.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "integrators/bidir/hero_only.hpp"
#include "integrators/photon/progressive_radius.hpp"
#include "integrators/photon/vcm.hpp"
#include "spectral/xyz_estimator.hpp"

namespace pathlab {

uint64_t Vcm::trace_light_paths_spectral(const RenderContext& ctx, uint64_t pass, const SampledWavelengths& wl) {
    const size_t paths = ctx.pixel_count(), per_chunk = Bdpt::chunk_size(paths), chunks = (paths + per_chunk - 1) / per_chunk;
    chunk_vertices_.resize(chunks);
    chunk_betas_.resize(chunks);
    chunk_photons_.resize(chunks);
    chunk_powers_.resize(chunks);
    chunk_photon_vertex_.resize(chunks);
    path_begin_.resize(paths);
    path_length_.resize(paths);
    path_dispersed_from_.resize(paths);
    const int max_bounces = bdpt_.max_bounces();
    std::atomic<uint64_t> rays{0};
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        SpectralSubpath& path = spectral_subpaths_.local().second;
        std::vector<PathVertex>& vertices = chunk_vertices_[c];
        std::vector<Spectrum4>& betas = chunk_betas_[c];
        std::vector<Photon>& photons = chunk_photons_[c];
        std::vector<SpectralPower>& powers = chunk_powers_[c];
        std::vector<uint32_t>& photon_vertex = chunk_photon_vertex_[c];
        vertices.clear(), betas.clear(), photons.clear(), powers.clear(), photon_vertex.clear();
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            // Light path j is pixel j's, from bdpt's stream (vcm.cpp), at the pass's wavelengths.
            Sampler sampler(ctx.seed, Bdpt::sample_stream(j, 1), pass, ctx.sampler);
            bdpt_.light_subpath_spectral(ctx, sampler, wl, path);
            path_begin_[j] = uint32_t(vertices.size());
            path_length_[j] = uint16_t(path.size());
            path_dispersed_from_[j] = path.dispersed_from;
            for (size_t v = 1; v < path.size(); ++v) {
                const PathVertex& y = path.vertices[v];
                if (y.kind != VertexKind::Surface || !y.connectible() || int(v) > max_bounces) continue;
                photons.push_back({y.p, y.sp.frame.to_world(y.sp.wi), Rgb(0.0f), uint16_t(v)});  // power: powers_
                powers.push_back({path.beta[v], path.dispersed(int(v))});
                photon_vertex.push_back(uint32_t(vertices.size() + v));
            }
            vertices.insert(vertices.end(), path.vertices.begin(), path.vertices.end());
            betas.insert(betas.end(), path.beta.begin(), path.beta.end());
        }
        rays += Scene::rays_traced_by_this_thread() - rays_before;
    });
    photons_.clear();
    powers_.clear();
    photon_vertex_.clear();
    for (size_t c = 0; c < chunks; ++c) {
        photons_.insert(photons_.end(), chunk_photons_[c].begin(), chunk_photons_[c].end());
        powers_.insert(powers_.end(), chunk_powers_[c].begin(), chunk_powers_[c].end());
        for (const uint32_t v : chunk_photon_vertex_[c]) photon_vertex_.push_back(&chunk_vertices_[c][v]);
    }
    return rays.load();
}

Spectrum4 Vcm::merge_spectral(const SpectralSubpath& camera, int t, float r, const MergeMis& vm, const SampledWavelengths& wl) const {
    const PathVertex& z = camera.vertices[size_t(t - 1)];
    const int max_bounces = bdpt_.max_bounces();
    SpectralMergeSum sum;
    grid_.for_each_within(z.p, r, [&](const Photon& ph) {
        const int s = int(ph.vertex) + 1;
        const int depth = s + t - 3;
        if (depth > max_bounces || (options_.only_length >= 0 && depth != options_.only_length)) return;
        const Spectrum4 f = merge_bsdf_spectral(z.sp, ph.wi, wl);
        if (f.is_black()) return;
        const size_t k = size_t(&ph - photons_.data());
        const PathVertex* y = photon_vertex_[k] - ph.vertex;
        sum.add(f * merge_weight(y, s, camera.vertices, t, vm), powers_[k]);
    });
    // The factor 4 once per path: a hero-only photon counts 4 times against a camera path of 4
    // lanes; against a dispersed camera path once, and that path's own hero_only() gives the 4.
    const bool camera_dispersed = camera.dispersed(t - 1);
    SampledWavelengths camera_wl = wl;
    if (camera_dispersed) camera_wl.terminate_secondary();
    const Spectrum4 m = camera.beta[size_t(t - 1)] * sum.total(camera_wl) / float(norm_);
    return camera_dispersed ? hero_only(m) : m;
}

PassCounters Vcm::render_spectral_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    const size_t pixels = ctx.pixel_count(), per_chunk = Bdpt::chunk_size(pixels);
    const int chunks = int((pixels + per_chunk - 1) / per_chunk);
    const double r1 = initial_photon_radius(ctx, options_), alpha = options_.photon_alpha;
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        const SampledWavelengths wl = pass_wavelengths(ctx, pass);
        const float r = float(progressive_radius(r1, alpha, pass + 1));
        MergeMis vm;
        vm.merging = options_.vcm_merging;
        vm.connections = options_.vcm_connections;
        norm_ = double(pixels) * (faults_.no_pi_in_kernel ? 1.0 : kPi) * double(r) * double(r);
        vm.eta = norm_;
        rays += trace_light_paths_spectral(ctx, pass, wl);
        if (vm.merging) grid_.build(photons_, r);
        if (progress) progress((double(k) + 0.25) / count);
        pass_.begin(pixels, chunks);
        const bool filtered = ctx.filter && !ctx.filter->is_box();
        const Vec2f shift = filtered ? filter_shift(ctx, pass) : Vec2f(0.0f, 0.0f);
        std::atomic<int> chunks_done{0};
        tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& range) {
            auto& subpaths = spectral_subpaths_.local();
            SpectralSubpath& camera = subpaths.first;
            SpectralSubpath& light = subpaths.second;
            for (int c = range.begin(); c != range.end(); ++c) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t chunk_invalid = 0;
                SplatList& splats = pass_.chunk(c);
                for (size_t pixel = size_t(c) * per_chunk; pixel < std::min(pixels, size_t(c + 1) * per_chunk); ++pixel) {
                    Sampler camera_sampler(ctx.seed, pixel, pass, ctx.sampler);
                    bdpt_.camera_subpath_spectral(ctx, pixel, camera_sampler, wl, camera, filtered ? &shift : nullptr);
                    // This pixel's light subpath, copied (connections modify it for a moment).
                    const size_t chunk = pixel / per_chunk, begin = path_begin_[pixel], end = begin + path_length_[pixel];
                    light.clear();
                    light.vertices.assign(chunk_vertices_[chunk].begin() + begin, chunk_vertices_[chunk].begin() + end);
                    light.beta.assign(chunk_betas_[chunk].begin() + begin, chunk_betas_[chunk].begin() + end);
                    light.dispersed_from = path_dispersed_from_[pixel];
                    Spectrum4 own(0.0f);  // the pixel's own contributions, converted once
                    const auto add = [&](const Spectrum4& value, bool splat, const Vec2f& raster) {
                        if (!value.is_finite()) return void(++chunk_invalid);
                        if (!splat) return void(own += value);
                        const Rgb rgb(spectral_sample_to_linear_srgb(value, wl));
                        if (filtered) splats.add_at(raster, rgb);
                        else splats.add(uint32_t(ctx.camera.pixel_of(raster)), rgb);
                    };
                    bdpt_.for_each_connection_spectral(
                        ctx, pixel, pass, light, camera, wl, &vm,
                        [&](int, int, const SpectralStrategyResult& res) { add(res.L * res.weight, res.splat, res.raster); },
                        [&](int t) {
                            const PathVertex& z = camera.vertices[size_t(t - 1)];
                            if (vm.merging && t >= 2 && z.kind == VertexKind::Surface && z.connectible()) {
                                const Spectrum4 m = merge_spectral(camera, t, r, vm, wl);
                                if (!m.is_black()) add(m, false, {});
                            }
                        });
                    if (!own.is_black()) pass_.pixel(pixel) += spectral_sample_to_linear_srgb(own, wl);
                }
                rays += Scene::rays_traced_by_this_thread() - rays_before;
                invalid += chunk_invalid;
                if (progress) progress((double(k) + 0.25 + 0.75 * double(++chunks_done) / chunks) / count);
            }
        });
        pass_.finish(film, ctx.filter, shift);
    }
    return {rays.load(), invalid.load()};
}

}  // namespace pathlab

#include "integrators/photon/vcm.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/photon/progressive_radius.hpp"

namespace pathlab {

template <class T>
Vcm<T>::Vcm(const IntegratorOptions& options, VcmFaults faults) : options_(limited_to_length(options)), faults_(faults), bdpt_(options_) {}

template <class T>
size_t Vcm<T>::light_vertex_count() const {
    size_t n = 0;
    for (const auto& c : chunk_vertices_) n += c.size();
    return n;
}

template <class T>
size_t Vcm<T>::memory_bytes() const {
    size_t bytes = grid_.memory_bytes() + photons_.capacity() * sizeof(MergeVertex<T>) + photon_r_.capacity() * sizeof(Colour) +
                   chunk_photons_.capacity() * sizeof(size_t) +
                   path_begin_.capacity() * sizeof(uint32_t) + path_length_.capacity() * sizeof(uint16_t);
    for (const auto& c : chunk_vertices_) bytes += c.capacity() * sizeof(Vertex);
    return bytes;
}

namespace {

// Whether light vertex y_j is stored as a photon (merging needs a non-Dirac surface, or a medium).
template <class Vertex>
bool is_photon(const Vertex& y, size_t j, int max_bounces) {
    return j >= 1 && merges_at(y.kind) && y.connectible() && int(j) <= max_bounces;
}

// What a merge at vertex v needs of its scattering towards the world direction w (a photon's):
// the BSDF (or phase function) value, and the solid-angle densities of sampling w from v's own
// arrival direction and of sampling that from w.
struct MergeScatter {
    Rgb f{0.0f};  // (a phase function's value is grey)
    float pdf_to_light = 0, pdf_to_camera = 0;
};

MergeScatter merge_scatter(const Scene& scene, const PathVertexBase& z, const Vec3f& w) {
    MergeScatter m;
    if (z.kind == VertexKind::Medium) {
        const PhaseFunction& phase = medium_phase(scene.medium(z.medium));
        m.f = Rgb(phase_eval(phase, z.dir, w));
        m.pdf_to_light = phase_pdf(phase, z.dir, w);
        m.pdf_to_camera = phase_pdf(phase, w, z.dir);
        return m;
    }
    const Vec3f wo = z.sp.frame.to_local(w);
    m.f = z.sp.material->eval_and_pdf(z.sp, z.sp.wi, wo, m.pdf_to_light);
    if (!is_black(m.f)) m.pdf_to_camera = z.sp.material->pdf(z.sp, wo, z.sp.wi);
    return m;
}

// The solid-angle density 1 at `from` towards `to` as a density at `to` (area or volume, with
// the distance-sampling factor of the edge between them, whose transmittance `from` keeps).
float reverse_density_factor(const PathVertexBase& from, const PathVertexBase& to) {
    return to_area_density(1.0f, from, to) * to.distance_factor(from.T_in);
}

}  // namespace

template <class T>
MergeMis Vcm<T>::merge_mis(size_t light_paths, double r) const {
    MergeMis vm;
    vm.merging = options_.vcm_merging;
    vm.connections = options_.vcm_connections;
    const double pi = faults_.no_pi_in_kernel ? 1.0 : kPi;
    vm.eta = double(light_paths) * pi * r * r;
    vm.eta_volume = faults_.volume_kernel_as_disc ? vm.eta : double(light_paths) * 4.0 / 3.0 * pi * r * r * r;
    return vm;
}

template <class T>
MergeVertex<T> Vcm<T>::merge_vertex(const Vertex* y, int j) {
    const Vertex& v = y[j];
    const Vertex& prev = y[j - 1];
    MergeVertex<T> m;
    m.p = v.p;
    m.medium = photon_medium(v);
    m.wi = m.in_medium() ? v.dir : v.sp.frame.to_world(v.sp.wi);
    m.power = v.beta;
    m.vertex = uint16_t(j);
    m.dispersed = v.dispersed;
    m.pdf_fwd = v.pdf_fwd;
    m.prev_pdf_fwd = prev.pdf_fwd;
    m.prev_g = reverse_density_factor(v, prev);
    m.mis_running = float(v.mis_running);
    m.prev_delta = prev.delta;
    return m;
}

template <class T>
uint64_t Vcm<T>::trace_light_paths(const RenderContext& ctx, uint64_t pass, const Wavelengths& wl, const MergeMis& vm, int hero) {
    const size_t paths = ctx.pixel_count(), per_chunk = Bdpt<T>::chunk_size(paths), chunks = (paths + per_chunk - 1) / per_chunk;
    chunk_vertices_.resize(chunks);
    chunk_photons_.resize(chunks + 1);
    path_begin_.resize(paths);
    path_length_.resize(paths);
    const int max_bounces = bdpt_.max_bounces();
    std::atomic<uint64_t> rays{0};
    // The light subpaths, chunk by chunk, and how many merge vertices each chunk has.
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        std::vector<Vertex>& path = subpaths_.local().second;  // keeps its capacity from pass to pass
        std::vector<Vertex>& vertices = chunk_vertices_[c];
        vertices.clear();
        size_t photons = 0;
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            // Light path j is pixel j's, from bdpt's stream: the same path bdpt would connect.
            Sampler sampler(ctx.seed, Bdpt<T>::sample_stream(j, 1), pass, ctx.sampler);
            bdpt_.light_subpath(ctx, sampler, wl, path, &vm, hero);
            path_begin_[j] = uint32_t(vertices.size());
            path_length_[j] = uint16_t(path.size());
            for (size_t v = 1; v < path.size(); ++v) photons += is_photon(path[v], v, max_bounces);
            vertices.insert(vertices.end(), path.begin(), path.end());
        }
        chunk_photons_[c + 1] = photons;
        rays += Scene::rays_traced_by_this_thread() - rays_before;
    });
    // One array of merge vertices, each chunk writing its own range (in path order).
    chunk_photons_[0] = 0;
    for (size_t c = 0; c < chunks; ++c) chunk_photons_[c + 1] += chunk_photons_[c];
    photons_.resize(vm.merging ? chunk_photons_[chunks] : 0);
    const bool media = ctx.scene.has_media();
    photon_r_.resize(vm.merging && media ? photons_.size() : 0);
    if (vm.merging) {
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            size_t k = chunk_photons_[c];
            const std::vector<Vertex>& vertices = chunk_vertices_[c];
            for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
                const Vertex* y = vertices.data() + path_begin_[j];
                for (size_t v = 1; v < path_length_[j]; ++v)
                    if (is_photon(y[v], v, max_bounces)) {
                        if (media) photon_r_[k] = y[v].r;
                        photons_[k++] = merge_vertex(y, int(v));
                    }
            }
        });
    }
    return rays.load();
}

template <class T>
float Vcm<T>::merge_weight(const MergeVertex<T>& photon, float pdf_to_light, float pdf_to_camera, const std::vector<Vertex>& camera,
                           int t, const MergeMis& vm, float camera_prev_g) const {
    // The path is weighed as the connection (s - 1, t) whose camera endpoint is z = z_{t-1}
    // (standing for the photon's vertex y_{s-1}): z's light-side density is the photon's, and
    // the densities through z of its neighbours are z's BSDF's, between the photon's direction
    // and the camera's. The rest of both subpaths keep their densities: their running quantities.
    const MisRules rules(bdpt_.power_heuristic(), &vm);
    const Vertex& z = camera[size_t(t - 1)];
    const double light_prev_rev = double(pdf_to_light) * double(photon.prev_g);
    if (camera_prev_g < 0) camera_prev_g = reverse_density_factor(z, camera[size_t(t - 2)]);
    const double camera_prev_rev = double(pdf_to_camera) * double(camera_prev_g);
    // The light side ends at y_{s-2}, whose density from z is light_prev_rev.
    const double light = rules.h(MisRules::remap0(light_prev_rev) / MisRules::remap0(photon.prev_pdf_fwd)) * double(photon.mis_running);
    // The camera side includes this merge itself: its density, psi, times eta.
    const double psi = double(photon.pdf_fwd);
    const double camera_sum = camera_side_sum(camera.data(), t - 1, z.pdf_fwd, photon.pdf_fwd, psi, true, camera_prev_rev, rules);
    // The connection (s - 1, t) is the reference, 1, where it exists.
    const double reference = vm.connections && !photon.prev_delta ? 1.0 : 0.0;
    const double own = rules.h((faults_.merge_weight_without_light_pdf ? 1.0 : psi) * merge_eta(vm, z.kind));
    const double total = reference + light + camera_sum;
    return total > 0 ? float(own / total) : 0.0f;
}

template <class T>
float Vcm<T>::merge_weight(const Scene& scene, const Vertex* y, int s, const std::vector<Vertex>& camera, int t, const MergeMis& vm) const {
    const MergeVertex<T> photon = merge_vertex(y, s - 1);
    const MergeScatter m = merge_scatter(scene, camera[size_t(t - 1)], photon.wi);
    return merge_weight(photon, m.pdf_to_light, m.pdf_to_camera, camera, t, vm);
}

template <class T>
float Vcm<T>::merge_weight_oracle(const Scene& scene, const Vertex* y, int s, const std::vector<Vertex>& camera, int t,
                                  const MergeMis& vm) const {
    // As merge_weight, by Veach's ratio walk over both subpaths.
    const Vertex& z = camera[size_t(t - 1)];
    const Vertex& photon = y[s - 1];
    // z sampling the photon's direction, and the camera's from the photon's.
    const MergeScatter m = merge_scatter(scene, z, merge_vertex(y, s - 1).wi);
    const float light_prev_rev = m.pdf_to_light * reverse_density_factor(photon, y[s - 2]);
    const float camera_prev_rev = m.pdf_to_camera * reverse_density_factor(z, camera[size_t(t - 2)]);
    const MisVertex zm{z.pdf_fwd, photon.pdf_fwd, false, false, z.kind};
    const auto light_at = [&](int i) {
        MisVertex m = mis_vertex(y[i]);
        if (i == s - 2) m.pdf_rev = light_prev_rev;
        return m;
    };
    const auto camera_at = [&](int i) {
        if (i == t - 1) return zm;
        MisVertex m = mis_vertex(camera[size_t(i)]);
        if (i == t - 2) m.pdf_rev = camera_prev_rev;
        return m;
    };
    const bool power = bdpt_.power_heuristic();
    // The sum includes this merge itself (merging at camera vertex t - 1), and the connection
    // (s - 1, t) is the reference, 1, where it exists.
    const double others = mis_ratio_sum(light_at, s - 1, camera_at, t, power, &vm);
    const double reference = vm.connections && !y[s - 2].delta ? 1.0 : 0.0;
    double own = (faults_.merge_weight_without_light_pdf ? 1.0 : double(photon.pdf_fwd)) * merge_eta(vm, z.kind);
    if (power) own *= own;
    const double total = reference + others;
    return total > 0 ? float(own / total) : 0.0f;
}

template <class T>
ColourOf<T> Vcm<T>::merge(const Scene& scene, const std::vector<Vertex>& camera, int t, float r, const MergeMis& vm,
                          const Wavelengths& wl) const {
    const Vertex& z = camera[size_t(t - 1)];
    const bool in_medium = z.kind == VertexKind::Medium;
    // Photons of the same medium only (in a medium; a ball may reach across a boundary).
    const int16_t merged_medium = photon_medium(z);
    const bool media = !photon_r_.empty();
    const int max_bounces = bdpt_.max_bounces();
    MergeSum<T> sum;
    const float camera_prev_g = reverse_density_factor(z, camera[size_t(t - 2)]);
    grid_.for_each_within(z.p, r, [&](uint32_t k) {
        const MergeVertex<T>& ph = photons_[k];
        if (ph.medium != merged_medium) return;
        const int s = int(ph.vertex) + 1;
        const int depth = s + t - 3;
        if (depth > max_bounces || (options_.only_length >= 0 && depth != options_.only_length)) return;
        const MergeScatter m = merge_scatter(scene, z, ph.wi);
        if (is_black(m.f)) return;
        Colour c = (in_medium ? Colour(m.f.x) : bsdf_colour(z.sp, z.sp.frame.to_local(ph.wi), m.f, wl)) * ph.power *
                   merge_weight(ph, m.pdf_to_light, m.pdf_to_camera, camera, t, vm, camera_prev_g);
        // In media: the spectral MIS over the hero channel that both subpaths shared.
        if (media) c /= path_density_of(photon_r_[k] * z.r, ph.dispersed || z.dispersed);
        sum.add(c, ph.dispersed);
    });
    // The factor 4 once per path: a dispersed photon counts 4 times against a camera path of 4
    // lanes; against a dispersed camera path once, and that path's own hero_only() gives the 4.
    Wavelengths camera_wl = wl;
    if (z.dispersed) camera_wl.terminate_secondary();
    Colour beta = z.beta;
    if (in_medium) {
        // Both throughputs include the scattering coefficient at the merged point: the path, once.
        beta = divide_where_positive(beta, medium_view(scene.medium(z.medium), wl).coefficients(z.p).sigma_s);
    }
    const Colour m = beta * sum.total(camera_wl) / float(in_medium ? vm.eta_volume : vm.eta);
    return z.dispersed ? hero_only(m) : m;
}

template <class T>
PassCounters Vcm<T>::render_passes(const RenderContext& ctx, Film& film, uint64_t first, int count, const PassProgress& progress) {
    const size_t pixels = ctx.pixel_count(), per_chunk = Bdpt<T>::chunk_size(pixels);
    const int chunks = int((pixels + per_chunk - 1) / per_chunk);
    const double r1 = initial_photon_radius(ctx, options_), alpha = options_.photon_alpha;
    std::atomic<uint64_t> rays{0}, invalid{0};
    for (int k = 0; k < count; ++k) {
        const uint64_t pass = first + uint64_t(k);
        const Wavelengths wl = T::pass_wavelengths(ctx.seed, ctx.sampler, pass);
        const float r = float(progressive_radius(r1, alpha, pass + 1));
        const MergeMis vm = merge_mis(pixels, r);
        // In media, one hero channel for every subpath of the iteration (see vcm.hpp).
        const int hero = Bdpt<T>::sample_hero(ctx, pixels, pass, wl);
        rays += trace_light_paths(ctx, pass, wl, vm, hero);
        if (vm.merging) grid_.build_sorted(photons_, r, &photon_r_);
        if (progress) progress((double(k) + 0.25) / count);
        pass_.begin(pixels, chunks);
        const bool filtered = ctx.filter && !ctx.filter->is_box();
        const Vec2f shift = filtered ? filter_shift(ctx, pass) : Vec2f(0.0f, 0.0f);
        std::atomic<int> chunks_done{0};
        tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& range) {
            // Named references, not a structured binding: lambdas below capture them, which C++20
            // allows for bindings but clang before 16 (Debian 12's is 14: the fuzz build) does not.
            auto& subpaths = subpaths_.local();
            std::vector<Vertex>& camera = subpaths.first;
            for (int c = range.begin(); c != range.end(); ++c) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t chunk_invalid = 0;
                SplatList& splats = pass_.chunk(c);
                for (size_t pixel = size_t(c) * per_chunk; pixel < std::min(pixels, size_t(c + 1) * per_chunk); ++pixel) {
                    Sampler camera_sampler(ctx.seed, pixel, pass, ctx.sampler);
                    bdpt_.camera_subpath(ctx, pixel, camera_sampler, wl, camera, filtered ? &shift : nullptr, &vm, hero);
                    // This pixel's light subpath, as stored (connections only read it).
                    const typename Bdpt<T>::SubpathView light(chunk_vertices_[pixel / per_chunk].data() + path_begin_[pixel],
                                                              path_length_[pixel]);
                    // The pixel's own contributions, summed and converted once; splats (t = 1) on their own.
                    typename T::SampleSum own(0.0f);
                    const auto add = [&](const Colour& value, bool splat, const Vec2f& raster) {
                        if (!is_finite(value)) return void(++chunk_invalid);
                        if (splat && filtered) splats.add_at(raster, Rgb(film_colour(value, wl)));
                        else if (splat) splats.add(uint32_t(ctx.camera.pixel_of(raster)), Rgb(film_colour(value, wl)));
                        else accumulate(own, value);
                    };
                    // bdpt's connections, then merging at each camera vertex z_{t-1}.
                    bdpt_.for_each_connection(
                        ctx, pixel, pass, light, camera, wl, &vm,
                        [&](int, int, const StrategyResult<T>& res) { add(res.L * res.weight, res.splat, res.raster); },
                        [&](int t) {
                            const Vertex& z = camera[size_t(t - 1)];
                            if (vm.merging && t >= 2 && merges_at(z.kind) && z.connectible()) {
                                const Colour m = merge(ctx.scene, camera, t, r, vm, wl);
                                if (!is_black(m)) add(m, false, {});
                            }
                        });
                    pass_.pixel(pixel) += film_colour(own, wl);
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

template class Vcm<RgbTransport>;
template class Vcm<SpectralTransport>;
// The VCM report's target for a light vertex kept for merging: a cache line.
static_assert(sizeof(MergeVertex<RgbTransport>) <= 64 && sizeof(MergeVertex<SpectralTransport>) <= 64);

namespace {

std::vector<ParamInfo> vcm_params() {
    std::vector<ParamInfo> p = path_params();
    for (ParamInfo& r : progressive_radius_params()) p.push_back(std::move(r));
    return p;
}

}  // namespace

const IntegratorInfo& vcm_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"vcm", {}, "vertex connection and merging: bdpt's connections and photon merging, combined by MIS",
                         false, true, vcm_params(), [](const IntegratorOptions& o) { return make_for_transport<Vcm>(o); }, false, true};
        i.media = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

const IntegratorInfo& bpm_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i{"bpm", {}, "bidirectional photon mapping: merging at every camera vertex, combined by MIS (vcm without connections)",
                         false, true, vcm_params(),
                         [](IntegratorOptions o) {
                             o.vcm_connections = false;
                             o.vcm_merging = true;
                             return make_for_transport<Vcm>(o);
                         },
                         false, true};
        i.media = true;
        i.light_paths = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab

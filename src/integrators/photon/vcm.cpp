#include "integrators/photon/vcm.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include <fmt/format.h>

#include "integrators/common/path_rules.hpp"
#include "integrators/integrators.hpp"
#include "integrators/photon/progressive_radius.hpp"

namespace pathlab {

namespace {
constexpr const char* kEstimatorNames[] = {"bpt", "surf", "pp3d", "pb2d", "bb1d"};
}  // namespace

VcmEstimators parse_estimators(const std::string& list) {
    if (list.empty() || list == "all") return {true, true, true, true, true};
    VcmEstimators e{false, false, false, false, false};
    bool* flags[] = {&e.bpt, &e.surf, &e.pp3d, &e.pb2d, &e.bb1d};
    size_t begin = 0;
    while (begin <= list.size()) {
        const size_t end = std::min(list.find(',', begin), list.size());
        const std::string name = list.substr(begin, end - begin);
        const auto* found = std::find(std::begin(kEstimatorNames), std::end(kEstimatorNames), name);
        if (found == std::end(kEstimatorNames))
            throw std::invalid_argument(fmt::format("unknown estimator '{}' in --estimators {}. Valid estimators: bpt, surf, pp3d, pb2d, bb1d (or all)", name,
                                         list));
        *flags[found - std::begin(kEstimatorNames)] = true;
        begin = end + 1;
    }
    return e;
}

std::string estimator_names(const VcmEstimators& e) {
    const bool flags[] = {e.bpt, e.surf, e.pp3d, e.pb2d, e.bb1d};
    std::string names;
    for (size_t k = 0; k < std::size(flags); ++k)
        if (flags[k]) names += (names.empty() ? "" : ",") + std::string(kEstimatorNames[k]);
    return names;
}

template <class T>
Vcm<T>::Vcm(const IntegratorOptions& options, VcmFaults faults)
    : options_(limited_to_length(options)),
      estimators_(options.estimators.empty()
                      ? VcmEstimators{options.vcm_connections, options.vcm_merging, options.vcm_merging, false, false}
                      : parse_estimators(options.estimators)),
      faults_(faults),
      bdpt_(options_) {}

template <class T>
size_t Vcm<T>::light_vertex_count() const {
    size_t n = 0;
    for (const auto& c : chunk_vertices_) n += c.size();
    return n;
}

template <class T>
size_t Vcm<T>::memory_bytes() const {
    size_t bytes = grid_.memory_bytes() + photons_.capacity() * sizeof(MergeVertex<T>) + photon_r_.capacity() * sizeof(Colour) +
                   chunk_photons_.capacity() * sizeof(size_t) + volume_tree_.memory_bytes() + beam_tree_.memory_bytes() +
                   light_beams_.capacity() * sizeof(LightBeam) +
                   volume_index_.capacity() * sizeof(uint32_t) + volume_position_.capacity() * sizeof(Vec3f) +
                   path_begin_.capacity() * sizeof(uint32_t) + path_length_.capacity() * sizeof(uint16_t);
    for (const auto& c : chunk_vertices_) bytes += c.capacity() * sizeof(Vertex);
    return bytes;
}

namespace {

// Whether light vertex y_j is stored as a photon (merging needs a non-Dirac surface, or a medium).
template <class Vertex>
bool is_photon(const Vertex& y, size_t j, int max_bounces, const VcmEstimators& e) {
    const bool kept = y.kind == VertexKind::Medium ? e.pp3d || e.pb2d || e.bb1d : e.surf;
    return j >= 1 && merges_at(y.kind) && kept && y.connectible() && int(j) <= max_bounces;
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
size_t Vcm<T>::photon_beam_paths(size_t light_paths) const {
    return std::min<size_t>(light_paths, options_.photon_beams > 0 ? size_t(options_.photon_beams) : kDefaultPhotonBeamPaths);
}

template <class T>
MergeMis Vcm<T>::merge_mis(size_t light_paths, double r, double r_beam) const {
    if (r_beam < 0) r_beam = r;
    MergeMis vm;
    vm.merging = estimators_.merging();
    vm.connections = estimators_.bpt;
    const double pi = faults_.no_pi_in_kernel ? 1.0 : kPi;
    const double disc = double(light_paths) * pi * r * r;
    vm.eta = estimators_.surf ? disc : 0.0;
    vm.eta_volume = !estimators_.pp3d ? 0.0 : faults_.volume_kernel_as_disc ? disc : double(light_paths) * 4.0 / 3.0 * pi * r * r * r;
    vm.eta_beam2d = estimators_.pb2d ? double(light_paths) * pi * r_beam * r_beam : 0.0;
    vm.eta_beam1d = estimators_.bb1d ? double(photon_beam_paths(light_paths)) * 2 * r_beam : 0.0;
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
    light_per_chunk_ = per_chunk;
    const bool photon_beams = vm.eta_beam1d > 0;
    const size_t beam_paths = photon_beam_paths(paths);
    chunk_beams_.resize(photon_beams ? chunks : 0);
    std::atomic<uint64_t> rays{0};
    // The light subpaths, chunk by chunk, and how many merge vertices each chunk has.
    tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
        const uint64_t rays_before = Scene::rays_traced_by_this_thread();
        std::vector<Vertex>& path = subpaths_.local().second;  // keeps its capacity from pass to pass
        BeamScratch& scratch = beam_scratch_.local();
        std::vector<Vertex>& vertices = chunk_vertices_[c];
        vertices.clear();
        if (photon_beams) chunk_beams_[c].clear();
        size_t photons = 0;
        const MisRules rules(bdpt_.power_heuristic(), &vm);
        for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
            // Light path j is pixel j's, from bdpt's stream: the same path bdpt would connect.
            Sampler sampler(ctx.seed, Bdpt<T>::sample_stream(j, 1), pass, ctx.sampler);
            bdpt_.light_subpath(ctx, sampler, wl, path, &vm, hero, -1, photon_beams ? &scratch.beams : nullptr);
            path_begin_[j] = uint32_t(vertices.size());
            path_length_[j] = uint16_t(path.size());
            for (size_t v = 1; v < path.size(); ++v) photons += is_photon(path[v], v, max_bounces, estimators_);
            vertices.insert(vertices.end(), path.begin(), path.end());
            if (photon_beams && j < beam_paths)
                for (const SubpathBeam<T>& b : scratch.beams) {
                    // The running quantity of a vertex on the beam reads only the vertices before it.
                    scratch.camera.assign(path.begin(), path.begin() + b.from + 1);
                    scratch.camera.emplace_back();
                    set_running_mis(scratch.camera.data(), b.from + 2, /*light_side=*/true, rules);
                    chunk_beams_[c].push_back({b, uint32_t(j), float(scratch.camera.back().mis_running)});
                }
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
    light_beams_.clear();
    for (const std::vector<LightBeam>& beams : chunk_beams_) light_beams_.insert(light_beams_.end(), beams.begin(), beams.end());
    return rays.load();
}

template <class T>
void Vcm<T>::place_photons(size_t paths, bool media, float r) {
    const int max_bounces = bdpt_.max_bounces();
    const size_t per_chunk = light_per_chunk_, chunks = chunk_vertices_.size();
    // Calls f(k, y, v) for every merge vertex y[v] of the iteration, k its index in path order.
    const auto for_each_photon = [&](auto&& f) {
        tbb::parallel_for(size_t(0), chunks, [&](size_t c) {
            size_t k = chunk_photons_[c];
            const std::vector<Vertex>& vertices = chunk_vertices_[c];
            for (size_t j = c * per_chunk; j < std::min(paths, (c + 1) * per_chunk); ++j) {
                const Vertex* y = vertices.data() + path_begin_[j];
                for (size_t v = 1; v < path_length_[j]; ++v)
                    if (is_photon(y[v], v, max_bounces, estimators_)) f(k++, y, int(v));
            }
        });
    };
    // Their positions first, the grid on them, and then each merge vertex made once, in its slot
    // of the grid's cell order.
    photon_positions_.resize(photons_.size());
    for_each_photon([&](size_t k, const Vertex* y, int v) { photon_positions_[k] = y[v].p; });
    const std::vector<uint32_t>& place = grid_.build_placed(Positions::of(photon_positions_), r);
    for_each_photon([&](size_t k, const Vertex* y, int v) {
        if (media) photon_r_[place[k]] = y[v].r;
        photons_[place[k]] = merge_vertex(y, v);
    });
}

template <class T>
float Vcm<T>::merge_weight(const MergeVertex<T>& photon, float pdf_to_light, float pdf_to_camera, const std::vector<Vertex>& camera,
                           int t, const MergeMis& vm, float camera_prev_g, double own_eta) const {
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
    // (bb1d's density at z: the angle between the camera's edge and the photon's)
    const float sin_z = z.kind == VertexKind::Medium ? length(cross(z.dir, photon.wi)) : 0.0f;
    const double camera_sum = camera_side_sum(camera.data(), t - 1, z.pdf_fwd, photon.pdf_fwd, psi, true, camera_prev_rev, rules, sin_z);
    // The connection (s - 1, t) is the reference, 1, where it exists.
    const double reference = vm.connections && !photon.prev_delta ? 1.0 : 0.0;
    if (own_eta < 0) own_eta = z.kind == VertexKind::Medium ? vm.eta_volume : vm.eta;
    const double own = rules.h((faults_.merge_weight_without_light_pdf ? 1.0 : psi) * own_eta);
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
                                  const MergeMis& vm, double own_eta) const {
    // As merge_weight, by Veach's ratio walk over both subpaths.
    const Vertex& z = camera[size_t(t - 1)];
    const Vertex& photon = y[s - 1];
    // z sampling the photon's direction, and the camera's from the photon's.
    const MergeScatter m = merge_scatter(scene, z, merge_vertex(y, s - 1).wi);
    const float light_prev_rev = m.pdf_to_light * reverse_density_factor(photon, y[s - 2]);
    const float camera_prev_rev = m.pdf_to_camera * reverse_density_factor(z, camera[size_t(t - 2)]);
    const Vec3f photon_wi = merge_vertex(y, s - 1).wi;
    const MisVertex zm{z.pdf_fwd,   photon.pdf_fwd, false, false, z.kind, z.sigma_mis,
                       z.kind == VertexKind::Medium ? length(cross(z.dir, photon_wi)) : 0.0f};
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
    if (own_eta < 0) own_eta = z.kind == VertexKind::Medium ? vm.eta_volume : vm.eta;
    double own = (faults_.merge_weight_without_light_pdf ? 1.0 : double(photon.pdf_fwd)) * own_eta;
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
    }, [&](uint32_t k) { prefetch_item(photons_[k]); });
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
void Vcm<T>::build_volume_tree(float r) {
    volume_index_.clear();
    volume_position_.clear();
    for (size_t k = 0; k < photons_.size(); ++k)
        if (photons_[k].in_medium()) volume_index_.push_back(uint32_t(k)), volume_position_.push_back(photons_[k].p);
    const Positions centres = Positions::of(volume_position_);
    volume_tree_.build(centres, std::vector<float>(volume_position_.size(), r));
}

template <class T>
const PathVertex<T>* Vcm<T>::light_path(uint32_t j) const {
    return chunk_vertices_[j / light_per_chunk_].data() + path_begin_[j];
}

template <class T>
MergeVertex<T> Vcm<T>::photon_on_beam(const Scene& scene, const Vertex* y, const SubpathBeam<T>& b, float along, float mis_running,
                                      Vertex& x) const {
    const Vertex& from = y[b.from];
    place_on_beam(scene, b, along, from, x);
    MergeVertex<T> m;
    m.p = x.p;
    m.medium = int16_t(b.medium);
    m.wi = -b.d;
    m.vertex = uint16_t(b.from + 1);
    m.dispersed = b.dispersed;
    m.pdf_fwd = x.pdf_fwd;
    m.prev_pdf_fwd = from.pdf_fwd;
    m.prev_g = reverse_density_factor(x, from);
    m.mis_running = mis_running;
    m.prev_delta = from.delta;
    return m;
}

template <class T>
float Vcm<T>::beam_beam_weight(const Scene& scene, const Vertex* y, const SubpathBeam<T>& light_beam, float along_light,
                               const std::vector<Vertex>& camera, const SubpathBeam<T>& camera_beam, float along_camera, const MergeMis& vm,
                               bool oracle) const {
    const MisRules rules(bdpt_.power_heuristic(), &vm);
    std::vector<Vertex> z(camera.begin(), camera.begin() + camera_beam.from + 1), l(y, y + light_beam.from + 1);
    z.emplace_back(), l.emplace_back();
    place_on_beam(scene, camera_beam, along_camera, z[size_t(camera_beam.from)], z.back());
    place_on_beam(scene, light_beam, along_light, l[size_t(light_beam.from)], l.back());
    const int t = camera_beam.from + 2, s = light_beam.from + 2;
    set_running_mis(z.data(), t, /*light_side=*/false, rules);
    set_running_mis(l.data(), s, /*light_side=*/true, rules);
    const double sin = length(cross(camera_beam.d, light_beam.d)), sigma = z.back().sigma_mis;
    const double own_eta = vm.eta_beam1d * sin / (sigma * sigma);
    if (oracle) return merge_weight_oracle(scene, l.data(), s, z, t, vm, own_eta);
    const MergeVertex<T> photon = merge_vertex(l.data(), s - 1);
    const MergeScatter m = merge_scatter(scene, z.back(), photon.wi);
    return merge_weight(photon, m.pdf_to_light, m.pdf_to_camera, z, t, vm, -1, own_eta);
}

template <class T>
ColourOf<T> Vcm<T>::beam_beam(const Scene& scene, const std::vector<Vertex>& camera, const SubpathBeam<T>& beam, float r,
                              const MergeMis& vm, const Wavelengths& wl, std::vector<Vertex>& scratch) const {
    const int t = beam.from + 2;  // the camera's vertex on the beam stands at index from + 1
    const int max_bounces = bdpt_.max_bounces();
    if (t - 1 > max_bounces || beam_tree_.size() == 0) return Colour(0.0f);  // (a light beam's vertex has s >= 2)
    Colour sigma_t;
    const Medium& medium = scene.medium(beam.medium);
    const auto view = medium_view(medium, wl);
    if (!view.constant_extinction(sigma_t)) return Colour(0.0f);  // refused before the render (render_job.cpp)
    scratch.assign(camera.begin(), camera.begin() + beam.from + 1);
    scratch.emplace_back();
    set_running_mis(scratch.data(), t, /*light_side=*/false, MisRules(bdpt_.power_heuristic(), &vm));
    Vertex& xc = scratch.back();
    const Vertex& from = scratch[size_t(beam.from)];
    Vertex xl;
    MergeSum<T> sum;
    beam_tree_.for_each_near(beam.o, beam.d, beam.length, [&](const BeamTree::Piece& piece) {
        const LightBeam& lb = light_beams_[piece.segment];
        const SubpathBeam<T>& b = lb.beam;
        if (b.medium != beam.medium) return;
        const int depth = b.from + 2 + t - 3;
        if (depth > max_bounces || (options_.only_length >= 0 && depth != options_.only_length)) return;
        // The closest points of the two lines, within both beams and r of each other.
        const Vec3f n = cross(beam.d, b.d);
        const float sin2 = dot(n, n);
        if (!(sin2 > 1e-12f)) return;  // parallel: the estimate's 1 / sin is unbounded, its density 0
        const Vec3f w = b.o - beam.o;
        const float dist = std::abs(dot(w, n)) / std::sqrt(sin2);
        if (!(dist < r)) return;
        const float along_c = dot(cross(w, b.d), n) / sin2, along_l = dot(cross(w, beam.d), n) / sin2;
        if (!(along_c >= 0 && along_c < beam.length && along_l >= piece.t0 && along_l < piece.t1)) return;
        place_on_beam(scene, beam, along_c, from, xc);
        const MergeVertex<T> photon = photon_on_beam(scene, light_path(lb.path), b, along_l, lb.mis_running, xl);
        const MergeScatter m = merge_scatter(scene, xc, photon.wi);
        if (is_black(m.f)) return;
        const float sin = std::sqrt(sin2);
        const double sigma = xc.sigma_mis;
        const float weight = merge_weight(photon, m.pdf_to_light, m.pdf_to_camera, scratch, t, vm, reverse_density_factor(xc, from),
                                          vm.eta_beam1d * double(sin) / (sigma * sigma));
        // Both beams' transmittances to the closest points over the probabilities that their walks got there.
        const Colour Tc = homogeneous_transmittance(sigma_t, along_c), Tl = homogeneous_transmittance(sigma_t, along_l);
        const float qc = max_component(Tc), ql = max_component(Tl);
        if (!(qc > 0 && ql > 0)) return;
        const Colour ratio = Tc / Colour(qc) * Tl / Colour(ql);
        Colour c = beam.beta * b.beta * ratio * view.coefficients(xc.p).sigma_s * Colour(m.f.x) * weight;
        if (!faults_.beam_beam_without_sine) c /= sin;
        c /= path_density_of(b.r * beam.r * ratio, b.dispersed || beam.dispersed);
        sum.add(c, b.dispersed);
    });
    Wavelengths camera_wl = wl;
    if (beam.dispersed) camera_wl.terminate_secondary();
    const Colour m = sum.total(camera_wl) / float(vm.eta_beam1d);  // the kernel 1 / (2r), over N light paths
    return beam.dispersed ? hero_only(m) : m;
}

template <class T>
void Vcm<T>::place_on_beam(const Scene& scene, const SubpathBeam<T>& beam, float along, const Vertex& from, Vertex& x) const {
    const Medium& medium = scene.medium(beam.medium);
    x.kind = VertexKind::Medium;
    x.medium = beam.medium;
    x.dir = -beam.d;
    x.dispersed = beam.dispersed;
    x.p = beam.o + beam.d * along;
    x.T_in = beam.mis_T * mis_transmittance(medium, beam.o, beam.d, along);
    x.sigma_mis = mis_extinction(medium, x.p);
    // (from a light at infinity the density of its entry disk: random_walk's first vertex's)
    x.pdf_fwd = (beam.from_infinity ? beam.pdfW : to_area_density(beam.pdfW, from, x)) * x.distance_factor(x.T_in);
}

template <class T>
float Vcm<T>::beam_merge_weight(const Scene& scene, const Vertex* y, int s, const std::vector<Vertex>& camera, const SubpathBeam<T>& beam,
                                float along, const MergeMis& vm, bool oracle) const {
    std::vector<Vertex> z(camera.begin(), camera.begin() + beam.from + 1);
    z.emplace_back();
    place_on_beam(scene, beam, along, z[size_t(beam.from)], z.back());
    const int t = beam.from + 2;
    set_running_mis(z.data(), t, /*light_side=*/false, MisRules(bdpt_.power_heuristic(), &vm));
    const double own_eta = vm.eta_beam2d / double(z.back().sigma_mis);
    if (oracle) return merge_weight_oracle(scene, y, s, z, t, vm, own_eta);
    const MergeVertex<T> photon = merge_vertex(y, s - 1);
    const MergeScatter m = merge_scatter(scene, z.back(), photon.wi);
    return merge_weight(photon, m.pdf_to_light, m.pdf_to_camera, z, t, vm, -1, own_eta);
}

template <class T>
ColourOf<T> Vcm<T>::beam_merge(const Scene& scene, const std::vector<Vertex>& camera, const SubpathBeam<T>& beam, float r,
                               const MergeMis& vm, const Wavelengths& wl, std::vector<Vertex>& scratch) const {
    const int t = beam.from + 2;  // the merge vertex stands at camera index from + 1
    const int max_bounces = bdpt_.max_bounces();
    if (t - 1 > max_bounces || volume_tree_.size() == 0) return Colour(0.0f);  // (a photon has s >= 2)
    Colour sigma_t;
    const Medium& medium = scene.medium(beam.medium);
    if (!medium_view(medium, wl).constant_extinction(sigma_t)) return Colour(0.0f);  // refused before the render (render_job.cpp)
    scratch.assign(camera.begin(), camera.begin() + beam.from + 1);
    scratch.emplace_back();
    const MisRules rules(bdpt_.power_heuristic(), &vm);
    // Its running quantity reads only the vertices before it: the same at every point of the beam.
    set_running_mis(scratch.data(), t, /*light_side=*/false, rules);
    Vertex& x = scratch.back();
    const Vertex& from = scratch[size_t(beam.from)];
    MergeSum<T> sum;
    volume_tree_.for_each_along(beam.o, beam.d, beam.length, [&](uint32_t i, float along) {
        const uint32_t k = volume_index_[i];
        const MergeVertex<T>& ph = photons_[k];
        if (ph.medium != beam.medium) return;
        const int depth = int(ph.vertex) + 1 + t - 3;
        if (depth > max_bounces || (options_.only_length >= 0 && depth != options_.only_length)) return;
        place_on_beam(scene, beam, along, from, x);
        const MergeScatter m = merge_scatter(scene, x, ph.wi);
        if (is_black(m.f)) return;
        const float w = merge_weight(ph, m.pdf_to_light, m.pdf_to_camera, scratch, t, vm, reverse_density_factor(x, from),
                                     vm.eta_beam2d / double(x.sigma_mis));
        // The beam's transmittance to the photon over the probability that the walk got there
        // (the hero channel's T; the channels' ratio goes to r, as free-flight sampling does).
        const Colour Tr = homogeneous_transmittance(sigma_t, along);
        const float q = max_component(Tr);
        if (!(q > 0)) return;
        const Colour ratio = Tr / Colour(q);
        Colour c = beam.beta * (faults_.beam_without_transmittance ? Colour(1.0f / q) : ratio) * Colour(m.f.x) * ph.power * w;
        c /= path_density_of(photon_r_[k] * beam.r * ratio, ph.dispersed || beam.dispersed);
        sum.add(c, ph.dispersed);
    });
    Wavelengths camera_wl = wl;
    if (beam.dispersed) camera_wl.terminate_secondary();
    const double kernel = faults_.beam_kernel_as_ball ? vm.eta_beam2d * 4.0 / 3.0 * double(r) : vm.eta_beam2d;
    const Colour m = sum.total(camera_wl) / float(kernel);
    return beam.dispersed ? hero_only(m) : m;
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
        // The beams' radius shrinks as the others' (--beam-radius sets its first value; by default a
        // quarter of the points': measured on the volumetric caustic, docs/measurements.md).
        const float r_beam = options_.beam_radius > 0 ? float(double(options_.beam_radius) * r / r1) : r / kBeamRadiusDivisor;
        const MergeMis vm = merge_mis(pixels, r, r_beam);
        // In media, one hero channel for every subpath of the iteration (see vcm.hpp).
        const int hero = Bdpt<T>::sample_hero(ctx, pixels, pass, wl);
        rays += trace_light_paths(ctx, pass, wl, vm, hero);
        if (vm.merging) place_photons(pixels, ctx.scene.has_media(), r);
        if (vm.eta_beam2d > 0) build_volume_tree(r_beam);
        if (vm.eta_beam1d > 0) {
            std::vector<BeamTree::Segment> segments(light_beams_.size());
            for (size_t i = 0; i < segments.size(); ++i)
                segments[i] = {light_beams_[i].beam.o, light_beams_[i].beam.d, light_beams_[i].beam.length};
            // Pieces of 4 r: a query's boxes hold little more than the cylinders around the pieces.
            beam_tree_.build(segments, r_beam, 4 * r_beam);
        }
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
            BeamScratch& scratch = beam_scratch_.local();
            std::vector<SubpathBeam<T>>* beams = vm.eta_beam2d > 0 || vm.eta_beam1d > 0 ? &scratch.beams : nullptr;
            for (int c = range.begin(); c != range.end(); ++c) {
                const uint64_t rays_before = Scene::rays_traced_by_this_thread();
                uint64_t chunk_invalid = 0;
                SplatList& splats = pass_.chunk(c);
                for (size_t pixel = size_t(c) * per_chunk; pixel < std::min(pixels, size_t(c + 1) * per_chunk); ++pixel) {
                    Sampler camera_sampler(ctx.seed, pixel, pass, ctx.sampler);
                    bdpt_.camera_subpath(ctx, pixel, camera_sampler, wl, camera, filtered ? &shift : nullptr, &vm, hero, beams);
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
                            const double own_eta = z.kind == VertexKind::Medium ? vm.eta_volume : vm.eta;
                            if (vm.merging && own_eta > 0 && t >= 2 && merges_at(z.kind) && z.connectible()) {
                                const Colour m = merge(ctx.scene, camera, t, r, vm, wl);
                                if (!is_black(m)) add(m, false, {});
                            }
                        });
                    // pb2d and bb1d: the photons and the photon beams along each piece of the camera
                    // subpath's edges in media.
                    if (beams)
                        for (const SubpathBeam<T>& b : *beams) {
                            if (vm.eta_beam2d > 0)
                                if (const Colour m = beam_merge(ctx.scene, camera, b, r_beam, vm, wl, scratch.camera); !is_black(m)) add(m, false, {});
                            if (vm.eta_beam1d > 0)
                                if (const Colour m = beam_beam(ctx.scene, camera, b, r_beam, vm, wl, scratch.camera); !is_black(m)) add(m, false, {});
                        }
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

const IntegratorInfo& upbp_integrator() {
    static const IntegratorInfo info = [] {
        std::vector<ParamInfo> params = vcm_params();
        params.push_back({"beam_radius", ParamType::Float, "0",
                          "the first radius of pb2d and bb1d, reduced as initial_radius is (0: a quarter of initial_radius's; --beam-radius wins)"});
        params.push_back({"photon_beams", ParamType::Integer, "0",
                          "light paths per iteration whose edges in media are photon beams for bb1d (0: 256, or the pixel count if "
                          "fewer; --photon-beams wins)"});
        params.push_back({"estimators", ParamType::String, "all",
                          "the estimators combined by MIS, of bpt (connections), surf (merging on surfaces), pp3d (points in media), "
                          "pb2d (photon points along camera beams), bb1d (photon beams against camera beams)"});
        IntegratorInfo i{"upbp", {}, "unified points, beams and paths: bdpt's connections, surface merging and the point-point, "
                                     "point-beam and beam-beam estimators in media, combined by MIS (--estimators)",
                         false, true, params,
                         [](IntegratorOptions o) {
                             if (o.estimators.empty()) o.estimators = "all";
                             return make_for_transport<Vcm>(o);
                         },
                         false, true};
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

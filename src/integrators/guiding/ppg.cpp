// Practical path guiding (Müller, Gross and Novák, EGSR 2017): pt-mis whose continuation
// direction is drawn, where the SD-tree (sd_tree.hpp) has learned something, from the one-sample
// mixture of the BSDF (probability a) and the tree's distribution of arriving radiance:
//   p(wo) = a p_bsdf(wo) + (1 - a) p_tree(wo),
// a = --guiding-fraction (1/2, the paper's, by default), or learned per leaf during training
// (BsdfFractionFit in sd_tree.hpp; Müller 2019).
// Both halves stay in the mixture for every direction, so every direction the BSDF reaches stays
// reachable (guiding cannot lose light; it can only move variance). Next-event estimation is
// kept: a light sample is weighed against the mixture's density, the emission the continuation
// finds against light sampling's (balance heuristic, or power with --mis power). A Dirac lobe is
// never guided: it is sampled only through the BSDF half, with probability a times its own.
//
// Training (prepare): iterations of 1, 2, 4, ... samples per pixel with their own random numbers,
// each guided by the tree of the iterations before, record at every non-Dirac vertex the radiance
// its continuation brought back (the light found further on, MIS-weighted, over the throughput to
// the next vertex) over the direction's density, and the light sample's MIS-weighted radiance
// over its density. The tree is then refined (sd_tree.hpp). The image is rendered with the last
// tree, fixed: training samples are not in it (the paper's choice: the final iteration alone).
// Records are added in pixel order, a block of rows at a time, so the tree and the image do not
// depend on the thread count.
//
// --guiding-rr: adjoint-driven Russian roulette and splitting (Vorba and Křivánek 2016). Training
// also learns each leaf's mean outgoing radiance (what its vertices sent back, over the throughput
// that reached them). After a bounce, the path's expected contribution is its throughput times
// the next vertex's leaf radiance; against the pixel's (estimated by the first hit's leaf) it is
// kept within a window of ratio kWindow: roulette below it (survivors divided by their
// probability), splitting into copies above it. Both are unbiased; only the variance changes.
//
// In a scene with media (trace_in_media) ppg follows volpath's walk (media_lighting.hpp, whose
// light sample and BSDF-or-phase sample take a LeafGuide) and guides at points in media too,
// between the phase function and the leaf; --guiding-rr plays only the roulette there.
#include "integrators/guiding/ppg.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstring>
#include <string>
#include <type_traits>

#include "core/sampling.hpp"
#include "integrators/common/camera_ray.hpp"
#include "integrators/common/direct_lighting.hpp"
#include "integrators/common/media_lighting.hpp"
#include "integrators/integrators.hpp"

namespace pathlab {

namespace {

// The training passes' random numbers: apart from the image's (Sampler(seed, pixel, pass)).
constexpr uint64_t kTrainingSeed = 0x9b1de5a7c0ffee11ull;

// The mean over lanes of a / b, lanes where b is 0 left out (a path's radiance over its
// throughput: what arrived at a vertex along its continuation).
template <class C>
float mean_ratio(const C& a, const C& b) {
    constexpr int lanes = std::is_same_v<C, Spectrum4> ? 4 : 3;
    float sum = 0;
    int n = 0;
    for (int i = 0; i < lanes; ++i)
        if (b[i] > 0) sum += a[i] / b[i], ++n;
    return n ? sum / float(n) : 0.0f;
}
template <class C>
float mean_of(const C& c) {
    constexpr int lanes = std::is_same_v<C, Spectrum4> ? 4 : 3;
    float sum = 0;
    for (int i = 0; i < lanes; ++i) sum += c[i];
    return sum / float(lanes);
}

}  // namespace

template <class T>
PathGuiding<T>::PathGuiding(const IntegratorOptions& o, GuidingFaults faults) : options_(o), rules_(o), faults_(faults) {}

template <class T>
std::vector<uint64_t> PathGuiding<T>::iteration_sizes(uint64_t training_spp) {
    std::vector<uint64_t> sizes;
    uint64_t size = 1, left = training_spp;
    while (left > 0) {
        // The last iteration takes the rest when the next doubling would not fit after it.
        const uint64_t take = left < 3 * size ? left : size;
        sizes.push_back(take);
        left -= take;
        size *= 2;
    }
    return sizes;
}

template <class T>
void PathGuiding<T>::prepare(const RenderContext& ctx, const PassProgress& progress) {
    if (prepared_.matches(ctx)) return;
    const auto start = std::chrono::steady_clock::now();
    tree_ = SdTree(ctx.scene.bounds_center(), ctx.scene.bounds_radius(), options_.guiding);
    guided_ = false;
    const std::vector<uint64_t> sizes = iteration_sizes(uint64_t(std::max<int64_t>(0, options_.guiding_spp)));
    uint64_t total = 0, done = 0, first = 0;
    for (uint64_t s : sizes) total += s;
    const int w = ctx.width, h = ctx.height;
    // Rows are traced in parallel a block at a time, and their records added in row order. With
    // several ranks (MPI) each traces every size-th row of a block, and the ranks exchange their
    // rows' records before every rank adds all of them in row order: the same tree everywhere, and
    // the same as one process's, in a share of its time.
    const int block_rows = std::max(1, std::min(h, 65536 / std::max(1, w)));
    const int rank = ctx.ranks ? ctx.ranks->rank : 0, ranks = ctx.ranks && ctx.ranks->all_gather ? ctx.ranks->size : 1;
    std::vector<std::vector<Record>> row_records(static_cast<size_t>(block_rows));
    for (const uint64_t spp : sizes) {
        for (int y0 = 0; y0 < h; y0 += block_rows) {
            const int rows = std::min(block_rows, h - y0);
            tbb::parallel_for(0, rows, [&](int r) {
                std::vector<Record>& out = row_records[size_t(r)];
                out.clear();
                if (r % ranks != rank) return;
                const int y = y0 + r;
                for (int x = 0; x < w; ++x) {
                    const size_t pixel = size_t(y) * size_t(w) + size_t(x);
                    for (uint64_t k = 0; k < spp; ++k) {
                        Sampler sampler(ctx.seed ^ kTrainingSeed, pixel, first + k, ctx.sampler);
                        const Vec2f jitter = sampler.next2d();
                        const Ray ray = camera_ray(ctx.camera, float(x) + jitter.x, float(y) + jitter.y, sampler);
                        Wl wl = T::camera_wavelengths(sampler);
                        trace(ctx.scene, ray, sampler, wl, &out);
                    }
                }
            });
            if (ranks > 1) exchange_rows(*ctx.ranks, row_records, rows);
            for (int r = 0; r < rows; ++r)
                for (const Record& rec : row_records[size_t(r)]) switch (rec.kind) {
                        case Record::kIncoming: tree_.record(rec.p, rec.direction, rec.value); break;
                        case Record::kOutgoing: tree_.record_outgoing(rec.p, rec.value); break;
                        case Record::kFraction: tree_.record_fraction_gradient(rec.p, rec.value); break;
                    }
            done += spp * uint64_t(rows);
            if (progress) progress(double(done) / double(total * uint64_t(h)));
        }
        tree_.refine(spp);
        guided_ = true;
        first += spp;
    }
    training_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    prepared_.set(ctx);
}

template <class T>
void PathGuiding<T>::exchange_rows(const PrepareRanks& ranks, std::vector<std::vector<Record>>& row_records, int rows) {
    // This rank's rows (every size-th from its rank on), each its record count and its records.
    static_assert(std::is_trivially_copyable_v<Record>);
    std::string mine;
    for (int r = ranks.rank; r < rows; r += ranks.size) {
        const std::vector<Record>& records = row_records[size_t(r)];
        const uint64_t n = records.size();
        mine.append(reinterpret_cast<const char*>(&n), sizeof n).append(reinterpret_cast<const char*>(records.data()), n * sizeof(Record));
    }
    const std::vector<std::string> all = ranks.all_gather(mine);
    for (int k = 0; k < ranks.size; ++k) {
        const std::string& bytes = all[size_t(k)];
        size_t at = 0;
        for (int r = k; r < rows; r += ranks.size) {
            uint64_t n = 0;
            std::memcpy(&n, bytes.data() + at, sizeof n);
            at += sizeof n;
            std::vector<Record>& records = row_records[size_t(r)];
            records.resize(size_t(n));
            std::memcpy(records.data(), bytes.data() + at, size_t(n) * sizeof(Record));
            at += size_t(n) * sizeof(Record);
        }
    }
}

template <class T>
ColourOf<T> PathGuiding<T>::radiance(const Scene& scene, const Ray& ray, Sampler& sampler, Wl& wl) const {
    return trace(scene, ray, sampler, wl, nullptr);
}

template <class T>
ColourOf<T> PathGuiding<T>::trace(const Scene& scene, const Ray& camera_ray, Sampler& sampler, Wl& wl, std::vector<Record>* records) const {
    if (scene.has_media()) return trace_in_media(scene, camera_ray, sampler, wl, records);
    const bool seen_directly = !options_.hide_emitters;
    Intersection hit;
    if (!scene.intersect(camera_ray, hit)) return seen_directly ? escaped_radiance(scene, camera_ray.d, wl) : Colour(0.0f);
    const Colour emitted = seen_directly ? emitted_radiance(scene, hit, -camera_ray.d, wl) : Colour(0.0f);
    // Adjoint-driven roulette's estimate of the pixel: the radiance the first hit's leaf sends back.
    const float pixel = guided_ && options_.guiding_rr && !records ? tree_.leaf(hit.p).outgoing : 0.0f;
    if (!records) return emitted + walk(scene, hit, camera_ray.d, Colour(1.0f), 0, sampler, wl, nullptr, nullptr, pixel, 1);
    std::array<PathVertex, kRecordedVertices> vertices;
    return emitted + walk(scene, hit, camera_ray.d, Colour(1.0f), 0, sampler, wl, records, vertices.data(), pixel, 1);
}

template <class T>
ColourOf<T> PathGuiding<T>::walk(const Scene& scene, Intersection hit, Vec3f dir, Colour beta, int first_bounce, Sampler& sampler, Wl& wl,
                                 std::vector<Record>* records, PathVertex* vertices, float pixel, int copies) const {
    Colour L(0.0f);
    int n = 0;
    const bool power = rules_.power_mis();
    const GuidingLeaf* next_leaf = nullptr;  // the leaf of `hit`, when the roulette has looked it up
    const bool learn_fraction = records && options_.guiding_fraction == kLearnedGuidingFraction;
    for (int bounces = first_bounce; rules_.may_bounce(bounces); ++bounces) {
        const ShadingPoint sp = make_shading_point(scene, hit, dir);
        if (sp.material->is_black()) break;
        const GuidingLeaf* leaf = guided_ ? (next_leaf ? next_leaf : &tree_.leaf(sp.p)) : nullptr;
        const LeafGuide g = leaf_guide(leaf, (sp.material->lobes() & (kLobeDiffuse | kLobeGlossy)) != 0);
        // Light sampling weighed against the continuation's density (the light's direction is local here).
        const auto light_mis_pdf = [&](const Vec3f& w, float pdf_bsdf) { return g.mis_pdf(sp.frame.to_world(w), pdf_bsdf); };
        PathVertex* v = records && n < kRecordedVertices ? &vertices[n++] : nullptr;
        if (v) *v = {sp.p, Vec3f(0.0f), 0.0f, false, L, beta, L, beta};
        LightSampleSeen<Wl> light;
        L += beta * estimate_light_sample(scene, sp, sampler, /*mis=*/true, wl, power, light_mis_pdf, records ? &light : nullptr, bounces == 0);
        if (records && light.found) records->push_back({sp.p, light.wi, mean_of(light.Li), Record::kIncoming});

        // The continuation: the BSDF's sample (always without guiding), or the tree's.
        const Vec2f u = sampler.next2d();
        const auto c = sample_bsdf_or_guide(sp, u, g.on && !(sampler.next1d() < g.a), g, wl);
        if (!c || !(c->pdf > 0)) break;
        const BsdfSample* s = &c->s;
        const Colour& f = c->f;
        const float pdf = c->pdf;
        const Colour step = f * (std::abs(s->wo.z) / pdf);
        const Vec3f wo_world = c->wo_world;
        if (v && !s->delta) {
            v->direction = wo_world, v->pdf = pdf, v->guided_record = true, v->L_before = L, v->beta_after = beta * step;
            if (g.on && learn_fraction) v->a = g.a, v->f_cos = mean_of(f) * std::abs(s->wo.z), v->pdf_bsdf = s->pdfW, v->pdf_tree = g.pdf(wo_world);
        }
        const EmitterHit found = trace_to_emitter(scene, sp.spawn(s->wo), sp.p, sp.frame.n, bounces == 0);
        if (!is_black(found.Le)) {
            const float weight = s->delta ? 1.0f : mis_heuristic(power, pdf, found.pdf_light);
            const int light_index = found.hit ? found.isect.light : scene.environment_light();
            L += beta * step * light_colour(scene, light_index, found.Le, wl) * weight;
        }
        if (!found.hit || !rules_.may_bounce(bounces + 1)) break;
        beta *= step;
        // Adjoint-driven roulette and splitting (Vorba and Křivánek 2016) where the next vertex's
        // leaf knows its radiance, else the throughput's roulette.
        next_leaf = pixel > 0 ? &tree_.leaf(found.isect.p) : nullptr;
        const float next = next_leaf ? next_leaf->outgoing : 0.0f;
        if (next > 0) {
            const auto [lower, upper] = weight_window(pixel, next);
            const float b = mean_of(beta);
            if (b < lower) {
                const float q = std::max(b / lower, 1e-3f);
                if (sampler.next1d() >= q) break;
                if (!faults_.drop_roulette_weight) beta /= q;
            } else if (b > upper && !T::spectral && copies < kMaxCopies) {
                const int split = std::min({int(std::ceil(b / upper)), kMaxSplit, kMaxCopies / copies});
                beta /= float(split);
                for (int i = 1; i < split; ++i)
                    L += walk(scene, found.isect, wo_world, beta, bounces + 1, sampler, wl, nullptr, nullptr, pixel, copies * split);
                copies *= split;
            }
        } else if (!rules_.survive_roulette(bounces + 1, beta, sampler)) {
            break;
        }
        hit = found.isect;
        dir = wo_world;
    }
    if (records) add_records(vertices, n, L, options_.guiding_rr, *records);
    return L;
}

template <class T>
std::pair<float, float> PathGuiding<T>::weight_window(float pixel, float next) {
    // The throughput at which the path's expected contribution is the pixel's, and a window of
    // ratio kWindow around it.
    const float centre = pixel / next, lower = 2.0f * centre / (1.0f + kWindow);
    return {lower, kWindow * lower};
}

template <class T>
LeafGuide PathGuiding<T>::leaf_guide(const GuidingLeaf* leaf, bool guidable) const {
    const bool on = leaf && leaf->usable && guidable;
    return {leaf, on ? guiding_bsdf_fraction(options_, *leaf) : 1.0f, on, faults_.drop_guide_pdf_in_mis};
}

template <class T>
void PathGuiding<T>::add_records(const PathVertex* vertices, int n, const Colour& L, bool outgoing, std::vector<Record>& out) {
    // What arrived at each recorded vertex along its continuation: all the path gathered after
    // it, over the throughput to the next vertex; recorded over the direction's density. And what
    // the vertex sent back: all the path gathered from it on, over the throughput that reached it
    // (for adjoint-driven roulette only: `outgoing`).
    for (int i = 0; i < n; ++i) {
        const PathVertex& v = vertices[i];
        if (v.guided_record) {
            const float Li = mean_ratio(L - v.L_before, v.beta_after);
            out.push_back({v.p, v.direction, Li / v.pdf, Record::kIncoming});
            if (v.a < 1) {  // the fraction's gradient (BsdfFractionFit), where the vertex was guided
                const float gradient = BsdfFractionFit::gradient(v.f_cos * Li / v.pdf, v.pdf, v.pdf_bsdf, v.pdf_tree, v.a);
                out.push_back({v.p, v.direction, gradient, Record::kFraction});
            }
        }
        if (outgoing) out.push_back({v.p, Vec3f(0.0f), mean_ratio(L - v.L_start, v.beta_start), Record::kOutgoing});
    }
}

template <class T>
ColourOf<T> PathGuiding<T>::trace_in_media(const Scene& scene, const Ray& camera_ray, Sampler& sampler, Wl& wl,
                                           std::vector<Record>* records) const {
    // volpath's loop (path/volpath.cpp) with each vertex's leaf guiding its continuation (at a
    // surface as above; in a medium between the phase function and the leaf), through
    // media_lighting.hpp's Guide. The throughput that the records divide by is beta / density.
    MediumState<T> st{sampler, wl};
    Colour seg(1.0f);
    MediumWalk w = walk_media(scene, camera_ray, scene.camera_medium(), st, seg);
    Colour beta = seg, L(0.0f);
    const bool seen_directly = !options_.hide_emitters;
    if (w.kind == MediumWalk::kEscaped) return seen_directly ? beta * escaped_radiance(scene, w.dir, wl) / st.density() : Colour(0.0f);
    if (w.kind == MediumWalk::kSurface && seen_directly) L = beta * emitted_radiance(scene, w.isect, -w.dir, wl) / st.density();
    std::array<PathVertex, kRecordedVertices> vertices;
    int n = 0;
    const bool power = rules_.power_mis();
    const bool learn_fraction = records && options_.guiding_fraction == kLearnedGuidingFraction;
    const auto leaf_at = [&](const MediumWalk& m) -> const GuidingLeaf& { return tree_.leaf(m.kind == MediumWalk::kSurface ? m.isect.p : m.p); };
    // Adjoint-driven roulette's estimate of the pixel: the radiance the first vertex's leaf sends
    // back; next_leaf: the leaf of w, when the roulette has looked it up.
    const GuidingLeaf* next_leaf = guided_ && options_.guiding_rr && !records && w.kind != MediumWalk::kLost ? &leaf_at(w) : nullptr;
    const float pixel = next_leaf ? next_leaf->outgoing : 0.0f;
    for (int bounces = 0; w.kind != MediumWalk::kLost && rules_.may_bounce(bounces); ++bounces) {
        ScatterVertex v;
        v.medium = w.medium;
        ShadingPoint sp;
        bool guidable = true;
        if (w.kind == MediumWalk::kSurface) {
            sp = make_shading_point(scene, w.isect, w.dir);
            if (sp.material->is_black()) break;
            v.sp = &sp, v.hit = &w, v.p = sp.p;
            guidable = (sp.material->lobes() & (kLobeDiffuse | kLobeGlossy)) != 0;
        } else {
            v.p = w.p;
            v.wi = -w.dir / length(w.dir);
            v.phase = &medium_phase(scene.medium(w.medium));
        }
        const LeafGuide g = leaf_guide(guided_ ? (next_leaf ? next_leaf : &tree_.leaf(v.p)) : nullptr, guidable);
        PathVertex* pv = records && n < kRecordedVertices ? &vertices[size_t(n++)] : nullptr;
        const Colour throughput = beta / st.density();
        if (pv) *pv = {v.p, Vec3f(0.0f), 0.0f, false, L, throughput, L, throughput};
        LightSampleSeen<Wl> light;
        L += beta * estimate_light(scene, v, sampler, st, /*mis=*/true, wl, power, g, records ? &light : nullptr, bounces == 0) / st.density();
        if (records && light.found) records->push_back({v.p, light.wi, mean_of(light.Li), Record::kIncoming});
        const Colour L_before = L;
        const ScatterSample<T> s = sample_scatter(scene, v, sampler, st, /*mis=*/true, wl, power, nullptr, g, bounces == 0);
        if (!s.sampled) break;
        L += beta * s.next_seg * s.found / st.density();
        const Colour beta_next = beta * s.next_seg * s.weight;
        if (pv && !s.delta) {
            const Vec3f wo = normalize(s.ray.d);
            pv->direction = wo, pv->pdf = s.pdf, pv->guided_record = true, pv->L_before = L_before, pv->beta_after = beta_next / st.density();
            if (g.on && learn_fraction) pv->a = g.a, pv->f_cos = mean_of(s.weight) * s.pdf, pv->pdf_bsdf = s.pdf_scatter, pv->pdf_tree = g.pdf(wo);
        }
        if (!rules_.may_bounce(bounces + 1) || s.next.kind == MediumWalk::kEscaped || s.next.kind == MediumWalk::kLost) break;
        beta = beta_next;
        w = s.next;
        // Adjoint-driven roulette on beta / density where the next vertex's leaf knows its
        // radiance (no splitting in media: a copy would need its own media state), else volpath's.
        next_leaf = pixel > 0 ? &leaf_at(w) : nullptr;
        const float next = next_leaf ? next_leaf->outgoing : 0.0f;
        Colour weight = beta / st.density();
        if (next > 0) {
            const float b = mean_of(weight), lower = weight_window(pixel, next).first;
            if (b < lower) {
                const float q = std::max(b / lower, 1e-3f);
                if (sampler.next1d() >= q) break;
                if (!faults_.drop_roulette_weight) beta /= q;
            }
        } else {
            if (!rules_.survive_roulette(bounces + 1, weight, sampler)) break;
            beta = weight * st.density();
        }
    }
    if (records) add_records(vertices.data(), n, L, options_.guiding_rr, *records);
    return L;
}

template <class T>
std::vector<IntegratorStatistic> PathGuiding<T>::statistics() const {
    std::vector<IntegratorStatistic> stats{{"guiding_training_seconds", training_seconds_},
                                           {"guiding_leaves", double(tree_.leaf_count())},
                                           {"guiding_tree_mib", double(tree_.memory_bytes()) / (1024.0 * 1024.0)}};
    if (options_.guiding_fraction == kLearnedGuidingFraction) {  // the learned BSDF fractions' mean over the leaves that guide
        double sum = 0;
        size_t n = 0;
        for (const GuidingLeaf& l : tree_.leaves())
            if (l.usable) sum += l.fraction.fraction(), ++n;
        stats.push_back({"guiding_fraction_mean", n ? sum / double(n) : 0.5});
    }
    return stats;
}

template class PathGuiding<RgbTransport>;
template class PathGuiding<SpectralTransport>;

namespace {

std::vector<ParamInfo> ppg_params() {
    std::vector<ParamInfo> p = path_params();
    p.push_back({"training_spp", ParamType::Integer, "31",
                 "samples per pixel of the SD-tree's training, in iterations of 1, 2, 4, ... (not in the image; --guiding-spp wins)", ""});
    p.push_back({"guiding_rr", ParamType::Boolean, "false", "adjoint-driven Russian roulette and splitting (or --guiding-rr)", ""});
    p.push_back({"guiding_fraction", ParamType::FloatOrString, "0.5",
                 "the probability of sampling the BSDF rather than the SD-tree where it guides: a number in (0, 1] or 'learned' (per leaf, "
                 "Müller 2019; or --guiding-fraction)",
                 ""});
    p.push_back({"guiding", ParamType::String, "sd-tree",
                 "what each spatial leaf learns of the arriving light: sd-tree (a quadtree over directions) or vmm (von Mises-Fisher lobes "
                 "fitted by on-line EM, Vorba et al. 2014; or --guiding)",
                 ""});
    return p;
}

}  // namespace

const IntegratorInfo& ppg_integrator() {
    static const IntegratorInfo info = [] {
        IntegratorInfo i = sampling_lights(IntegratorInfo{
            "ppg", {"guided", "guided_path"},
            "path tracing guided by a learned SD-tree of arriving radiance (practical path guiding), NEE by MIS; in media too (volpath's walk, "
            "guided phase sampling)",
            false, true, ppg_params(), [](const IntegratorOptions& o) { return make_for_transport<PathGuiding>(o); }});
        i.media = true;
        return i;
    }();
    return info;
}

}  // namespace pathlab

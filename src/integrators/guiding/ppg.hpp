// ppg: path tracing guided by an SD-tree (practical path guiding; ppg.cpp says how).
#pragma once

#include <vector>

#include "integrators/common/path_rules.hpp"
#include "integrators/guiding/sd_tree.hpp"
#include "integrators/integrator.hpp"

namespace pathlab {

// Deliberate faults for the tests that show they can fail.
struct GuidingFaults {
    bool drop_guide_pdf_in_mis = false;  // light sampling's MIS weight ignores the guiding density
    bool drop_roulette_weight = false;   // adjoint-driven roulette's survivors keep their throughput
};

// The probability of sampling the BSDF rather than the SD-tree in a leaf that guides: the
// options' guiding_fraction (Müller's 0.5 by default), or with kLearnedGuidingFraction the leaf's
// learned one (BsdfFractionFit).
inline float guiding_bsdf_fraction(const IntegratorOptions& o, const GuidingLeaf& leaf) {
    return o.guiding_fraction == kLearnedGuidingFraction ? leaf.fraction.fraction() : o.guiding_fraction;
}

// A leaf's guiding distribution at a vertex, as media_lighting.hpp's sampling and light sampling
// take it (its Guide): the one-sample mixture a p_scatter + (1 - a) p_leaf where `on`.
struct LeafGuide {
    const GuidingLeaf* leaf = nullptr;
    float a = 1;
    bool on = false;
    bool drop_in_mis = false;  // GuidingFaults::drop_guide_pdf_in_mis

    bool guides() const { return on; }
    float fraction() const { return a; }
    float pdf(const Vec3f& w) const { return leaf->pdf(w); }
    Vec3f sample(Vec2f u) const { return leaf->sample(u); }
    float mixture(const Vec3f& w, float pdf_scatter) const { return on ? a * pdf_scatter + (1.0f - a) * leaf->pdf(w) : pdf_scatter; }
    float mis_pdf(const Vec3f& w, float pdf_scatter) const { return drop_in_mis ? pdf_scatter : mixture(w, pdf_scatter); }
};

template <class T>
class PathGuiding final : public PixelIntegrator<T> {
public:
    using Colour = ColourOf<T>;
    using Wl = WavelengthsOf<T>;

    explicit PathGuiding(const IntegratorOptions& o, GuidingFaults faults = {});
    // Trains the SD-tree: iterations of 1, 2, 4, ... samples per pixel (the last takes what is
    // left of --guiding-spp), each guided by the tree the previous one built.
    void prepare(const RenderContext& ctx, const PassProgress& progress) override;
    Colour radiance(const Scene& scene, const Ray& ray, Sampler& sampler, Wl& wl) const override;
    std::vector<IntegratorStatistic> statistics() const override;

    const SdTree& tree() const { return tree_; }
    bool trained() const { return guided_; }  // prepare() has trained the tree
    // The training iterations' sizes in samples per pixel, for a training budget.
    static std::vector<uint64_t> iteration_sizes(uint64_t training_spp);

    // One record of a training path (sd_tree.hpp): the radiance arriving from `direction` over
    // its density, or (outgoing) the radiance the vertex sent back.
    // Or (fraction) a gradient of the leaf's BSDF fraction's fit.
    struct Record {
        enum Kind : uint8_t { kIncoming, kOutgoing, kFraction };
        Vec3f p, direction;
        float value;
        Kind kind;
    };

    // Adjoint-driven roulette and splitting (--guiding-rr): the weight window's ratio, the most
    // copies one vertex splits a path into, and the most copies of a camera sample in all.
    static constexpr float kWindow = 5.0f;
    static constexpr int kMaxSplit = 8, kMaxCopies = 64;

private:
    // A training path's vertex: where its continuation left from, in which direction, with what
    // density, the radiance gathered before its light came in and the throughput after it; and
    // the radiance gathered before the vertex and the throughput that reached it.
    // With a learned fraction, a guided vertex also keeps what the fraction's gradient needs: the
    // fraction a, f |cos| of the continuation and its two densities.
    struct PathVertex {
        Vec3f p, direction;
        float pdf;
        bool guided_record;
        Colour L_start, beta_start, L_before, beta_after;
        float a = 1, f_cos = 0, pdf_bsdf = 0, pdf_tree = 0;
    };
    static constexpr int kRecordedVertices = 64;  // a training path records its first 64 vertices

    // The estimate of a camera sample (recording a training path's records).
    Colour trace(const Scene& scene, const Ray& ray, Sampler& sampler, Wl& wl, std::vector<Record>* records) const;
    // The radiance a path brings back from `hit` on, times beta (the throughput there), for a path
    // that has made first_bounce bounces: records (training; `vertices` holds kRecordedVertices) or
    // roulette and splitting against the pixel's estimate `pixel` (0: the throughput's roulette),
    // the path being one of `copies`.
    Colour walk(const Scene& scene, Intersection hit, Vec3f dir, Colour beta, int first_bounce, Sampler& sampler, Wl& wl,
                std::vector<Record>* records, PathVertex* vertices, float pixel, int copies) const;
    // The estimate of a camera sample in a scene with media (volpath's walk, guided at surfaces and
    // at points in media).
    Colour trace_in_media(const Scene& scene, const Ray& ray, Sampler& sampler, Wl& wl, std::vector<Record>* records) const;
    // Adjoint-driven roulette's window of throughputs (lower, upper) for a path whose next vertex's
    // leaf sends back `next`, against the pixel's `pixel`.
    static std::pair<float, float> weight_window(float pixel, float next);
    // The guiding at a vertex whose leaf is `leaf` (null: untrained), where the BSDF may be guided.
    LeafGuide leaf_guide(const GuidingLeaf* leaf, bool guidable) const;
    // The records of a block's `rows` rows, each traced by one rank (row r by rank r % size), on every rank.
    static void exchange_rows(const PrepareRanks& ranks, std::vector<std::vector<Record>>& row_records, int rows);
    // A training path's records, from its recorded vertices and all it gathered (L).
    static void add_records(const PathVertex* vertices, int n, const Colour& L, bool outgoing, std::vector<Record>& out);

    IntegratorOptions options_;
    PathRules rules_;
    GuidingFaults faults_;
    SdTree tree_;
    bool guided_ = false;  // the tree has been trained
    double training_seconds_ = 0;
    PreparedFor prepared_;  // a trained tree is kept for a continued render
};
extern template class PathGuiding<RgbTransport>;
extern template class PathGuiding<SpectralTransport>;

}  // namespace pathlab

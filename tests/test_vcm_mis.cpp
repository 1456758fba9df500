// VCM's MIS weights on hand-built paths (mis_harness.hpp): with merging, every strategy that
// can make a path, the connections (s, t) and merging at each non-Dirac inner vertex x_j, gets
// the weight of the balance (and power) heuristic computed here from the strategies' densities
// written out from their definitions, the merge's being the VCM report's: the density of the
// connection whose camera endpoint is x_j, times the light side's area density of x_j, times
// eta = light paths x pi r^2. The weights sum to 1, with connections on (vcm) and off (bpm), for
// several eta; a merge weight that leaves out the light side's density is caught. The weights
// vcm renders with (running quantities, O(1) per connection and per merged photon) equal those
// of Veach's ratio walk (the oracle) to 1e-5 relative.
#include "integrators/photon/vcm.hpp"
#include "mis_harness.hpp"

namespace pathlab::test {
namespace {

class VcmMisHarness {
public:
    VcmMisHarness(const MisHarness& h, bool power, bool connections, VcmFaults faults = {})
        : h_(h), vcm_(options(power), faults), power_(power) {
        vm_.merging = true;
        vm_.connections = connections;
    }
    void set_eta(double eta) { vm_.eta = eta; }

    bool valid_connection(const FullPath& f, int s) const { return h_.valid(f, s) && (vm_.connections || s == 0); }
    bool valid_merge(const FullPath& f, int j) const { return j >= 1 && j <= h_.k(f) - 1 && !h_.specular(f, j); }
    // The light side's area density of x_j (from x_{j+1}; after a Dirac vertex, its coefficient
    // times the edge's cos / d^2, as bsdf_density gives it).
    double light_density(const FullPath& f, int j) const {
        return j + 1 == h_.k(f) ? h_.light_emission(f) : h_.bsdf_density(f, j + 2, j + 1, j);
    }
    // Merging at x_j: the connection with camera endpoint x_j (s = k - j) times p_light(x_j) eta.
    double merge_density(const FullPath& f, int j) const { return h_.strategy_density(f, h_.k(f) - j) * light_density(f, j) * vm_.eta; }

    double direct_weight(const FullPath& f, bool merge, int index) const {
        const auto h = [this](double x) { return power_ ? x * x : x; };
        double sum = 0;
        for (int s = 0; s <= h_.k(f); ++s)
            if (valid_connection(f, s)) sum += h(h_.strategy_density(f, s));
        for (int j = 1; j < h_.k(f); ++j)
            if (valid_merge(f, j)) sum += h(merge_density(f, j));
        return h(merge ? merge_density(f, index) : h_.strategy_density(f, index)) / sum;
    }

    float connection_weight(const FullPath& f, int s) const {
        std::vector<PathVertex<RgbTransport>> light, camera;
        h_.subpaths(f, s, light, camera, power_, &vm_);
        const int t = h_.k(f) + 1 - s;
        const float w = vcm_.bdpt().mis_weight(h_.ctx(), light, s, camera, t, h_.sampled_end(f, s), {}, &vm_);
        const float oracle = vcm_.bdpt().mis_weight_oracle(h_.ctx(), light, s, camera, t, h_.sampled_end(f, s), {}, &vm_);
        EXPECT_NEAR(w, oracle, 1e-5 * oracle + 1e-12) << "connection s=" << s << ": running vs walk";
        return w;
    }
    // The photon x_j on the light subpath x_k .. x_j, merged at x_j on the camera subpath x_0 .. x_j.
    float merge_weight(const FullPath& f, int j) const {
        const int s = h_.k(f) - j + 1;
        std::vector<PathVertex<RgbTransport>> light, camera, unused;
        h_.subpaths(f, s, light, unused, power_, &vm_);
        h_.subpaths(f, s - 1, unused, camera, power_, &vm_);
        const float w = vcm_.merge_weight(h_.ctx().scene, light.data(), s, camera, j + 1, vm_);
        const float oracle = vcm_.merge_weight_oracle(h_.ctx().scene, light.data(), s, camera, j + 1, vm_);
        EXPECT_NEAR(w, oracle, 1e-5 * oracle + 1e-12) << "merge at x_" << j << ": running vs walk";
        return w;
    }

private:
    static IntegratorOptions options(bool power) {
        IntegratorOptions o;
        o.mis_power = power;
        return o;
    }
    const MisHarness& h_;
    Vcm<RgbTransport> vcm_;
    bool power_;
    MergeMis vm_;
};

// Checks every strategy's weight of f against the direct heuristic; returns the sum of the weights.
double check_weights(const VcmMisHarness& v, const MisHarness& h, const FullPath& f, const std::string& what) {
    double sum = 0;
    for (int s = 0; s <= h.k(f); ++s) {
        if (!v.valid_connection(f, s)) continue;
        const float w = v.connection_weight(f, s);
        const double expected = v.direct_weight(f, false, s);
        EXPECT_FALSE(std::isnan(w)) << what << " s=" << s;
        EXPECT_NEAR(w, expected, 1e-4 + 1e-4 * expected) << what << ", connection s=" << s;
        sum += w;
    }
    for (int j = 1; j < h.k(f); ++j) {
        if (!v.valid_merge(f, j)) continue;
        const float w = v.merge_weight(f, j);
        const double expected = v.direct_weight(f, true, j);
        EXPECT_FALSE(std::isnan(w)) << what << " merge at x_" << j;
        EXPECT_NEAR(w, expected, 1e-4 + 1e-4 * expected) << what << ", merge at x_" << j;
        sum += w;
    }
    return sum;
}

void expect_weights(const MisHarness& h, const FullPath& f, const std::string& what) {
    ASSERT_TRUE(f.problem.empty()) << what << ": " << f.problem;
    for (const bool power : {false, true})
        for (const bool connections : {true, false}) {
            VcmMisHarness v(h, power, connections);
            for (const double eta : {1e-3, 0.1, 10.0}) {
                v.set_eta(eta);
                const std::string label = what + (power ? " (power" : " (balance") + (connections ? ", vcm" : ", bpm") +
                                          ", eta " + std::to_string(eta) + ")";
                EXPECT_NEAR(check_weights(v, h, f, label), 1.0, 1e-4) << label;
            }
        }
}

// The bdpt MIS test's paths (mis_harness.hpp); from the point light the specular-diffuse-
// specular ones, where merging is the only strategy (and gets weight 1).
TEST(VcmMis, HandBuiltPaths) {
    for (const LightKind kind : {LightKind::Area, LightKind::Point, LightKind::Environment}) {
        const MisHarness h(kind);
        for (const NamedPath& p : hand_built_paths(h)) expect_weights(h, p.path, p.name);
    }
}

// The test of the tests: a merge weight without the light side's density of its vertex no
// longer sums to 1 with the others.
TEST(VcmMis, DetectsAMergeDensityWithoutTheLightPdf) {
    const MisHarness h(LightKind::Area);
    const FullPath f = h.build({Vec3f(0.2f, 0.4f, 0.0f), Vec3f(-0.4f, 2.5f, 1.0f), Vec3f(0.1f, 0.45f, 2.5f)});
    ASSERT_TRUE(f.problem.empty()) << f.problem;
    VcmMisHarness v(h, false, true, VcmFaults{.merge_weight_without_light_pdf = true});
    v.set_eta(0.1);
    double sum = 0;
    for (int s = 0; s <= h.k(f); ++s)
        if (v.valid_connection(f, s)) sum += v.connection_weight(f, s);
    for (int j = 1; j < h.k(f); ++j)
        if (v.valid_merge(f, j)) sum += v.merge_weight(f, j);
    EXPECT_GT(std::abs(sum - 1.0), 1e-2);
}

}  // namespace
}  // namespace pathlab::test

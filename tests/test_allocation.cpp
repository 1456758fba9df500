// The hot path allocates nothing: every estimator's radiance() for thousands of samples, the
// light tracer's paths once its splat list has the size of a pass, and bdpt's subpaths and
// connections, and the iterations of sppm, ppm, vcm and bpm (but a few), make no heap allocation (counted by
// replacing operator new in this test binary).
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "instrument/allocation_counter.hpp"
#include "integrators/bidir/bdpt.hpp"
#include "integrators/bidir/light_tracer.hpp"
#include "integrators/mlt/mmlt.hpp"
#include "integrators/mlt/pssmlt.hpp"
#include "integrators/photon/pm.hpp"
#include "integrators/photon/sppm.hpp"
#include "integrators/photon/vcm.hpp"
#include "job/renderer.hpp"
#include "scene/builtin_scenes.hpp"

namespace pathlab {
namespace {

TEST(Allocation, CounterSeesAllocations) {
    const uint64_t before = allocations_by_this_thread();
    // A direct call of operator new (unlike a new-expression, the compiler may not elide it).
    void* p = ::operator new(64);
    ::operator delete(p);
    EXPECT_EQ(allocations_by_this_thread() - before, 1u);
}

// Scene 3 with its materials replaced by the microfacet and Fresnel ones, in turn.
SceneDescription with_new_materials(SceneDescription d) {
    const MicrofacetDistribution ggx(MicrofacetType::GGX, 0.2f, 0.2f), beckmann(MicrofacetType::Beckmann, 0.3f, 0.1f);
    const Material choices[] = {make_rough_conductor(ggx, *named_conductor("Au")), make_plastic(Rgb(0.5f)),
                                make_rough_plastic(beckmann, Rgb(0.4f)), make_rough_dielectric(ggx, 1.5f),
                                make_conductor(*named_conductor("Cu")), make_rough_conductor(beckmann)};
    for (size_t i = 0; i < d.materials.size(); ++i)
        if (!d.materials[i].is_black()) d.materials[i] = choices[i % std::size(choices)];
    return d;
}

// Every integrator of transport T (RGB, spectral) on the scene.
template <class T>
void expect_no_allocations(const Scene& scene, int index) {
    const PerspectiveCamera camera(scene.camera(), 64, 64);
    const char* mode = T::spectral ? " (spectral)" : "";
    IntegratorOptions options;
    options.spectral = T::spectral;
    IntegratorOptions finite = options;
    finite.max_depth = 5;  // (mmlt's chains need a last length)
    for (const IntegratorInfo& info : integrators()) {
        const auto integrator = info.make(info.name == "mmlt" ? finite : options);
        const RenderContext ctx{scene, camera, 64, 64, 7, SamplerKind::Independent, 32};
        if (const auto* lt = dynamic_cast<const LightTracer<T>*>(integrator.get())) {
            // Light paths: once the splat list has grown (here: by a pass of twice as many
            // paths as are then counted), none allocates.
            SplatList splats;
            uint64_t invalid = 0;
            for (uint64_t j = 0; j < 8192; ++j) {
                Sampler sampler(7, j, 0);
                lt->trace(ctx, sampler, splats, invalid);
            }
            splats.clear();
            const uint64_t before = allocations_by_this_thread();
            for (uint64_t j = 0; j < 4096; ++j) {
                Sampler sampler(7, j, 1);
                lt->trace(ctx, sampler, splats, invalid);
            }
            EXPECT_EQ(allocations_by_this_thread() - before, 0u) << info.name << mode << " on scene " << index;
            EXPECT_GT(splats.splats().size(), 100u) << "the light paths must reach the camera";
            continue;
        }
        if (const auto* bdpt = dynamic_cast<const Bdpt<T>*>(integrator.get())) {
            // Subpaths and every connection allocate nothing.
            std::vector<PathVertex<T>> cam, light;  // as long as a path can be: growth is not per sample
            cam.reserve(size_t(bdpt->max_camera_vertices()));
            light.reserve(size_t(bdpt->max_light_vertices()));
            const auto sample = [&](uint64_t j, uint64_t pass) {
                Sampler sampler(7, j, pass);
                const auto wl = T::camera_wavelengths(sampler);
                bdpt->camera_subpath(ctx, size_t(j % 4096), sampler, wl, cam);
                bdpt->light_subpath(ctx, sampler, wl, light);
                float sum = 0;
                for (int t = 1; t <= int(cam.size()); ++t)
                    for (int s = 0; s <= std::max(1, int(light.size())); ++s)
                        if (s + t >= 2 && !(s == 1 && t == 1)) sum += bdpt->connect(ctx, light, s, cam, t, sampler, wl).weight;
                return sum;
            };
            float weights = 0;
            for (uint64_t j = 0; j < 4096; ++j) weights += sample(j, 0);
            const uint64_t before = allocations_by_this_thread();
            for (uint64_t j = 0; j < 4096; ++j) weights += sample(j, 1);
            EXPECT_EQ(allocations_by_this_thread() - before, 0u) << info.name << mode << " on scene " << index;
            EXPECT_GT(weights, 100.0f) << "the strategies must connect";
            continue;
        }
        const auto* sppm = dynamic_cast<const Sppm<T>*>(integrator.get());
        const auto* vcm = dynamic_cast<const Vcm<T>*>(integrator.get());
        if (sppm || vcm) {
            // Iterations: after two (which size the photon, vertex and grid arrays), an
            // iteration of 4096 light paths (thousands of photons and merges) allocates only
            // when a chunk's list outgrows its capacity, at most once per chunk and list:
            // sppm's photon lists (64 chunks); vcm's vertex lists (64 chunks), its one array of
            // merge vertices and the grid's four arrays.
            // One thread: the counter sees this thread's allocations only.
            tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
            Film film(64, 64);
            integrator->render_passes(ctx, film, 0, 2, {});
            const uint64_t before = allocations_by_this_thread();
            integrator->render_passes(ctx, film, 2, 1, {});
            EXPECT_LE(allocations_by_this_thread() - before, sppm ? 64u : 64u + 5u) << info.name << mode << " on scene " << index;
            if (vcm) { EXPECT_GT(vcm->photon_count(), 2048u) << info.name << mode << " on scene " << index; }
            continue;
        }
        if (dynamic_cast<const Pssmlt<T>*>(integrator.get()) || dynamic_cast<const Mmlt<T>*>(integrator.get())) {
            // Passes: after two (which size the chains' states, the bootstrap's arrays, the
            // splat lists and mmlt's subpaths), a pass allocates only when a chain's splat list
            // or state outgrows its capacity, at most once per chain (64 chains; measured: 0 or 1).
            tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
            Film film(64, 64);
            integrator->prepare(ctx, {});
            integrator->render_passes(ctx, film, 0, 2, {});
            const uint64_t before = allocations_by_this_thread();
            integrator->render_passes(ctx, film, 2, 1, {});
            EXPECT_LE(allocations_by_this_thread() - before, 64u) << info.name << mode << " on scene " << index;
            continue;
        }
        const auto radiance = [&](Sampler& sampler, const Ray& ray) {
            auto wl = T::camera_wavelengths(sampler);
            if (const auto* pm = dynamic_cast<const PhotonMapper<T>*>(integrator.get())) {
                wl = T::pass_wavelengths(ctx.seed, ctx.sampler, 0);  // the maps' (below)
                return pm->radiance(scene, ray, sampler, wl);
            }
            return dynamic_cast<const PixelIntegrator<T>&>(*integrator).radiance(scene, ray, sampler, wl);
        };
        if (auto* pm = dynamic_cast<PhotonMapper<T>*>(integrator.get())) {
            // Its photon maps first (their building allocates; the samples must not): RGB mode
            // builds them before the first pass, spectral mode with each pass.
            pm->prepare(ctx);
            if (T::spectral) {
                Film film(64, 64);
                pm->render_passes(ctx, film, 0, 1, {});
            }
        } else {
            ASSERT_TRUE(dynamic_cast<const PixelIntegrator<T>*>(integrator.get()))
                << info.name << ": a new kind of integrator needs its own allocation check here";
        }
        const auto samples = [&](uint64_t from, uint64_t to) {
            for (uint64_t s = from; s < to; ++s) {
                Sampler sampler(7, s % 4096, s);
                const Vec2f jitter = sampler.next2d();
                const Ray ray = camera.generate(float(s % 64) + jitter.x, float((s / 64) % 64) + jitter.y);
                (void)radiance(sampler, ray);
            }
        };
        samples(0, 64);  // warm-up: spectral mode's first sample makes its static colour tables
        const uint64_t before = allocations_by_this_thread();
        samples(64, 4096);
        EXPECT_EQ(allocations_by_this_thread() - before, 0u) << info.name << mode << " on scene " << index;
    }
}

TEST(Allocation, NoEstimatorAllocatesPerSample) {
    for (int index : {0, 3, 5, 7, -1}) {
        const auto scene = Scene::build(index < 0 ? with_new_materials(make_builtin_scene(3)) : make_builtin_scene(index));
        expect_no_allocations<RgbTransport>(*scene, index);
        expect_no_allocations<SpectralTransport>(*scene, index);
    }
}

}  // namespace
}  // namespace pathlab

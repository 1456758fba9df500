// The hot path allocates nothing: every estimator's radiance() for thousands of samples makes no
// heap allocation (counted by replacing operator new in this test binary).
#include <gtest/gtest.h>

#include "instrument/allocation_counter.hpp"
#include "render/renderer.hpp"
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

TEST(Allocation, NoEstimatorAllocatesPerSample) {
    for (int index : {0, 3, 5, 7}) {
        const auto scene = Scene::build(make_builtin_scene(index));
        const CameraRays camera(scene->camera(), 64, 64);
        for (const EstimatorInfo& info : estimators()) {
            const auto estimator = info.make({});
            const uint64_t before = allocations_by_this_thread();
            for (uint64_t s = 0; s < 4096; ++s) {
                Sampler sampler(7, s % 4096, s);
                const Vec2f jitter = sampler.next2d();
                const Ray ray = camera.generate(float(s % 64) + jitter.x, float((s / 64) % 64) + jitter.y);
                (void)estimator->radiance(*scene, ray, sampler);
            }
            EXPECT_EQ(allocations_by_this_thread() - before, 0u) << info.name << " on scene " << index;
        }
    }
}

}  // namespace
}  // namespace pathlab

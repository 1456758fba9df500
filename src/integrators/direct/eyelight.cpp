// eyelight: a debugging view. Each pixel shows |cos| between the camera ray and the surface
// normal it hits (black where the ray escapes). No lights, no materials.
#include "integrators/integrators.hpp"

namespace pathlab {
namespace {

// |cos| as the colour of an RGB white emitter (D65 at unit luminance in spectral mode, through
// light_colour with no light), so the view stays grey in the film.
template <class T>
class EyeLight final : public PixelIntegrator<T> {
public:
    explicit EyeLight(const IntegratorOptions&) {}
    ColourOf<T> radiance(const Scene& scene, const Ray& ray, Sampler&, WavelengthsOf<T>& wl) const override {
        Intersection hit;
        if (!scene.intersect(ray, hit)) return ColourOf<T>(0.0f);
        return light_colour(scene, -1, Rgb(1.0f), wl) * std::abs(dot(ray.d, hit.ns));
    }
};

}  // namespace

const IntegratorInfo& eyelight_integrator() {
    static const IntegratorInfo info{"eyelight", {}, "debug view: |cos| between camera ray and surface normal", false, true, {},
                              [](const IntegratorOptions& o) { return make_for_transport<EyeLight>(o); }};
    return info;
}

}  // namespace pathlab

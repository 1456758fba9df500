#include "lights/ies.hpp"

namespace pathlab {

IesLight read_ies_light(Properties& p, const EmitterContext& ctx) {
    const std::string path = emitter_file(p, ctx, "ies");
    const Rgb intensity = p.get_rgb("intensity");
    const Frame frame = rotation_frame(p, "ies");
    Vec3d position(0.0);
    if (const auto t = p.get_transform("to_world")) position = t->point(position);
    std::shared_ptr<const IesDistribution> profile;
    try {
        profile = std::make_shared<const IesDistribution>(read_ies_file(path));
    } catch (const IesError& e) {
        p.fail("filename", e.what());
    }
    return IesLight{Vec3f(position), frame, intensity / kLumensPerWatt, std::move(profile)};
}

}  // namespace pathlab

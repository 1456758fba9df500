// heterogeneous: a medium whose extinction and albedo vary in space (smoke, clouds): volumes
// (volume.hpp) give sigma_t and albedo at each point, and a majorant grid over the extinction's
// voxel grid bounds it piecewise (majorant_grid.hpp).
//
// XML (Mitsuba 3): <volume type="gridvolume" name="sigma_t"> (or constvolume, or an <rgb>/<float>
// sigma_t; default 1), likewise albedo (default 0.75), scale (float, default 1) multiplying
// the extinction, and a nested <phase> (default isotropic).
#pragma once

#include "core/properties.hpp"
#include "media/majorant_grid.hpp"
#include "media/phase.hpp"
#include "media/volume.hpp"

namespace pathlab {

struct HeterogeneousMedium {
    Volume sigma_t = Volume::constant_value(Rgb(1.0f));  // before `scale`
    Volume albedo = Volume::constant_value(Rgb(0.75f));
    float scale = 1;
    PhaseFunction phase;
    std::shared_ptr<const MajorantGrid> majorants;  // over sigma_t's grid (none for a constant)

    // Builds the majorant grid (call after setting sigma_t and scale).
    void prepare() {
        majorants = sigma_t.grid ? std::make_shared<const MajorantGrid>(MajorantGrid::build(*sigma_t.grid, scale)) : nullptr;
    }
    Rgb extinction(const Vec3f& p) const { return sigma_t.eval(p) * scale; }
};

inline const PluginInfo& heterogeneous_plugin() {
    static const PluginInfo info{
        "medium", "heterogeneous", "coefficients that vary in space, from voxel grids",
        {{"sigma_t", ParamType::Rgb, "1", "extinction, unless a volume named sigma_t gives it"},
         {"albedo", ParamType::Rgb, "0.75", "single-scattering albedo, in [0, 1], unless a volume named albedo gives it"},
         {"scale", ParamType::Float, "1", "multiplies the extinction"}},
        "Nested `<volume name=\"sigma_t\">` and `<volume name=\"albedo\">` (gridvolume or constvolume) give the "
        "coefficients; a nested `<phase>` the phase function (default isotropic). Extinction is 0 outside sigma_t's grid."};
    return info;
}

}  // namespace pathlab

// Textures: a colour or a scalar that varies over a surface, evaluated at a hit's surface
// coordinates uv (a SurfaceUv: also a mesh's attributes there). A closed set dispatched with
// std::visit, as the materials are: constant (a plain value), bitmap (bitmap.hpp),
// checkerboard (checkerboard.hpp) and mesh_attribute (mesh_attribute.hpp). Conventions (the uv
// transform, the scalar value of a colour, texel footprints) in texture_common.hpp.
//
// A material refers to its textures (bsdfs/material.hpp); they are immutable once loaded and
// shared by every thread. Texel values are kept as loaded (linear RGB, per texture): they are
// the differentiable parameters `<bsdf id>.reflectance.data` (src/diff/parameters.hpp), and a
// later stage may upsample them to spectra.
#pragma once

#include <variant>

#include "textures/bitmap.hpp"
#include "textures/checkerboard.hpp"
#include "textures/mesh_attribute.hpp"

namespace pathlab {

struct ConstantTexture {
    Rgb value{0.0f};

    Rgb eval(const Vec2f&) const { return value; }
    float eval_1(const Vec2f&) const { return scalar_value(value); }
    Vec2f eval_1_grad(const Vec2f&) const { return {0.0f, 0.0f}; }
};

class Texture {
public:
    using Model = std::variant<ConstantTexture, BitmapTexture, CheckerboardTexture, MeshAttributeTexture>;

    Texture(Model m) : model_(std::move(m)) {}

    Rgb eval(const SurfaceUv& uv) const {
        return std::visit([&](const auto& t) { return t.eval(uv); }, model_);
    }
    float eval_1(const SurfaceUv& uv) const {
        return std::visit([&](const auto& t) { return t.eval_1(uv); }, model_);
    }
    Vec2f eval_1_grad(const SurfaceUv& uv) const {
        return std::visit([&](const auto& t) { return t.eval_1_grad(uv); }, model_);
    }
    // The texels a lookup reads (bitmaps; none for the others).
    TexelFootprint footprint(const Vec2f& uv) const {
        if (const auto* b = std::get_if<BitmapTexture>(&model_)) return b->footprint(uv);
        return {};
    }
    // The smallest and largest value of each channel anywhere on the surface (a mesh_attribute's:
    // 0 and its scale, which the scene file checks against the mesh's values).
    Rgb min_value() const;
    Rgb max_value() const;

    const Model& model() const { return model_; }

private:
    Model model_;
};

inline Rgb Texture::min_value() const {
    if (const auto* b = std::get_if<BitmapTexture>(&model_)) return b->min_value();
    if (const auto* c = std::get_if<CheckerboardTexture>(&model_)) return min(c->color0, c->color1);
    if (std::holds_alternative<MeshAttributeTexture>(model_)) return Rgb(0.0f);
    return std::get<ConstantTexture>(model_).value;
}
inline Rgb Texture::max_value() const {
    if (const auto* b = std::get_if<BitmapTexture>(&model_)) return b->max_value();
    if (const auto* c = std::get_if<CheckerboardTexture>(&model_)) return max(c->color0, c->color1);
    if (const auto* m = std::get_if<MeshAttributeTexture>(&model_)) return Rgb(m->scale);
    return std::get<ConstantTexture>(model_).value;
}

}  // namespace pathlab

// Scalar losses of a rendered image against a target, and their adjoint images dLoss/dI (what
// the path replay carries): the mean over the pixels of a region (the whole image by default)
// and the three channels of (I - T)^2 (L2) or |I - T| (L1).
#pragma once

#include <string>

#include "image/image.hpp"

namespace pathlab {

enum class LossKind { L2, L1 };

struct Loss {
    LossKind kind = LossKind::L2;
    // The region [x0, x1) x [y0, y1) (x1 = 0: the whole image).
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// "l2" or "l1" (std::invalid_argument listing them otherwise); "x0,y0,x1,y1" for a region.
LossKind parse_loss_kind(const std::string& name);

double loss_value(const Image& image, const Image& target, const Loss& loss);
Image loss_adjoint(const Image& image, const Image& target, const Loss& loss);

}  // namespace pathlab

#include "diff/loss.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace pathlab {
namespace {

struct Region {
    int x0, y0, x1, y1;
    double count() const { return 3.0 * double(x1 - x0) * double(y1 - y0); }
};

Region region_of(const Image& image, const Image& target, const Loss& loss) {
    if (image.width() != target.width() || image.height() != target.height())
        throw std::invalid_argument(fmt::format("the target is {}x{}, the rendered image {}x{}", target.width(), target.height(),
                                                image.width(), image.height()));
    Region r{loss.x0, loss.y0, loss.x1, loss.y1};
    if (r.x1 == 0) r = {0, 0, image.width(), image.height()};
    if (r.x0 < 0 || r.y0 < 0 || r.x1 > image.width() || r.y1 > image.height() || r.x0 >= r.x1 || r.y0 >= r.y1)
        throw std::invalid_argument(fmt::format("the loss region {},{},{},{} is not inside the {}x{} image", r.x0, r.y0, r.x1, r.y1,
                                                image.width(), image.height()));
    return r;
}

}  // namespace

LossKind parse_loss_kind(const std::string& name) {
    if (name == "l2") return LossKind::L2;
    if (name == "l1") return LossKind::L1;
    throw std::invalid_argument(fmt::format("unknown loss '{}'; valid: l2, l1", name));
}

double loss_value(const Image& image, const Image& target, const Loss& loss) {
    const Region r = region_of(image, target, loss);
    double sum = 0;
    for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = double(image.at(x, y)[c]) - double(target.at(x, y)[c]);
                sum += loss.kind == LossKind::L2 ? d * d : std::abs(d);
            }
    return sum / r.count();
}

Image loss_adjoint(const Image& image, const Image& target, const Loss& loss) {
    const Region r = region_of(image, target, loss);
    Image adj(image.width(), image.height());
    for (int y = r.y0; y < r.y1; ++y)
        for (int x = r.x0; x < r.x1; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = double(image.at(x, y)[c]) - double(target.at(x, y)[c]);
                adj.at(x, y)[c] = float((loss.kind == LossKind::L2 ? 2 * d : (d > 0) - (d < 0)) / r.count());
            }
    return adj;
}

}  // namespace pathlab

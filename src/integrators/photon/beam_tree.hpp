// Photon beams (line segments) in a bounding volume hierarchy, for upbp's beam-beam estimator:
// the query of a camera beam visits every piece of a photon beam whose bounds, grown by the
// radius r, the camera beam's segment crosses; the caller tests the lines' distance exactly
// (Vcm::beam_beam). A long oblique beam has a box of mostly empty space that every query would
// enter, so beams are cut into pieces of at most `piece` length (the caller keeps a pair whose
// closest point on the photon beam lies in the piece's own range: each pair once).
#pragma once

#include <cstdint>
#include <vector>

#include "core/vec.hpp"
#include "integrators/photon/box_tree.hpp"

namespace pathlab {

class BeamTree {
public:
    struct Segment {
        Vec3f o, d;        // from o along the unit d ...
        float length = 0;  // ... this far
    };
    // A piece of segment `segment`: its range [t0, t1) along it.
    struct Piece {
        uint32_t segment;
        float t0, t1;
    };
    // The segments, cut into pieces of at most `piece` length, each grown by r.
    void build(const std::vector<Segment>& segments, float r, float piece);

    // f(piece) for every piece whose grown bounds the segment o + s d, s in [0, tmax), may cross
    // (d unit), in an order fixed by the segments: results do not depend on threads.
    template <typename F> void for_each_near(const Vec3f& o, const Vec3f& d, float tmax, F&& f) const {
        tree_.for_each_crossed(o, d, tmax, [&](uint32_t i) { f(pieces_[i]); });
    }

    size_t size() const { return pieces_.size(); }
    size_t memory_bytes() const { return tree_.memory_bytes() + pieces_.capacity() * sizeof(Piece); }

private:
    BoxTree tree_;
    std::vector<Piece> pieces_;
};

}  // namespace pathlab

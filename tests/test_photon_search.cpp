// Range search over photons: the hashed grid and nanoflann's k-d tree return exactly the
// photons within r of a query (|p - q| <= r, the boundary included), the same as brute force,
// on random and clustered photons, for queries inside and outside their bounds.
#include <gtest/gtest.h>

#include <algorithm>

#include "core/rng.hpp"
#include "integrators/photon/photon.hpp"
#include "integrators/photon/photon_grid.hpp"

namespace pathlab::test {
namespace {

std::vector<uint32_t> brute_force(const std::vector<Photon<RgbTransport>>& photons, const Vec3f& q, float r) {
    std::vector<uint32_t> out;
    for (size_t i = 0; i < photons.size(); ++i) {
        const Vec3f d = photons[i].p - q;
        if (dot(d, d) <= r * r) out.push_back(uint32_t(i));
    }
    return out;
}

template <typename Search> std::vector<uint32_t> found(const Search& s, const std::vector<Photon<RgbTransport>>& photons, const Vec3f& q, float r) {
    std::vector<uint32_t> out;
    s.for_each_within(q, r, [&](uint32_t i) { out.push_back(i); });
    (void)photons;
    std::sort(out.begin(), out.end());
    return out;
}

std::vector<Photon<RgbTransport>> random_photons(Pcg32& rng, size_t n) {
    std::vector<Photon<RgbTransport>> photons;
    for (size_t i = 0; i < n; ++i) {
        Vec3f p(rng.next_float(), rng.next_float(), rng.next_float());
        if (i % 3 == 0) p = Vec3f(0.3f) + (p - Vec3f(0.5f)) * 0.02f;  // a dense cluster
        if (i % 97 == 0 && i > 0) p = photons[i - 1].p;               // duplicates
        photons.push_back({p * 4.0f - Vec3f(1.0f), Vec3f(0, 0, 1), Rgb(1.0f), 2, 0, -1});
    }
    return photons;
}

TEST(PhotonSearch, GridAndKdTreeFindExactlyThePhotonsWithinTheRadius) {
    Pcg32 rng(12, 34);
    const std::vector<Photon<RgbTransport>> photons = random_photons(rng, 6000);
    size_t grand_total = 0;
    for (const float build_radius : {0.01f, 0.08f, 0.5f}) {
        PhotonGrid grid, placed;
        PhotonKdTree tree;
        grid.build(photons, build_radius);
        tree.build(photons, build_radius);
        // build_placed: the items stored in its cell order by the caller; item_at[slot] is the item.
        const std::vector<uint32_t>& place = placed.build_placed(Positions::of(photons), build_radius);
        std::vector<uint32_t> item_at(photons.size(), uint32_t(-1));
        for (size_t i = 0; i < photons.size(); ++i) item_at[place[i]] = uint32_t(i);
        ASSERT_EQ(std::count(item_at.begin(), item_at.end(), uint32_t(-1)), 0) << "place must be a permutation";
        size_t total = 0;
        for (int k = 0; k < 600; ++k) {
            // Queries in and around the photons' box, some at photons, radii up to the build radius.
            Vec3f q = Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 5.0f - Vec3f(1.5f);
            if (k % 4 == 0) q = photons[size_t(rng.next_u32() % photons.size())].p;
            const float r = build_radius * (k % 5 == 0 ? 1.0f : rng.next_float());
            const std::vector<uint32_t> expected = brute_force(photons, q, r);
            total += expected.size();
            ASSERT_EQ(found(grid, photons, q, r), expected) << "grid, r=" << r << ", query " << k;
            ASSERT_EQ(found(tree, photons, q, r), expected) << "k-d tree, r=" << r << ", query " << k;
            // The placed grid visits the same items in the same order as the plain one.
            std::vector<uint32_t> plain, slots;
            grid.for_each_within(q, r, [&](uint32_t i) { plain.push_back(i); });
            placed.for_each_within(q, r, [&](uint32_t slot) { slots.push_back(item_at[slot]); });
            ASSERT_EQ(slots, plain) << "placed grid, r=" << r << ", query " << k;
        }
        EXPECT_GT(total, 150u) << "the queries at photons must find them";
        grand_total += total;
    }
    EXPECT_GT(grand_total, 20000u) << "the larger radii must find many photons";
}

TEST(PhotonSearch, ThePhotonAtExactlyTheRadiusCountsAndNothingIsFoundInNothing) {
    const std::vector<Photon<RgbTransport>> photons = {{Vec3f(0.5f), Vec3f(0, 0, 1), Rgb(1.0f), 2, 0, -1}, {Vec3f(0.5f, 0.5f, 1.5f), Vec3f(0, 0, 1), Rgb(1.0f), 2, 0, -1}};
    PhotonGrid grid;
    PhotonKdTree tree;
    grid.build(photons, 0.25f);
    tree.build(photons, 0.25f);
    const Vec3f q(0.75f, 0.5f, 0.5f);  // exactly 0.25 from the first photon
    EXPECT_EQ(found(grid, photons, q, 0.25f), std::vector<uint32_t>{0});
    EXPECT_EQ(found(tree, photons, q, 0.25f), std::vector<uint32_t>{0});
    EXPECT_TRUE(found(grid, photons, q, 0.2499f).empty());
    EXPECT_TRUE(found(tree, photons, q, 0.2499f).empty());

    const std::vector<Photon<RgbTransport>> none;
    grid.build(none, 0.1f);
    tree.build(none, 0.1f);
    EXPECT_TRUE(found(grid, none, q, 0.1f).empty());
    EXPECT_TRUE(found(tree, none, q, 0.1f).empty());
}

// The merge's order is part of the image's bytes: the overload that prefetches (in batches of
// 16, the records of a batch asked for before its first call) must call f with the same indices
// in the same order as the plain one, and prefetch each index exactly once, before its f.
TEST(PhotonSearch, PrefetchingSearchCallsBackInTheSameOrder) {
    Pcg32 rng(56, 78);
    std::vector<Photon<RgbTransport>> photons = random_photons(rng, 6000);
    PhotonGrid grid;
    {
        const std::vector<uint32_t>& place = grid.build_placed(Positions::of(photons), 0.3f);
        std::vector<Photon<RgbTransport>> in_cell_order(photons.size());
        for (size_t i = 0; i < photons.size(); ++i) in_cell_order[place[i]] = photons[i];
        photons = std::move(in_cell_order);
    }
    size_t longest = 0;
    for (int k = 0; k < 200; ++k) {
        const Vec3f q = k % 2 == 0 ? photons[size_t(rng.next_u32() % photons.size())].p
                                   : Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 4.0f - Vec3f(1.0f);
        const float r = 0.3f * rng.next_float();
        std::vector<uint32_t> plain, called, asked;
        std::vector<bool> asked_before(photons.size(), false);
        bool in_order = true;
        grid.for_each_within(q, r, [&](uint32_t i) { plain.push_back(i); });
        grid.for_each_within(
            q, r,
            [&](uint32_t i) {
                in_order = in_order && asked_before[i];
                called.push_back(i);
            },
            [&](uint32_t i) {
                asked_before[i] = true;
                asked.push_back(i);
            });
        ASSERT_EQ(called, plain) << "query " << k;
        ASSERT_EQ(asked, plain) << "query " << k;
        ASSERT_TRUE(in_order) << "query " << k << ": an item was called back before it was prefetched";
        longest = std::max(longest, plain.size());
    }
    EXPECT_GT(longest, 64u) << "some queries must span several batches";
}

}  // namespace
}  // namespace pathlab::test

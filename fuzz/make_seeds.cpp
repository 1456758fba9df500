// Writes the seed corpora of the reader fuzz targets, from files pathlab (and the libraries it
// links) can make itself: small images in every format and variant the readers know, and OBJ
// meshes (OBJ, PLY, .serialized), voxel grids, spectrum files and a checkpoint. Usage:
// fuzz_make_seeds DIR  (creates DIR/exr, DIR/hdr, DIR/pfm, DIR/png,
// DIR/jpeg, DIR/bmp, DIR/obj, DIR/vol, DIR/vdb, DIR/ply, DIR/serialized, DIR/spd, DIR/checkpoint).
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "geometry/mesh_files.hpp"
#include "image/image_io.hpp"
#include "job/checkpoint.hpp"
#include "job/rank_group.hpp"
#include "media/grid_files.hpp"

namespace fs = std::filesystem;
using pathlab::Image;
using pathlab::Rgb;

namespace {

Image pattern(int w, int h) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img.at(x, y) = Rgb(float(x) / float(w), float(y) / float(h), std::exp2(float((x * 7 + y * 3) % 20) - 10.0f));
    if (w > 2) img.at(1, 0) = Rgb(0.0f);
    return img;
}

void write_exr_variant(const std::string& file, const Image& img, Imf::Compression c, bool tiled, bool half_type, bool grey) {
    const int w = img.width(), h = img.height();
    const Imath::Box2i window(Imath::V2i(-3, 2), Imath::V2i(-3 + w - 1, 2 + h - 1));
    Imf::Header header(window, window);
    header.compression() = c;
    const Imf::PixelType type = half_type ? Imf::HALF : Imf::FLOAT;
    const std::vector<std::string> names = grey ? std::vector<std::string>{"Y"} : std::vector<std::string>{"R", "G", "B"};
    for (const std::string& n : names) header.channels().insert(n, Imf::Channel(type));
    std::vector<float> f(size_t(w) * h * 3);
    std::vector<half> hf(f.size());
    for (size_t i = 0; i < img.pixel_count(); ++i)
        for (int k = 0; k < 3; ++k) f[i * 3 + k] = img[i][k], hf[i * 3 + k] = half(img[i][k]);
    Imf::FrameBuffer fb;
    for (size_t k = 0; k < names.size(); ++k) {
        char* base = half_type ? reinterpret_cast<char*>(hf.data() + k) : reinterpret_cast<char*>(f.data() + k);
        const size_t s = half_type ? sizeof(half) : sizeof(float);
        fb.insert(names[k], Imf::Slice::Make(type, base, window, 3 * s, 3 * s * size_t(w)));
    }
    if (tiled) {
        header.setTileDescription(Imf::TileDescription(4, 4, Imf::MIPMAP_LEVELS));
        Imf::TiledOutputFile out(file.c_str(), header);
        out.setFrameBuffer(fb);
        for (int level = 0; level < out.numLevels(); ++level) out.writeTiles(0, out.numXTiles(level) - 1, 0, out.numYTiles(level) - 1, level);
    } else {
        Imf::OutputFile out(file.c_str(), header);
        out.setFrameBuffer(fb);
        out.writePixels(h);
    }
}

void write_bytes(const fs::path& file, const std::string& bytes) { std::ofstream(file, std::ios::binary) << bytes; }

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    const fs::path dir = argv[1];
    for (const char* sub : {"exr", "hdr", "pfm", "png", "jpeg", "bmp", "obj", "vol", "vdb", "ply", "serialized", "spd", "checkpoint"})
        fs::create_directories(dir / sub);

    // pathlab's own writers, at sizes around the readers' special cases (HDR run-length
    // encoding needs widths of 8 or more).
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{5, 3}, std::pair{16, 8}, std::pair{37, 4}}) {
        const Image img = pattern(w, h);
        const std::string stem = std::to_string(w) + "x" + std::to_string(h);
        for (const char* ext : {"exr", "hdr", "pfm", "png"}) pathlab::write_image(img, (dir / ext / (stem + "." + ext)).string());
    }

    // JPEG (stb_image_write): grey and colour, two qualities (4:2:0 subsampling below 91), sizes
    // that are and are not whole 8x8 and 16x16 blocks.
    for (const auto& [w, h] : {std::pair{1, 1}, std::pair{8, 8}, std::pair{17, 9}, std::pair{33, 20}}) {
        const Image img = pattern(w, h);
        std::vector<uint8_t> rgb(size_t(w) * size_t(h) * 3), grey(size_t(w) * size_t(h));
        for (size_t i = 0; i < img.pixel_count(); ++i) {
            for (int k = 0; k < 3; ++k) rgb[i * 3 + size_t(k)] = uint8_t(std::min(255.0f, img[i][k] * 255.0f));
            grey[i] = rgb[i * 3];
        }
        const std::string stem = (dir / "jpeg" / (std::to_string(w) + "x" + std::to_string(h))).string();
        for (const int q : {50, 95}) {
            stbi_write_jpg((stem + "-q" + std::to_string(q) + ".jpg").c_str(), w, h, 3, rgb.data(), q);
            stbi_write_jpg((stem + "-grey-q" + std::to_string(q) + ".jpg").c_str(), w, h, 1, grey.data(), q);
        }
        // BMP (stb_image_write: 24 bits, bottom-up rows padded to 4 bytes; grey written as 24 bits too)
        const std::string bmp = (dir / "bmp" / (std::to_string(w) + "x" + std::to_string(h))).string();
        stbi_write_bmp((bmp + ".bmp").c_str(), w, h, 3, rgb.data());
        stbi_write_bmp((bmp + "-grey.bmp").c_str(), w, h, 1, grey.data());
    }

    // EXR: every compression; tiled with mipmaps; half and grey channels.
    const Image small = pattern(9, 7);
    int n = 0;
    for (const Imf::Compression c : {Imf::NO_COMPRESSION, Imf::RLE_COMPRESSION, Imf::ZIPS_COMPRESSION, Imf::ZIP_COMPRESSION,
                                     Imf::PIZ_COMPRESSION, Imf::PXR24_COMPRESSION, Imf::B44_COMPRESSION, Imf::B44A_COMPRESSION,
                                     Imf::DWAA_COMPRESSION, Imf::DWAB_COMPRESSION}) {
        const bool lossy_half = c == Imf::B44_COMPRESSION || c == Imf::B44A_COMPRESSION;
        write_exr_variant((dir / "exr" / ("c" + std::to_string(n++) + ".exr")).string(), small, c, false, lossy_half, false);
    }
    write_exr_variant((dir / "exr" / "tiled.exr").string(), small, Imf::ZIP_COMPRESSION, true, false, false);
    write_exr_variant((dir / "exr" / "tiled-half-y.exr").string(), small, Imf::RLE_COMPRESSION, true, true, true);
    write_exr_variant((dir / "exr" / "half-y.exr").string(), small, Imf::PIZ_COMPRESSION, false, true, true);

    // HDR: a header without FORMAT and the old Radiance run-length encoding (1,1,1,n repeats).
    {
        std::string old = "#?RGBE\nEXPOSURE=2\n\n-Y 2 +X 12\n";
        const auto pixel = [&](int r, int g, int b, int e) { old += {char(r), char(g), char(b), char(e)}; };
        pixel(128, 64, 32, 129), pixel(1, 1, 1, 5), pixel(200, 1, 1, 120), pixel(1, 1, 1, 5);
        for (int x = 0; x < 12; ++x) pixel(x * 20, 100, 3, 128 + x % 3);
        write_bytes(dir / "hdr" / "old-rle.hdr", old);
    }

    // PFM: greyscale and big-endian.
    {
        std::string pf = "Pf\n3 2\n1.0\n";
        for (int i = 0; i < 6; ++i) {
            const float v = float(i) * 0.25f;
            uint32_t u;
            std::memcpy(&u, &v, 4);
            u = __builtin_bswap32(u);
            pf.append(reinterpret_cast<const char*>(&u), 4);
        }
        write_bytes(dir / "pfm" / "grey-big-endian.pfm", pf);
    }

    // PNG: 1 to 4 channels (grey, grey + alpha, RGB, RGBA) from stb's writer.
    {
        std::vector<unsigned char> px(6 * 5 * 4);
        for (size_t i = 0; i < px.size(); ++i) px[i] = (unsigned char)(i * 37 % 256);
        for (int comp = 1; comp <= 4; ++comp)
            stbi_write_png((dir / "png" / ("comp" + std::to_string(comp) + ".png")).string().c_str(), 6, 5, comp, px.data(), 6 * comp);
    }

    // OBJ: normals, texture coordinates, quads and polygons, negative indices, groups.
    write_bytes(dir / "obj" / "quad-normals.obj",
                "# a quad with normals and uvs\no quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                "g front\ns 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
    write_bytes(dir / "obj" / "negative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf -4 -3 -2\nf -1 -3 -2\nusemtl red\nf 1//1 2 3\n");
    write_bytes(dir / "obj" / "polygon.obj", "v 0 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 0 2 0\nv -1 1 0\nf 1 2 3 4 5 6\nl 1 2\np 3\n");

    // .vol grids of 1 and 3 channels, written by pathlab's writer.
    for (int channels : {1, 3}) {
        pathlab::VoxelGrid g;
        g.res = {4, 3, 2};
        g.channels = channels;
        for (size_t i = 0; i < g.voxel_count() * size_t(channels); ++i) g.data.push_back(float(i % 7) * 0.25f);
        pathlab::write_vol_file((dir / "vol" / ("grid" + std::to_string(channels) + ".vol")).string(), g);
    }
    // .vdb grids written by OpenVDB (through pathlab's module): a small one and one with a tile.
    for (const int side : {3, 9}) {
        pathlab::VoxelGrid g;
        g.res = {side, side - 1, side - 2 > 0 ? side - 2 : 1};
        g.channels = 1;
        for (size_t i = 0; i < g.voxel_count(); ++i) g.data.push_back(i % 5 == 0 ? 0.0f : float(i % 7) * 0.25f);
        pathlab::write_vdb_file((dir / "vdb" / ("grid" + std::to_string(side) + ".vdb")).string(), g, "density", 0.1);
    }

    // PLY: ASCII with normals and a quad, binary little and big endian with uvs and a list of
    // another count type.
    const std::string ply_vertices = "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
    write_bytes(dir / "ply" / "ascii.ply", "ply\nformat ascii 1.0\ncomment a quad\n" + ply_vertices +
                                               "property float nx\nproperty float ny\nproperty float nz\n"
                                               "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                               "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n");
    for (const bool big : {false, true}) {
        std::string b = std::string("ply\nformat binary_") + (big ? "big" : "little") + "_endian 1.0\n" + ply_vertices +
                        "property float u\nproperty float v\nelement face 2\nproperty list uint16 uint32 vertex_indices\nend_header\n";
        const auto put = [&](const void* p, size_t n) {
            std::string bytes(static_cast<const char*>(p), n);
            if (big) std::reverse(bytes.begin(), bytes.end());
            b += bytes;
        };
        const float v[4][5] = {{0, 0, 0, 0, 0}, {1, 0, 0, 1, 0}, {1, 1, 0, 1, 1}, {0, 1, 0, 0, 1}};
        for (const auto& row : v)
            for (const float x : row) put(&x, 4);
        for (const auto& face : {std::array<uint32_t, 3>{0, 1, 2}, std::array<uint32_t, 3>{0, 2, 3}}) {
            const uint16_t n = 3;
            put(&n, 2);
            for (const uint32_t i : face) put(&i, 4);
        }
        write_bytes(dir / "ply" / (big ? "binary-big.ply" : "binary-little.ply"), b);
    }

    // Mitsuba .serialized: a quad with normals and uvs, single and double precision.
    {
        pathlab::MeshDesc m;
        m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
        m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
        m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        m.triangles = {{0, 1, 2}, {0, 2, 3}};
        write_bytes(dir / "serialized" / "quad.serialized", pathlab::serialized_mesh_bytes(m));
        write_bytes(dir / "serialized" / "quad-double.serialized", pathlab::serialized_mesh_bytes(m, true));
    }

    // Spectrum files: comments, blank lines, tabs, exponents.
    write_bytes(dir / "spd" / "simple.spd", "# a spectrum\n400 0.1\n500 0.25\n\n600\t0.5\n700 1e-1\n");
    write_bytes(dir / "spd" / "dense.spd", [] {
        std::string s;
        for (int w = 360; w <= 830; w += 5) s += std::to_string(w) + " " + std::to_string(0.5 + 0.4 * std::sin(w * 0.05)) + "\n";
        return s;
    }());

    // A checkpoint of a 3x2 film of two passes, written by pathlab's writer.
    {
        pathlab::Film film(3, 2);
        for (int pass = 0; pass < 2; ++pass)
            for (size_t p = 0; p < film.pixel_count(); ++p) film.add(p, pathlab::Rgb(float(p) * 0.25f, 0.5f, float(pass)));
        pathlab::CheckpointInfo info;
        info.identity.fields = {{"scene", "cornell-box"}, {"algorithm", "pt-mis"}, {"seed", "1234"}};
        info.passes = pathlab::PassSet::range(0, 2);
        info.width = 3, info.height = 2, info.seconds = 0.5, info.writer = "fuzz";
        pathlab::LocalRanks ranks;
        pathlab::write_checkpoint((dir / "checkpoint" / "small.ckpt").string(), ranks, film, info);
    }
    return 0;
}

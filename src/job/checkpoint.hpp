// Checkpoint files: the whole state of a render in progress, written atomically, so that a
// render stopped by Ctrl-C, a time limit, a crash or kill -9 continues (--resume) to the image
// it would have made uninterrupted, bit for bit. The state is the film's exact accumulators
// (render/film.hpp: sums, squares and counts; splatting integrators add whole passes to them, so
// they hold the splats too), which passes they hold, and the render's identity
// (job/render_identity.hpp) to refuse a checkpoint of another scene or other settings.
// Integrators keep nothing else from pass to pass (integrators/integrator.hpp).
//
// Format (version 1, little-endian; docs/distributed.md):
//   offset 0       8 bytes   magic "PLCKPT\r\n"
//          8       u32       format version
//          12      u32       header length H (at most 1 MiB)
//          16      H bytes   header: "key=value\n" lines: the identity's fields, then passes,
//                            width, height, seconds, pathlab (the version that wrote it)
//          16+H    u64       pixel count N (= width x height)
//          24+H    N x 160   the pixels' PixelSums, row by row
//          end-8   u64       XXH3-64 of every byte before it
// Written through a temporary file that is renamed over FILE only once complete and synced
// (image/file_io.hpp), so FILE always holds the last complete checkpoint.
#pragma once

#include <stdexcept>
#include <string>

#include "job/pass_set.hpp"
#include "job/rank_group.hpp"
#include "job/render_identity.hpp"
#include "render/film.hpp"

namespace pathlab {

// A checkpoint that cannot be used: missing, not a checkpoint, truncated, corrupted, of
// another version, or of another render. The message names the file and says what is wrong.
struct CheckpointError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

constexpr char kCheckpointMagic[8] = {'P', 'L', 'C', 'K', 'P', 'T', '\r', '\n'};
constexpr uint32_t kCheckpointVersion = 1;

struct CheckpointInfo {
    RenderIdentity identity;
    PassSet passes;      // the passes the film holds
    int width = 0, height = 0;
    double seconds = 0;  // time spent rendering it, over every run so far
    std::string writer;  // the pathlab version that wrote it
    std::string command;  // the command that continues it (app/resumed_command.hpp); "" from before it was recorded
};

// Writes `path` atomically from the ranks' films summed (parts.reduce_film; a collective: call
// it on every rank, the root writes). Throws ImageIoError (on the root) when the file cannot be
// written; the file then keeps its previous content.
void write_checkpoint(const std::string& path, RankGroup& parts, const Film& film, const CheckpointInfo& info);

struct Checkpoint {
    CheckpointInfo info;
    Film film;
};
// Reads and verifies (size, magic, version, checksum) a checkpoint; throws CheckpointError.
Checkpoint read_checkpoint(const std::string& path);
// The header only, with the file's size checked (not its checksum).
CheckpointInfo read_checkpoint_info(const std::string& path);
// Whether `path` is a regular file that begins as a checkpoint does (its magic); a named pipe or
// a folder is not (and is not opened: a pipe would wait for a writer).
bool is_checkpoint_file(const std::string& path);

}  // namespace pathlab

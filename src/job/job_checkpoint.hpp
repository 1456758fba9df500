// A RenderJob's checkpoints (--checkpoint FILE, --resume FILE): which files, their checks, the
// film a resumed render continues and the callback that writes them. The command line and
// Python's render() both come through here, so they refuse the same things with one message.
#pragma once

#include <string>

#include "job/checkpoint.hpp"
#include "job/output_paths.hpp"
#include "job/render_identity.hpp"
#include "job/render_job.hpp"

namespace pathlab {

// The file a render checkpoints to: --checkpoint's, else the one it resumes (a resumed render
// goes on checkpointing to the file it continues); "" for none.
inline std::string checkpoint_file(const std::string& checkpoint, const std::string& resume) {
    return checkpoint.empty() ? resume : checkpoint;
}

// --resume FILE as one of the command's inputs (unless the render checkpoints to it).
void add_resume_input(OutputPaths& paths, const std::string& checkpoint, const std::string& resume);

// --checkpoint FILE (as checkpoint_file() gives it) as one of the command's outputs: a UsageError
// when it exists and is not the file resumed (it would replace another render's work), or
// cannot be written.
void add_checkpoint_output(OutputPaths& paths, const std::string& checkpoint, const std::string& resume);

// What a resumed render starts from: the checkpoint's film, its passes and the time spent on it.
struct ResumedRender {
    Film film;
    PassSet done;
    double seconds = 0;
};

// Reads the checkpoint `path` (CheckpointError when it cannot be used: missing, corrupted, of
// another render than `identity` says, or holding passes outside the job's [first_sample,
// first_sample + spp)).
ResumedRender resume_checkpoint(const std::string& path, const RenderJob& job, const RenderIdentity& identity);

// Makes the job write its checkpoints to `path` every settings.checkpoint_every seconds, at the
// end and when interrupted: `info` is what they record (identity, size, command), its seconds
// those spent before this run. A checkpoint that cannot be written is a warning on stderr
// naming `name`; the render goes on, and the file keeps the last complete checkpoint.
void checkpoint_job(RenderJob& job, const std::string& path, const CheckpointInfo& info, const std::string& name);

// "" when the render's final checkpoint to `path` was written, else what the file holds instead.
std::string final_checkpoint_failure(const std::string& path, const RenderStats& stats);

}  // namespace pathlab

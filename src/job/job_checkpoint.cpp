#include "job/job_checkpoint.hpp"

#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "job/usage_error.hpp"

namespace pathlab {

void add_resume_input(OutputPaths& paths, const std::string& checkpoint, const std::string& resume) {
    if (!resume.empty() && resume != checkpoint_file(checkpoint, resume)) paths.input(resume, "--resume");
}

void add_checkpoint_output(OutputPaths& paths, const std::string& checkpoint, const std::string& resume) {
    const std::string file = checkpoint_file(checkpoint, resume);
    if (file.empty()) return;
    if (resume.empty() && std::filesystem::exists(file))
        throw UsageError(fmt::format("{} exists: continue that render with --resume {}, or remove it first", file, file));
    paths.output(file, "--checkpoint", /*image=*/false);
}

ResumedRender resume_checkpoint(const std::string& path, const RenderJob& job, const RenderIdentity& identity) {
    Checkpoint c = read_checkpoint(path);
    const std::string diff = c.info.identity.differences(identity, kIdentityFields, "the checkpoint", "this render");
    if (!diff.empty()) throw CheckpointError(fmt::format("{} is a checkpoint of another render; they differ in\n{}", path, diff));
    const uint64_t first = job.settings.first_sample;
    if (job.settings.spp > 0 && !PassSet::range(first, first + job.settings.spp).contains(c.info.passes))
        throw CheckpointError(fmt::format("{} holds passes {}, more than this render's {} (raise --spp to continue it)", path,
                                          c.info.passes.to_string(), PassSet::range(first, first + job.settings.spp).to_string()));
    if (c.info.passes.begin() < first)
        throw CheckpointError(fmt::format("{} holds passes {}, before --first-sample {}", path, c.info.passes.to_string(), first));
    return {std::move(c.film), c.info.passes, c.info.seconds};
}

void checkpoint_job(RenderJob& job, const std::string& path, const CheckpointInfo& info, const std::string& name) {
    job.settings.checkpoint = [path, info, name](RankGroup& parts, const Film& film, const PassSet& done, const RenderStats& st) {
        CheckpointInfo now = info;
        now.passes = done;
        now.seconds = info.seconds + st.seconds;
        try {
            write_checkpoint(path, parts, film, now);
            return true;
        } catch (const std::exception& e) {
            // The render goes on; the file keeps the last complete checkpoint.
            fmt::print(stderr, "pathlab: warning: {}: checkpoint not written: {}\n", name, e.what());
            return false;
        }
    };
}

std::string final_checkpoint_failure(const std::string& path, const RenderStats& s) {
    if (!s.last_checkpoint_failed) return "";
    // The image is made, but the checkpoint asked for does not hold this render's end.
    return fmt::format("the final checkpoint {} could not be written; it holds {}", path,
                       s.checkpoints > 0 ? "an earlier checkpoint of this render" : "what it held before");
}

}  // namespace pathlab

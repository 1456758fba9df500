// What `pathlab view` shows: one scene rendered progressively by an estimator (slot A) and, for
// an A/B view, by a second one at the same time (slot B), each restartable with another
// integrator or sampler. Each slot renders on a thread of its own through RenderJob (the same
// render as `pathlab SCENE -a ALG`, its film's mean published a few times a second), until its
// sample count or until it is restarted or stopped; a slot's images are numbered so the page
// fetches only new ones. With a reference image, each published image's RMSE against it is
// recorded with the time, the page's RMSE-versus-time curve; without one but with two slots,
// A's curve is the RMS difference of each image of A and B's newest.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "image/image.hpp"
#include "job/render_job.hpp"
#include "job/scene_choice.hpp"

namespace pathlab {

// One image a slot published: its film's mean after `spp` samples per pixel.
struct ViewFrame {
    uint64_t number = 0;  // 1, 2, ... within the slot's current render
    Image image;
    uint64_t spp = 0;
    double seconds = 0;   // since that render started (the scene and the integrator's preparation included)
    uint64_t samples = 0; // pixel samples (or light paths) taken
};

struct ViewSlotState {
    bool active = false;
    std::string algorithm, sampler;  // "independent" or "sobol"
    uint64_t render = 0;             // counts the slot's (re)starts
    std::string status;              // "rendering", "done", "stopped", "failed"
    std::string error;               // why it failed
    std::string output;              // the file written when the render ended, if any
    std::shared_ptr<const ViewFrame> frame;
    std::vector<std::pair<double, double>> rmse;  // (seconds, RMSE) per published image
};

// "independent" or "sobol" (a UsageError naming them otherwise).
SamplerKind sampler_or_usage_error(const std::string& name);

class ViewSession {
public:
    struct Options {
        SceneChoice scene;
        JobRequest request;  // the renders' settings; its algorithm and sampler are slot A's first
        std::optional<Image> reference;  // the same size as the renders
        std::string reference_name;
        std::string output;  // -o: written when a render of slot A ends (completed, restarted or stopped); may hold {algorithm}
        double publish_every = 0.25;  // seconds between published images
        // Messages for the user (a render that failed, an output written), from the render threads.
        std::function<void(const std::string&)> say;
    };
    // Builds the scene (shared by every render) and starts slot A; a UsageError for an unknown
    // algorithm or one that cannot render the scene.
    explicit ViewSession(Options options);
    ~ViewSession();  // stops both slots (writing slot A's output)
    ViewSession(const ViewSession&) = delete;
    ViewSession& operator=(const ViewSession&) = delete;

    static constexpr int kSlots = 2;
    // (Re)starts slot 0 (A) or 1 (B): a UsageError (and the slot unchanged) for an unknown
    // algorithm or sampler, or an integrator that refuses the scene.
    void start(int slot, const std::string& algorithm, const std::string& sampler);
    void stop(int slot);
    ViewSlotState slot(int slot) const;
    const SceneChoice& scene() const { return options_.scene; }
    int width() const { return width_; }
    int height() const { return height_; }
    const Options& options() const { return options_; }
    // Every integrator, with why it cannot render this scene ("" when it can).
    const std::vector<std::pair<std::string, std::string>>& algorithms() const { return algorithms_; }
    // Waits until slot's render is no longer rendering, or `seconds` pass; true if it ended.
    bool wait(int slot, double seconds) const;

private:
    struct Slot;
    void publish(int slot, uint64_t render, const Film& film, const RenderStats& stats);
    void record_rmse_locked(int slot);
    void stop_locked(std::unique_lock<std::mutex>& lock, int slot);

    Options options_;
    std::shared_ptr<const Scene> scene_;
    int width_ = 0, height_ = 0;
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;
    std::vector<std::unique_ptr<Slot>> slots_;
    std::vector<std::pair<std::string, std::string>> algorithms_;
};

}  // namespace pathlab

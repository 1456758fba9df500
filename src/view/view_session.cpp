#include "view/view_session.hpp"

#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "job/render_identity.hpp"
#include "job/usage_error.hpp"

namespace pathlab {

struct ViewSession::Slot {
    ViewSlotState state;
    std::atomic<bool> cancel{false};
    std::thread thread;
};

namespace {

// sqrt of the mean squared difference over pixels and channels.
double rms_difference(const Image& a, const Image& b) {
    double sum = 0;
    const size_t n = 3 * a.pixel_count();
    for (size_t i = 0; i < n; ++i) {
        const double d = double(a.data()[i]) - double(b.data()[i]);
        sum += d * d;
    }
    return n ? std::sqrt(sum / double(n)) : 0.0;
}

}  // namespace

SamplerKind sampler_or_usage_error(const std::string& name) {
    if (name == "independent") return SamplerKind::Independent;
    if (name == "sobol") return SamplerKind::Sobol;
    throw UsageError(fmt::format("unknown sampler '{}'. Valid samplers: independent, sobol", name));
}

ViewSession::ViewSession(Options options) : options_(std::move(options)) {
    for (int i = 0; i < kSlots; ++i) slots_.push_back(std::make_unique<Slot>());
    // The scene is built once, by a job of the first algorithm (which also checks it can render it).
    RenderJob first(options_.scene, options_.request);
    width_ = first.width(), height_ = first.height();
    scene_ = first.shared_scene();
    if (options_.reference && (options_.reference->width() != width_ || options_.reference->height() != height_))
        throw UsageError(fmt::format("the reference {} is {}x{}, the render {}x{} (give --resolution {}x{})", options_.reference_name,
                                     options_.reference->width(), options_.reference->height(), width_, height_,
                                     options_.reference->width(), options_.reference->height()));
    for (const IntegratorInfo& info : integrators())
        algorithms_.emplace_back(info.name, integrator_refusal(info, options_.scene.description, options_.request));
    start(0, first.integrator_info().name, options_.request.sampler == SamplerKind::Sobol ? "sobol" : "independent");
}

ViewSession::~ViewSession() {
    std::unique_lock lock(mutex_);
    for (int i = 0; i < kSlots; ++i) stop_locked(lock, i);
}

void ViewSession::start(int slot, const std::string& algorithm, const std::string& sampler) {
    if (slot < 0 || slot >= kSlots) throw UsageError(fmt::format("no slot {}", slot));
    JobRequest request = options_.request;
    request.algorithm = integrator_or_usage_error(algorithm).name;
    request.sampler = sampler_or_usage_error(sampler);
    // Checks the algorithm against the scene (a UsageError saying why it cannot render it).
    auto job = std::make_unique<RenderJob>(options_.scene, request, scene_);
    job->settings.width = width_, job->settings.height = height_;
    if (slot == 0 && !options_.output.empty()) job->outputs = {job->expand(options_.output)};

    std::unique_lock lock(mutex_);
    stop_locked(lock, slot);
    Slot& s = *slots_[size_t(slot)];
    s.cancel = false;
    const uint64_t render = s.state.render + 1;
    s.state = ViewSlotState{};
    s.state.active = true;
    s.state.algorithm = job->integrator_info().name;
    s.state.sampler = sampler;
    s.state.render = render;
    s.state.status = "rendering";
    job->settings.cancel = &s.cancel;
    job->settings.display_every = options_.publish_every;
    job->settings.display = [this, slot, render](const Film& film, const RenderStats& stats) { publish(slot, render, film, stats); };
    s.thread = std::thread([this, slot, render, job = std::move(job)]() mutable {
        std::string status = "done", error, written;
        try {
            const int w = job->width(), h = job->height();
            RenderResult result{make_film(w, h), {}};
            const RenderIdentity identity = render_identity(*job, w, h);
            result.stats = job->run_into(result.film);
            if (result.stats.interrupted) status = "stopped";
            if (!job->outputs.empty()) {
                job->write_outputs(result, 0, render_metadata(identity, result.stats.passes, result.stats.invalid_samples, result.stats.integrator));
                written = job->outputs.front();
                if (options_.say)
                    options_.say(fmt::format("{} ({}, {} spp) written", written, job->integrator_info().name, result.stats.spp));
            }
        } catch (const std::exception& e) {
            status = "failed", error = e.what();
            if (options_.say) options_.say(fmt::format("the render with {} failed: {}", job->integrator_info().name, error));
        }
        std::lock_guard lock(mutex_);
        Slot& me = *slots_[size_t(slot)];
        if (me.state.render != render) return;
        me.state.status = status, me.state.error = error, me.state.output = written;
        changed_.notify_all();
    });
}

void ViewSession::stop(int slot) {
    if (slot < 0 || slot >= kSlots) throw UsageError(fmt::format("no slot {}", slot));
    std::unique_lock lock(mutex_);
    stop_locked(lock, slot);
    slots_[size_t(slot)]->state.active = false;
    // The RMS difference of A and B means nothing without B.
    if (!options_.reference) slots_[0]->state.rmse.clear();
}

void ViewSession::stop_locked(std::unique_lock<std::mutex>& lock, int slot) {
    Slot& s = *slots_[size_t(slot)];
    if (!s.thread.joinable()) return;
    s.cancel = true;
    std::thread t = std::move(s.thread);
    lock.unlock();  // the render publishes (and ends) under the lock
    t.join();
    lock.lock();
}

void ViewSession::publish(int slot, uint64_t render, const Film& film, const RenderStats& stats) {
    auto frame = std::make_shared<ViewFrame>();
    frame->image = film.mean();
    frame->spp = stats.spp;
    frame->seconds = stats.seconds;
    frame->samples = stats.samples;
    std::lock_guard lock(mutex_);
    Slot& s = *slots_[size_t(slot)];
    if (s.state.render != render) return;
    frame->number = s.state.frame ? s.state.frame->number + 1 : 1;
    s.state.frame = std::move(frame);
    record_rmse_locked(slot);
    changed_.notify_all();
}

void ViewSession::record_rmse_locked(int slot) {
    ViewSlotState& s = slots_[size_t(slot)]->state;
    // A curve of at most kMaxCurve points: every second one dropped when it is full.
    constexpr size_t kMaxCurve = 4096;
    const auto add = [](std::vector<std::pair<double, double>>& curve, double t, double e) {
        if (curve.size() >= kMaxCurve) {
            for (size_t i = 0; 2 * i < curve.size(); ++i) curve[i] = curve[2 * i];
            curve.resize((curve.size() + 1) / 2);
        }
        curve.emplace_back(t, e);
    };
    if (options_.reference) {
        add(s.rmse, s.frame->seconds, rms_difference(s.frame->image, *options_.reference));
        return;
    }
    // A against B's newest image: on A's curve, at the time of A's image.
    const ViewSlotState& a = slots_[0]->state;
    const ViewSlotState& b = slots_[1]->state;
    if (slot != 0 || !b.frame || !b.active) return;
    add(slots_[0]->state.rmse, s.frame->seconds, rms_difference(a.frame->image, b.frame->image));
}

ViewSlotState ViewSession::slot(int slot) const {
    std::lock_guard lock(mutex_);
    return slots_.at(size_t(slot))->state;
}

bool ViewSession::wait(int slot, double seconds) const {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, std::chrono::duration<double>(seconds),
                             [&] { return slots_.at(size_t(slot))->state.status != "rendering"; });
}

}  // namespace pathlab

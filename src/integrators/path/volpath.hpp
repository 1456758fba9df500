// volpath: volumetric path tracing (Mitsuba 3's name), pt-mis extended to participating media.
// docs/volumes.md explains the estimator; src/media/medium.hpp its free-flight sampling and
// transmittance.
#pragma once

#include <memory>

#include "integrators/integrator.hpp"

namespace pathlab {

struct VolpathSettings {
    // Multiple importance sampling between light sampling and phase/BSDF sampling. Without it,
    // next-event estimation alone finds the lights (emission that a phase or BSDF sample
    // finds counts only after a Dirac lobe): the benchmark's comparison.
    bool mis = true;
    // In a scene without media, pt-mis's loop (pt_mis.hpp) renders: the same image bit for bit
    // (volpath's own loop draws pt-mis's numbers and does its arithmetic, tested with this off),
    // without the walk's bookkeeping (measured at up to 15%, docs/volumes.md, "Cost").
    bool pt_mis_without_media = true;
    // > 1: free flights and transmittances in every medium by delta and ratio tracking against
    // this multiple of the majorant (null collisions in homogeneous media too): another
    // free-flight strategy with the same expectation, for the tests.
    float majorant_factor = 1;
};

// volpath for the transport the options ask for (IntegratorOptions::spectral).
std::unique_ptr<Integrator> make_volpath(const IntegratorOptions& options, VolpathSettings settings = {});

}  // namespace pathlab

// SPDX-License-Identifier: BSD-2-Clause
// The forward engine: closed-loop error-state EKF over one time-ordered stream of IMU samples and GNSS epochs.
// Mechanization + covariance prediction at the configured rate, ZUPT (form D or F) during detected stance,
// single-differenced (or undifferenced) pseudorange and Doppler updates with innovation-based fault rejection.
// No file I/O, no logging: inputs in, trajectory + counts out. Derivations: docs/fusion.md. The entry point only:
// its option and result types are in fusion/engine_types.hpp, which the filter's parts include instead of this.
#pragma once

#include "core/expected.hpp"
#include "fusion/engine_types.hpp"

namespace pednav::fusion {

/// Run the forward filter. Fails with a clear message on inputs that cannot be processed (no IMU samples,
/// no GNSS overlap in tc mode, no initial still period, ...).
Expected<EngineResult> run_forward(const EngineInputs& inputs, const EngineOptions& options);

}  // namespace pednav::fusion

// SPDX-License-Identifier: BSD-2-Clause
// Initialization of the engine's state (docs/fusion.md §8, docs/ins.md §6): the first still period (the levelling
// window), the initial gyro bias from its mean rate when that is consistent with the turn-on prior (eq. 6.1), and the
// heading from motion — an INS/ZUPT pass with yaw 0 fitted to the GNSS epoch solutions at growing walked distances.
// Internal to the engine.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.hpp"
#include "fusion/engine_types.hpp"
#include "fusion/gnss_update.hpp"
#include "ins/alignment.hpp"
#include "ins/imu.hpp"
#include "ins/zupt_detector.hpp"

namespace pednav::fusion {

/// Shortest stance run that can level the IMU [s]: the engine starts at the first one.
inline constexpr double kMinLevellingWindowS = 0.2;
/// Shortest levelling window whose mean rate may become the initial gyro bias [s] (docs/ins.md §6).
inline constexpr double kMinBiasWindowS = 2.0;
/// Sanity bounds of the levelling window. The window is a stance the configured detector found, so stillness is the
/// detector's call; these only refuse a window that is plainly not still (1 rad/s rate or 2 m/s² specific-force
/// scatter per axis, |mean f| more than 2 m/s² from gravity), whatever detector and thresholds the user chose; the
/// 0.1 s floor is below kMinLevellingWindowS, which the window already meets.
inline constexpr ins::StillnessOptions kLevellingSanity{1.0, 2.0, 2.0, 0.1};

/// IMU samples [begin, end) of the first stance run of >= kMinLevellingWindowS; nullopt if there is none.
std::optional<std::pair<size_t, size_t>> first_still_period(const std::vector<ins::ImuSample>& samples,
                                                            const std::vector<ins::ZuptDecision>& decisions);

/// The IMU errors to start from: the levelling window's mean rate as the gyro bias when the window is at least
/// kMinBiasWindowS long and its d² against the spec's turn-on σ (docs/ins.md eq. 6.1) is inside the χ²(3) gate;
/// else zero. Fills sum.still_gyro_bias_d2 and sum.initial_gyro_bias_deg_per_h; appends why not to `how`.
ins::ImuErrors initial_imu_errors(const ins::Levelling& level, const ins::ImuSpec& spec, EngineSummary& sum,
                                  std::string& how);

/// Heading from motion: yaw [rad] of the body at the start and its σ [rad].
struct HeadingFromMotion {
  double yaw_rad = 0.0;
  double sigma_yaw_rad = 0.0;
};

/// Heading from motion (docs/fusion.md §8, tc mode without a configured yaw): the INS/ZUPT track from `start` with
/// yaw 0 (nav_yaw0, imu0), and at each milestone D, 2D, 4D, … of distance walked a 2D fit of that track onto the GNSS
/// epoch solutions over the same span; the pass stops at the first fit with σ_yaw ≤ 3° on a track ≥ 10 m from its
/// start, or after five further milestones. Fills the heading fields of `sum` and appends the fit to `how`.
Expected<HeadingFromMotion> heading_from_motion(const EngineInputs& in, const EngineOptions& o,
                                                const std::vector<ins::ZuptDecision>& decisions,
                                                const GnssEpochUpdater& gnss, size_t start,
                                                const ins::NavState& nav_yaw0, const ins::ImuErrors& imu0,
                                                EngineSummary& sum, std::string& how);

}  // namespace pednav::fusion

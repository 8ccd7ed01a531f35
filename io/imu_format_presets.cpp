// SPDX-License-Identifier: BSD-2-Clause
// Built-in IMU format presets. The text is identical to datasets/imu_formats/<name>.yaml (a test checks it).
#include "io/imu_csv.hpp"

namespace pednav::io {
namespace {
struct Preset {
  const char* name;
  const char* yaml;
};
const Preset kPresets[] = {
    {"pyshoe", R"yaml(# PyShoe Vicon CSV export: ../shared/datasets/foot_pyshoe_vicon/csv/<trial>.csv (LORD 3DM-GX5-25, 200 Hz).
# Columns: t_s, acc_x_mps2, acc_y_mps2, acc_z_mps2, gyr_x_radps, gyr_y_radps, gyr_z_radps, gt_x_m, gt_y_m, gt_z_m, zv_label
# Relative seconds (no GPS time) -> GPS week 0, tow = log seconds. Sensor z points down at rest.
# Gyro full scale not checked: the running trial reaches 9.7 rad/s (556 deg/s), so the device was not at the
# +-300 deg/s default and the configured range is not documented. Accel range assumed the +-8 g default.
delimiter: ","
header_lines: 1
time: {base: relative, column: 0, unit: s}
gyro: {columns: [4, 5, 6], unit: rad_per_s, signs: [1, 1, 1]}
accel: {columns: [1, 2, 3], unit: mps2, signs: [1, 1, 1], full_scale_g: 8}
stance: {column: 10}   # zv_label: PyShoe's SHOE labels at its per-trial tuned threshold (zupt.detector: labels)
mounting_rpy_deg: [0, 0, 0]
max_gap_s: 0.05
)yaml"},
    {"xio_ngimu", R"yaml(# x-io NGIMU CSV (Gait-Tracking): ../shared/datasets/foot_xio_ngimu_loops/{short,long}_walk.csv, ~400 Hz.
# Columns: Time (s), Gyroscope X/Y/Z (deg/s), Accelerometer X/Y/Z (g). Device seconds -> GPS week 0.
# Duplicate rows (repeated time stamp) are dropped and counted; gaps up to ~18 ms occur (lost packets).
# Full scale from the NGIMU user manual: +-2000 deg/s, +-16 g.
delimiter: ","
header_lines: 1
time: {base: relative, column: 0, unit: s}
gyro: {columns: [1, 2, 3], unit: deg_per_s, signs: [1, 1, 1], full_scale_deg_per_s: 2000}
accel: {columns: [4, 5, 6], unit: g, signs: [1, 1, 1], full_scale_g: 16}
mounting_rpy_deg: [0, 0, 0]
max_gap_s: 0.05
)yaml"},
    {"lord_sensorconnect", R"yaml(# LORD SensorConnect CSV export: ../shared/datasets/foot_lord_gcp_hallway/SensorConnectData_NN.csv (3DM-GX5-25, 200 Hz).
# Columns: Time (s), scaledAccelX/Y/Z (g), scaledGyroX/Y/Z (rad/s), scaledMagX/Y/Z (Gauss), roll, pitch, yaw (rad).
# Device seconds -> GPS week 0. Full scale not checked: these logs reach 14.4 rad/s and 124 m/s^2 (norms), beyond the
# 3DM-GX5-25 defaults (+-300 deg/s, +-8 g), so the device ranges were set higher and are not documented.
delimiter: ","
header_lines: 1
time: {base: relative, column: 0, unit: s}
gyro: {columns: [4, 5, 6], unit: rad_per_s, signs: [1, 1, 1]}
accel: {columns: [1, 2, 3], unit: g, signs: [1, 1, 1]}
mag: {columns: [7, 8, 9], unit: gauss, signs: [1, 1, 1]}
mounting_rpy_deg: [0, 0, 0]
max_gap_s: 0.05
)yaml"},
};
}  // namespace

std::vector<std::string> imu_format_preset_names() {
  std::vector<std::string> v;
  for (const auto& p : kPresets) v.emplace_back(p.name);
  return v;
}

std::string imu_format_preset_yaml(const std::string& name) {
  for (const auto& p : kPresets) {
    if (name == p.name) return p.yaml;
  }
  return {};
}

}  // namespace pednav::io

// SPDX-License-Identifier: BSD-2-Clause
// Trajectory readers on the real reference files of ../shared/datasets.
#include <gtest/gtest.h>

#include "core/geodesy.hpp"
#include "io/trajectory_io.hpp"
#include "tests/support/data.hpp"

namespace pednav::io {
namespace {

using test::shared_data;

TEST(TrajectoryData, GalwayGgaRtkFixedEpochs) {
  const std::string path = shared_data("gnss_ublox_m8p_walk_galway/reference_nmea/rover-20181004-1532.nmea");
  PEDNAV_REQUIRE_DATA(path);
  TrajectoryReadOptions o;
  o.nmea_qualities = {4};
  auto f = read_trajectory(path, o);
  ASSERT_TRUE(f) << f.error().message;
  // SOURCE.md: 552 RTK-fixed of 1180 GGA; the rest are float/DGPS/single.
  EXPECT_EQ(f->trajectory.points.size(), 552u);
  EXPECT_EQ(f->skipped_quality, 1180 - 552);
  EXPECT_EQ(f->skipped_checksum, 0);
  // Within 30 m of the base (RTCM 1005), ellipsoidal height ~ 66 m.
  const Eigen::Vector3d base(3774085.6456, -601662.5769, 5089316.3970);
  for (const auto& p : f->trajectory.points) ASSERT_LT((p.p - base).norm(), 40.0);
  EXPECT_NEAR(geodetic_from_ecef(f->trajectory.points.front().p).h_m, 65.0, 5.0);
}

TEST(TrajectoryData, SeptentrioRtkPosIsAtTheSurveyedRover) {
  const std::string path = shared_data("gnss_septentrio_static_shortbaseline/rover_rtk.pos");
  PEDNAV_REQUIRE_DATA(path);
  auto f = read_trajectory(path, {});
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->trajectory.points.size(), 301u);
  const Eigen::Vector3d rover(-3817681.3807, 3562839.9785, 3650158.3760);  // rover_position.txt
  EXPECT_LT((f->trajectory.points.front().p - rover).norm(), 0.05);
}

TEST(TrajectoryData, SpirentTruthCsvUsesWeekCycles) {
  const std::string path = shared_data("rtklib_samples/instinct_spirent_rtk_GE/Rover-dynamic_PVA_Spirent.csv");
  PEDNAV_REQUIRE_DATA(path);
  auto f = read_trajectory(path, {});
  ASSERT_TRUE(f) << f.error().message;
  EXPECT_EQ(f->trajectory.points.front().t, GpsTime::from_week_tow(2244, 36000.0));
  EXPECT_GT(f->trajectory.points.size(), 6000u);  // 10 Hz for 10 min
}

}  // namespace
}  // namespace pednav::io

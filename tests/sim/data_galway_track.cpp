// Along-a-track mode on the real Galway walk (datasets/galway_track.yaml): the synthesized foot IMU is aligned in
// GPST with the real GNSS, the foot truth follows the RTK track, and the written config.yaml runs `pednav gnss`
// on the REAL rover/base/nav files with the GGA track as reference.
#include <gtest/gtest.h>

#include "eval/trajectory.hpp"
#include "io/config.hpp"
#include "io/scenario_config.hpp"
#include "io/simulate_command.hpp"
#include "io/trajectory_io.hpp"
#include "tests/sim/fixtures.hpp"
#include "tests/support/data.hpp"

namespace pednav {
namespace {

constexpr double kMaxFootToTrackRms_m = 1.5;  // foot under the walker vs the antenna track (half a stride + smoothing)

TEST(GalwayTrack, FootImuAlongTheRealRtkTrack) {
  const std::string nmea = test::shared_data("gnss_ublox_m8p_walk_galway/reference_nmea/rover-20181004-1532.nmea");
  PEDNAV_REQUIRE_DATA(nmea);
  auto sc = io::load_scenario(test::source_path("datasets/galway_track.yaml"));
  ASSERT_TRUE(sc.has_value()) << (sc ? "" : sc.error().message);
  const std::string dir = test::temp_dir("galway_track");
  auto sum = io::run_simulate_command(*sc, dir);
  ASSERT_TRUE(sum.has_value()) << (sum ? "" : sum.error().message);
  EXPECT_GT(sum->strides, 150);
  EXPECT_EQ(sum->rover_epochs, 0);  // the GNSS is the real one

  auto cfg = io::load_run_config(dir + "/config.yaml");
  ASSERT_TRUE(cfg.has_value()) << (cfg ? "" : cfg.error().message);
  EXPECT_NE(cfg->gnss.rover_obs.find("rover-20181004-1532.obs"), std::string::npos);
  EXPECT_EQ(cfg->reference.format, "nmea");

  io::TrajectoryReadOptions fixed;
  fixed.nmea_qualities = {4};
  auto ref = io::read_trajectory(nmea, fixed);
  auto foot = io::read_trajectory(dir + "/truth.csv", {});
  ASSERT_TRUE(ref && foot);
  // GPST alignment: the IMU starts on the first whole second of the track.
  const GpsTime t_imu = foot->trajectory.points.front().t;
  EXPECT_EQ(t_imu.ns() % kNsPerS, 0);
  EXPECT_LT(t_imu - ref->trajectory.points.front().t, 60.0);
  auto ev = eval::compare(foot->trajectory, ref->trajectory, {});
  ASSERT_TRUE(ev.has_value()) << (ev ? "" : ev.error().message);
  std::printf("galway_track: foot truth vs RTK-fixed GGA: %d epochs, horizontal RMS %.2f m\n", ev->epochs_compared,
              ev->horizontal_rms_m);
  EXPECT_GT(ev->epochs_compared, 20000);
  EXPECT_LT(ev->horizontal_rms_m, kMaxFootToTrackRms_m);
}

}  // namespace
}  // namespace pednav

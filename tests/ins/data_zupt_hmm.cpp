// HMM zero-velocity detector (seed 002; docs/zupt.md §3) on the x-io long loop with the committed configuration
// datasets/foot/xio_long.yaml, detector switched to hmm: two mapping rules measured on this log.
#include <gtest/gtest.h>

#include <cmath>

#include "io/config.hpp"
#include "io/hmm_model_io.hpp"
#include "io/imu_csv.hpp"
#include "ins/zupt_detector.hpp"
#include "tests/support/data.hpp"

namespace pednav::ins {
namespace {

// The walk ends at 56.1-56.4 s with a short last step, then the foot rests until the log ends at 70.7 s. That rest
// is one merged observation which the trained cycle (no D -> D) decodes as push-off: without `hmm_rest_s` the
// last 14 s have no ZUPT (INS end-point error 186 m). Every sample of the last kFinalRest_s must be stance.
constexpr double kFinalRest_s = 10.0;

TEST(DataZuptHmm, XioLongRestIsStanceAndStanceIsNearZeroRate) {
  PEDNAV_REQUIRE_DATA(test::shared_data("foot_xio_ngimu_loops/long_walk.csv"));
  auto cfg = io::load_run_config(test::source_path("datasets/foot/xio_long.yaml"));
  ASSERT_TRUE(cfg) << cfg.error().message;
  auto log = io::read_imu_csv(cfg->imu.file, cfg->imu.format);
  ASSERT_TRUE(log) << log.error().message;
  const auto& s = log->samples;
  ZuptDetectorOptions o = io::zupt_detector_options(cfg->zupt);
  o.detector = "hmm";
  o.hmm_refine_factor = 0.0;  // the decoded stance itself
  const HmmDetection h = detect_gait_hmm(s, o);
  ASSERT_EQ(h.decisions.size(), s.size());
  int final_rest_moving = 0, stance_off_zero = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    if (s.back().t - s[k].t < kFinalRest_s && !h.decisions[k].stance) ++final_rest_moving;
    // Stance only in the stance grades (here 8 and 9: |smoothed rate| < one grade width). Without that rule
    // the first, half step decodes its grade-13 swing extreme (5 rad/s) as D and 59 swing samples become stance.
    if (h.decisions[k].stance && std::abs(h.decisions[k].statistic) >= o.hmm_observations.grade_width_radps) {
      ++stance_off_zero;
    }
  }
  EXPECT_EQ(final_rest_moving, 0);
  EXPECT_EQ(stance_off_zero, 0);
}

}  // namespace
}  // namespace pednav::ins

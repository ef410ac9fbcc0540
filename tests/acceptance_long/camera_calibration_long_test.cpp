// SPDX-License-Identifier: Apache-2.0
// Acceptance (issue H3, part 1): `hrcsense calibrate` on the moving UR5 cell (D435 noise, the
// person coming and going) finds the simulator's true camera pose within 5 mm and 0.2 degrees
// from a told pose off by 0.1–0.2 m and 7.5–15 degrees, in 20 trials with fixed seeds (each its
// own error and its own sensor noise); and from a .bag that `hrcsense record` made of the same
// cell (all its 1000 frames) it gives the live result within 0.5 mm and 0.02 degrees.

#include "../support/calibration_runs.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace hrcsense {
namespace {

// Trials first..last, each within 5 mm and 0.2 degrees, each trial's error printed. Four tests of
// five trials, so that ctest spreads them over the cores. CI runs trials 1-5 (its 40 minutes);
// HRCSENSE_ALL_CALIBRATION_TRIALS=1 runs 6-20 too, as docs/CALIBRATION.md's figures were made.
bool all_trials() {
  const char* all = std::getenv("HRCSENSE_ALL_CALIBRATION_TRIALS");
  return all != nullptr && std::string(all) == "1";
}

void calibration_trials(unsigned first, unsigned last) {
  const Pose truth = test::calib_scene_pose("cell-ur5-moving.yaml");
  const std::string out = std::string(::testing::TempDir()) + "calibration_trial_" + std::to_string(first) + ".yaml";
  for (unsigned seed = first; seed <= last; ++seed) {
    const Pose told = test::calib_random_error(truth, seed, 0.1, 0.2, 7.5, 15.0);
    const test::CliResult run =
        test::cli("calibrate --config " + test::scene_path("cell-ur5-moving.yaml") + " --out " + out +
                  " --set sim.color=false --set source.seed=" + std::to_string(seed) + " " +
                  test::calib_pose_sets(truth, told));
    ASSERT_EQ(run.exit_code, 0) << "trial " << seed << ": " << run.out;
    const std::optional<Pose> calibrated = test::calib_printed_pose(run.out);
    ASSERT_TRUE(calibrated) << run.out;
    const double error_mm = translation_between_m(*calibrated, truth) * 1000.0;
    const double error_deg = rotation_between_deg(*calibrated, truth);
    std::printf("trial %2u: told %.3f m %.2f deg off -> %.2f mm %.3f deg\n", seed, translation_between_m(told, truth),
                rotation_between_deg(told, truth), error_mm, error_deg);
    EXPECT_LT(error_mm, 5.0) << "trial " << seed;
    EXPECT_LT(error_deg, 0.2) << "trial " << seed;
  }
}

TEST(CameraCalibrationLong, TrialsOneToFiveLandWithinFiveMillimetresAndTwoTenthsOfADegree) { calibration_trials(1, 5); }
TEST(CameraCalibrationLong, TrialsSixToTenLandWithinFiveMillimetresAndTwoTenthsOfADegree) {
  if (!all_trials()) GTEST_SKIP() << "trials 6-20 run with HRCSENSE_ALL_CALIBRATION_TRIALS=1";
  calibration_trials(6, 10);
}
TEST(CameraCalibrationLong, TrialsElevenToFifteenLandWithinFiveMillimetresAndTwoTenthsOfADegree) {
  if (!all_trials()) GTEST_SKIP() << "trials 6-20 run with HRCSENSE_ALL_CALIBRATION_TRIALS=1";
  calibration_trials(11, 15);
}
TEST(CameraCalibrationLong, TrialsSixteenToTwentyLandWithinFiveMillimetresAndTwoTenthsOfADegree) {
  if (!all_trials()) GTEST_SKIP() << "trials 6-20 run with HRCSENSE_ALL_CALIBRATION_TRIALS=1";
  calibration_trials(16, 20);
}

TEST(CameraCalibrationLong, ARecordedBagGivesTheLiveResult) {
  const std::string dir = ::testing::TempDir();
  const std::string scene = test::scene_path("cell-ur5-moving.yaml");
  const Pose truth = test::calib_scene_pose("cell-ur5-moving.yaml");
  const std::string sets = test::calib_pose_sets(truth, test::calib_random_error(truth, 99, 0.1, 0.2, 7.5, 15.0));
  const test::CliResult live = test::cli("calibrate --config " + scene + " --out " + dir + "calib_live.yaml " + sets);
  ASSERT_EQ(live.exit_code, 0) << live.out;
  const test::CliResult record =
      test::cli("record --config " + scene + " --out " + dir + "calib_cell.bag --overwrite " + sets);
  ASSERT_EQ(record.exit_code, 0) << record.out;
  const test::CliResult replay =
      test::cli("calibrate --config " + scene + " --out " + dir + "calib_bag.yaml " + sets +
                " --set source.type=bag --set source.path=" + dir + "calib_cell.bag --set robot.state.source=recorded");
  ASSERT_EQ(replay.exit_code, 0) << replay.out;
  const std::optional<Pose> from_live = test::calib_printed_pose(live.out);
  const std::optional<Pose> from_bag = test::calib_printed_pose(replay.out);
  ASSERT_TRUE(from_live && from_bag);
  EXPECT_LT(translation_between_m(*from_bag, *from_live), 0.0005);
  EXPECT_LT(rotation_between_deg(*from_bag, *from_live), 0.02);
  std::printf("bag vs live: %.4f mm, %.5f deg\n", translation_between_m(*from_bag, *from_live) * 1000.0,
              rotation_between_deg(*from_bag, *from_live));
}

}  // namespace
}  // namespace hrcsense

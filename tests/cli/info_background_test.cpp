// SPDX-License-Identifier: Apache-2.0
// `hrcsense info --config FILE` learns the background a run would start with (or loads
// background.path) and prints its unknown share, checked against a scene whose unseen part
// is counted by hand.
#include "../support/cli_folder.hpp"
#include "hrcsense/camera.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace {

using Outcome = hrcsense::test::CliOutcome;

// A 424x240 camera at the base origin looking along +z (identity pose) at a wall 2 m away that
// fills only the image columns 106..423: its left edge lies half-way between the rays of columns
// 105 and 106, x = 2 (105.5 − ppx) / fx, and its side face there looks away from the camera
// (x −, the camera sits at x 0 to its right). Columns 0..105 see nothing and are never valid, so
// their background is unknown: 106 · 240 = 25440 of 101760 pixels, 0.25. The ideal sensor
// without the left band leaves no other pixel unmeasured.
class InfoBackground : public hrcsense::test::CliFolder {
 protected:
  static constexpr int kUnseenColumns = 106;
  std::string write_scene() const {
    const hrcsense::Intrinsics in = *hrcsense::d435_depth_intrinsics(424, 240);
    const double edge_x_m = 2.0 * (kUnseenColumns - 0.5 - static_cast<double>(in.ppx)) / static_cast<double>(in.fx);
    char wall[160];
    std::snprintf(wall, sizeof wall, "        - box: {min: [%.6f, -10, 2.0], max: [10, 10, 2.1]}\n", edge_x_m);
    return write("half_wall.yaml",
                 "source: {type: sim, seed: 1}\n"
                 "sim: {width: 424, height: 240, frames: 30, noise: false, left_band: false, color: false}\n"
                 "camera:\n"
                 "  T_base_camera: {translation_m: [0, 0, 0], rotation_rpy_deg: [0, 0, 0]}\n"
                 "filters: {preset: none}\n"
                 "background: {frames: 12}\n"
                 "scene:\n"
                 "  objects:\n"
                 "    - name: wall\n"
                 "      static: true\n"
                 "      shapes:\n" +
                     std::string(wall));
  }
  static std::string expected_share() {
    const int unseen = kUnseenColumns * 240;
    char text[128];
    std::snprintf(text, sizeof text, "unknown_background_share %.4f (%d of %d px; 0 unsettled)",
                  static_cast<double>(unseen) / (424.0 * 240.0), unseen, 424 * 240);
    return text;
  }
};

TEST_F(InfoBackground, LearntBackgroundReportsTheUnseenShare) {
  const std::string scene = write_scene();
  const Outcome outcome = run("info --config " + scene);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_NE(outcome.out.find("background: learnt by frame 11 (0 batch(es) refused before), 424x240; " +
                             expected_share()),
            std::string::npos)
      << outcome.out;
  EXPECT_NE(expected_share().find("0.2500"), std::string::npos);  // the hand count above
}

TEST_F(InfoBackground, LoadedBackgroundReportsTheSameShare) {
  const std::string scene = write_scene();
  const Outcome learnt = run("run --config " + scene + " --frames 13 --set background.path=bg.bin --out run.jsonl");
  ASSERT_EQ(learnt.exit_code, 0) << learnt.err;
  const Outcome outcome = run("info --config " + scene + " --set background.path=bg.bin");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_NE(outcome.out.find("background: loaded from bg.bin, 424x240; " + expected_share()), std::string::npos)
      << outcome.out;
}

TEST_F(InfoBackground, FramesBoundTheLearning) {
  const std::string scene = write_scene();
  const Outcome outcome = run("info --config " + scene + " --frames 5");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_NE(outcome.out.find("background: not learnt in 5 frame(s), 0 batch(es) refused\n"), std::string::npos)
      << outcome.out;
}

}  // namespace

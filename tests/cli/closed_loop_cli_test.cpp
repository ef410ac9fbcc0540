// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` in closed loop (robot.trajectory.follow_link): the simulated arm takes the
// speed scale of each result written, as an arm whose slider the link sets. Unpaced, each frame
// is rendered once the one before was decided, so frame j's arm runs at frame j−1's scale: the
// frame's robot_speed_fraction (the `sim` state's reading) is the scale written one line before.

#include "../support/cli_folder.hpp"
#include "../support/sanitized.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>
#include <string>

namespace {

using nlohmann::json;

class ClosedLoopCli : public hrcsense::test::CliFolder {};

TEST_F(ClosedLoopCli, EachFrameRunsAtTheScaleWrittenForTheOneBefore) {
  std::string args = std::string("run --config '") + HRCSENSE_SOURCE_DIR + "/config/cell-ur5-moving.yaml' ";
  if (hrcsense::test::kSanitized) args += "--set sim.width=424 --set sim.height=240 ";
  args += "--set robot.trajectory.follow_link=true --frames 300 --out out.jsonl";
  const hrcsense::test::CliOutcome outcome = run(args);
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  std::istringstream in(hrcsense::test::read_text(dir_ / "out.jsonl"));
  int frames = 0, checked = 0, slowed = 0;
  double previous_scale = 1.0;  // nothing sent before frame 0: the arm starts at full speed
  for (std::string line; std::getline(in, line);) {
    const json j = json::parse(line);
    if (j.value("type", "") != "frame") continue;  // `verdict` lines stand for no frame
    ++frames;
    ASSERT_TRUE(j["robot_speed_fraction"].is_number()) << line.substr(0, 200);
    const double fraction = j["robot_speed_fraction"].get<double>();
    EXPECT_NEAR(fraction, previous_scale, 1e-6) << "frame " << j["frame"];
    ++checked;
    slowed += fraction < 1.0 ? 1 : 0;
    previous_scale = j["speed_scale"].get<double>();
  }
  EXPECT_EQ(frames, 300);
  EXPECT_EQ(checked, 300);
  EXPECT_GT(slowed, 10);  // the person beside the arm slowed or stopped it
}

}  // namespace

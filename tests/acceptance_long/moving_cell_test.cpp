// SPDX-License-Identifier: Apache-2.0
// Acceptance of the self-filter on config/cell-ur5-moving.yaml, end to end through the tool
// (the full sensor model, the sdk filters, 1000 frames, the arm moving from frame 0): the
// simulator's ground truth says which source pixel each measured contact lies on
// (truth.contact_label), so the expectations are independent of the self-filter's code.
// Release builds only, under the ctest label `long` (docs/ROBOT.md, "Self-filter").

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <utility>
#include <string>
#include <vector>

namespace {

struct FrameLine {
  int64_t frame = 0;
  std::string verdict;
  std::string reason_code;
  std::string label;  ///< truth.contact_label, empty when null
  bool valid = false;
};

std::string moving_cell_path() { return std::string(HRCSENSE_SOURCE_DIR) + "/config/cell-ur5-moving.yaml"; }

std::vector<FrameLine> run_moving_cell(const std::string& extra, const std::string& name,
                                       const std::string& config = moving_cell_path()) {
  const std::string out = std::string(::testing::TempDir()) + "moving_cell_" + name + ".jsonl";
  const std::string command = std::string(HRCSENSE_CLI) + " run --config " + config + " " + extra + " --out " + out +
                              " 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  std::vector<FrameLine> frames;
  std::ifstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j.at("type") != "frame") continue;
    FrameLine f;
    f.frame = j.at("frame").get<int64_t>();
    f.verdict = j.at("verdict").get<std::string>();
    f.reason_code = j.at("reason_code").get<std::string>();
    f.valid = j.at("valid").get<bool>();
    const nlohmann::json& label = j.at("truth").at("contact_label");
    if (!label.is_null()) f.label = label.get<std::string>();
    frames.push_back(f);
  }
  std::remove(out.c_str());
  return frames;
}

TEST(MovingCellAcceptance, NoContactOnTheArmWithTheSelfFilterAndManyWithout) {
  const std::vector<FrameLine> on = run_moving_cell("", "on");
  ASSERT_EQ(on.size(), 1000U);
  int robot_on = 0;
  for (const FrameLine& f : on) robot_on += f.label == "robot" ? 1 : 0;
  EXPECT_EQ(robot_on, 0);
  // The arm moves from frame 0 and nobody else is in view before frame 100: learning must have
  // finished with the first batch, while the arm moved.
  EXPECT_FALSE(on[99].valid);
  EXPECT_TRUE(on[100].valid) << on[100].reason_code;

  const std::vector<FrameLine> off = run_moving_cell("--set self_filter.enabled=false", "off");
  ASSERT_EQ(off.size(), 1000U);
  int robot_off = 0;
  for (const FrameLine& f : off) robot_off += f.label == "robot" ? 1 : 0;
  EXPECT_GT(robot_off, 0) << "without the self-filter the arm should be its own contact";

  // After the person has gone (frame 600 on) the cell holds only the moving arm: with the
  // self-filter nothing stops it, without it the arm is inside itself in every frame.
  int stops_on = 0, inside_off = 0;
  for (size_t i = 600; i < 1000; ++i) {
    stops_on += on[i].verdict == "stop" ? 1 : 0;
    inside_off += off[i].reason_code == "inside_robot" ? 1 : 0;
  }
  EXPECT_EQ(stops_on, 0);
  EXPECT_EQ(inside_off, 400);
}

TEST(MovingCellAcceptance, LearningFinishesWhileTheArmMovesWithoutFilters) {
  // Without filters every pixel the arm sweeps changes by tens of centimetres during learning;
  // masked as the robot's, they neither count as motion nor become background.
  const std::vector<FrameLine> frames = run_moving_cell("--set filters.preset=none --frames 200", "none");
  ASSERT_EQ(frames.size(), 200U);
  EXPECT_EQ(frames[99].reason_code, "learning_background");
  EXPECT_TRUE(frames[100].valid) << frames[100].reason_code;
}

// The same cell with the swing 2.75 times as fast (1.1 s → 0.4 s: the flange at about 2.9 m/s).
// Moving up to about 10 cm a frame, largely along the view, the arm's depth changes by less
// than the temporal filter's delta, so the filtered image shows it where it was, blended over
// about 1.5 frames: one pose is not enough, the default three are.
TEST(MovingCellAcceptance, AFastArmNeedsThePosesOfThePastFrames) {
  std::ifstream in(moving_cell_path());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"t_s: 1.35,", "t_s: 0.65,"},
                                 {"t_s: 1.6,", "t_s: 0.9,"}, {"t_s: 2.7,", "t_s: 1.3,"}}) {
    const size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
  }
  const std::string path = std::string(::testing::TempDir()) + "cell-ur5-fast.yaml";
  std::ofstream(path) << text;
  const auto stops_after_person = [](const std::vector<FrameLine>& frames) {
    int stops = 0;
    for (size_t i = 600; i < frames.size(); ++i) stops += frames[i].verdict == "stop" ? 1 : 0;
    return stops;
  };
  const std::vector<FrameLine> three = run_moving_cell("", "fast3", path);
  const std::vector<FrameLine> one = run_moving_cell("--set self_filter.memory_frames=1", "fast1", path);
  std::remove(path.c_str());
  ASSERT_EQ(three.size(), 1000U);
  ASSERT_EQ(one.size(), 1000U);
  EXPECT_EQ(stops_after_person(three), 0);
  EXPECT_GT(stops_after_person(one), 50) << "the arm's lagging image should be taken for an intruder";
}

}  // namespace

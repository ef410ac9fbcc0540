// SPDX-License-Identifier: Apache-2.0
// The controller's robot_mode and safety_mode (RobotStatus) are reported, never decided on: a run
// whose robot state says idle, protective stop or safeguard stop has exactly the verdicts of the
// same run without a status, and the summary counts the frames and the mode changes.

#include "fake_scene.hpp"

#include "hrcsense/robot_state.hpp"

#include <gtest/gtest.h>

#include <mutex>
#include <vector>

namespace hrcsense {
namespace {

using test::after_learning;
using test::CollectingSink;
using test::fake_params;
using test::FakeSource;
using test::Step;

RobotStatus status(int32_t robot_mode, int32_t safety_mode, bool tcp_pose_mismatch = false) {
  RobotStatus s;
  s.known = true;
  s.robot_mode = robot_mode;
  s.safety_mode = safety_mode;
  s.speed_scaling = safety_mode == 1 ? 1.0 : 0.0;
  s.tcp_pose_mismatch = tcp_pose_mismatch;
  return s;
}

// A valid state for every frame, with the i-th status of `statuses` for the i-th frame.
class ScriptedStatus final : public RobotStateSource {
 public:
  explicit ScriptedStatus(std::vector<RobotStatus> statuses) : statuses_(std::move(statuses)) {}
  RobotStateOrigin origin() const override { return RobotStateOrigin::fixed; }
  bool state_at(int64_t host_time_ns, RobotState& out) override {
    std::lock_guard<std::mutex> lock(mutex_);
    out = fixed_robot_state({});
    out.host_time_ns = host_time_ns;
    if (next_ < statuses_.size()) out.status = statuses_[next_];
    ++next_;
    return true;
  }

 private:
  std::mutex mutex_;
  std::vector<RobotStatus> statuses_;
  size_t next_ = 0;
};

std::vector<FrameResult> run(RobotStateSource& states, RunSummary& summary) {
  FakeSource source(after_learning({{1.5F}, {0.8F}, {0.3F}, {0.0F}, {1.5F}, {0.8F}}));
  CollectingSink sink;
  Pipeline pipeline(fake_params());
  RunHeader header;
  header.source = source.info();
  summary = run_pipeline(source, states, pipeline, sink, RunOptions{}, header);
  return sink.results;
}

TEST(RobotStatusReported, NeverChangesTheVerdictAndIsCounted) {
  // Frames 0-2 learn, 3-8 see objects at 1.5, 0.8, 0.3 m, none, 1.5, 0.8 m.
  const RobotStatus unknown;
  const std::vector<RobotStatus> statuses = {
      unknown,          // 0: no report
      status(7, 1),     // 1: running, normal
      status(7, 1),     // 2
      status(5, 1),     // 3: idle                    (change 1, not running)
      status(7, 3),     // 4: protective stop         (change 2)
      status(7, 5),     // 5: safeguard stop          (change 3)
      unknown,          // 6: no report (does not count, nor break the comparison)
      status(7, 1),     // 7: running, normal again   (change 4, against frame 5)
      status(7, 1, true),  // 8: a TCP pose mismatch
  };
  ScriptedStatus scripted(statuses);
  RunSummary with_status;
  const std::vector<FrameResult> reported = run(scripted, with_status);
  FixedRobotState plain({});
  RunSummary without_status;
  const std::vector<FrameResult> reference = run(plain, without_status);

  ASSERT_EQ(reported.size(), reference.size());
  ASSERT_EQ(reported.size(), 10U);  // nine frames and the final stop
  for (size_t i = 0; i < reported.size(); ++i) {
    EXPECT_EQ(reported[i].verdict.state, reference[i].verdict.state) << i;
    EXPECT_EQ(reported[i].verdict.code, reference[i].verdict.code) << i;
    EXPECT_EQ(reported[i].verdict.speed_scale, reference[i].verdict.speed_scale) << i;
    EXPECT_EQ(reported[i].valid, reference[i].valid) << i;
  }
  // The objects decide: run, slow, stop, run, run, slow after learning, whatever the modes.
  EXPECT_EQ(reported[3].verdict.state, VerdictState::run);
  EXPECT_EQ(reported[4].verdict.state, VerdictState::slow);
  EXPECT_EQ(reported[5].verdict.state, VerdictState::stop);
  EXPECT_EQ(reported[5].verdict.code, ReasonCode::in_stop_zone);
  EXPECT_EQ(reported[8].verdict.state, VerdictState::slow);
  // Each frame carries its status to the sinks.
  for (size_t i = 0; i < statuses.size(); ++i) {
    EXPECT_EQ(reported[i].robot_state.status.known, statuses[i].known) << i;
    EXPECT_EQ(reported[i].robot_state.status.safety_mode, statuses[i].safety_mode) << i;
  }
  EXPECT_FALSE(reported.back().robot_state.status.known);  // the final stop stands for no state

  const RobotStatusCounts& counts = with_status.robot_status;
  EXPECT_EQ(counts.frames_reported, 7);
  EXPECT_EQ(counts.frames_not_running, 1);
  EXPECT_EQ(counts.frames_protective_stop, 2);
  EXPECT_EQ(counts.mode_changes, 4);
  EXPECT_EQ(counts.frames_tcp_pose_mismatch, 1);
  EXPECT_EQ(without_status.robot_status.frames_reported, 0);
  EXPECT_EQ(with_status.verdict_stop, without_status.verdict_stop);
  EXPECT_EQ(with_status.verdict_run, without_status.verdict_run);
  EXPECT_EQ(with_status.verdict_slow, without_status.verdict_slow);
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// The robot per frame: Pipeline::process builds the arm's capsules from the robot state it is
// given, an invalid or non-finite state is a stop, and run_pipeline asks the robot state source
// for every frame.

#include "../support/decide.hpp"
#include "fake_scene.hpp"

#include "hrcsense/clock.hpp"
#include "hrcsense/robot_state.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace hrcsense {
namespace {

using test::fake_params;
using test::fill_frame;

constexpr double kPi = 3.14159265358979323846;

// A one-link "arm": every DH row zero, so each joint turns about the base z axis (the fake
// camera's optical axis) and link 1's frame is Rz(q1). Its only capsule lies on link 1's x
// axis from 0.5 m to 1 m, radius 0. Base frame base (DH frame 0): no extra rotation.
PipelineParams stick_params() {
  PipelineParams params = fake_params();
  params.robot.points.capsules.clear();
  RobotDescription stick;
  stick.name = "stick";
  stick.links[1].push_back(LinkCapsule{Eigen::Vector3d(0.5, 0.0, 0.0), Eigen::Vector3d(1.0, 0.0, 0.0), 0.0});
  params.robot.arm = stick;
  params.robot.base_frame = BaseFrame::base;
  params.robot.padding_m = 0.0;
  return params;
}

// Learns the empty cell (the wall) in the pipeline itself; learning needs no robot state.
void learn(Pipeline& pipeline) {
  Frame frame;
  FrameResult result;
  RobotState none;
  for (int i = 0; i < test::kLearnFrames; ++i) {
    fill_frame(i, 0.0F, frame);
    test::process_and_decide(pipeline, frame, none, result);
    ASSERT_EQ(result.verdict.code, ReasonCode::learning_background);
  }
  ASSERT_TRUE(pipeline.background_ready());
}

RobotState joints(double q1_rad) {
  JointAngles q{};
  q[0] = q1_rad;
  return fixed_robot_state(q);
}

// The fake scene's square at z = 0.8 m covers pixels u 20..59, v 10..49 of a camera with
// fx = fy = 100, ppx = 39.5, ppy = 29.5, so its points span x, y = (pixel - centre) / 100 · 0.8:
// x in [-0.156, 0.156], y in [-0.156, 0.156] (the pixels nearest the axis at ±0.004).
// With q1 = 0 the capsule runs from (0.5, 0, 0) to (1, 0, 0): the nearest square point is
// (0.156, ±0.004, 0.8), the nearest robot point the capsule's end (0.5, 0, 0), and the distance
// sqrt(0.344² + 0.004² + 0.8²) = sqrt(0.758352) = 0.870834 m. With q1 = π/2 the capsule turns
// onto +y: the robot point becomes (0, 0.5, 0) at the same distance by symmetry.
TEST(RobotStatePerFrame, ArmCapsulesFollowTheJointState) {
  Pipeline pipeline(stick_params());
  learn(pipeline);
  Frame frame;
  FrameResult result;
  const double expected_m = std::sqrt(0.344 * 0.344 + 0.004 * 0.004 + 0.8 * 0.8);

  fill_frame(3, 0.8F, frame);
  test::process_and_decide(pipeline, frame, joints(0.0), result);
  ASSERT_TRUE(result.valid) << result.verdict.reason;
  ASSERT_TRUE(result.contact.valid);
  EXPECT_NEAR(result.contact.distance_m, expected_m, 1e-5);
  EXPECT_NEAR(result.contact.closest_robot_base.x(), 0.5F, 1e-6F);
  EXPECT_NEAR(result.contact.closest_robot_base.y(), 0.0F, 1e-6F);
  EXPECT_EQ(result.contact.robot_link, 1);
  ASSERT_EQ(pipeline.robot().capsules.size(), 1U);
  EXPECT_NEAR(pipeline.robot().capsules[0].b.x(), 1.0F, 1e-6F);

  fill_frame(4, 0.8F, frame);
  test::process_and_decide(pipeline, frame, joints(kPi / 2.0), result);
  ASSERT_TRUE(result.contact.valid);
  EXPECT_NEAR(result.contact.distance_m, expected_m, 1e-5);
  EXPECT_NEAR(result.contact.closest_robot_base.x(), 0.0F, 1e-6F);
  EXPECT_NEAR(result.contact.closest_robot_base.y(), 0.5F, 1e-6F);
  EXPECT_NEAR(pipeline.robot().capsules[0].b.y(), 1.0F, 1e-6F);
  EXPECT_EQ(result.robot_state.q_rad[0], kPi / 2.0);  // the result says which state it used
}

// No state is a stop for an arm and for fixed points alike: a pipeline that does not know
// where the robot is must not say run, even when nothing is in the cell.
TEST(RobotStatePerFrame, InvalidStateIsStop) {
  for (const bool arm : {true, false}) {
    Pipeline pipeline(arm ? stick_params() : fake_params());
    learn(pipeline);
    Frame frame;
    FrameResult result;
    fill_frame(3, 0.0F, frame);  // the empty cell: with a state this is run
    test::process_and_decide(pipeline, frame, joints(0.0), result);
    ASSERT_EQ(result.verdict.state, VerdictState::run) << arm;
    RobotState none = joints(0.0);
    none.valid = false;
    fill_frame(4, 0.0F, frame);
    test::process_and_decide(pipeline, frame, none, result);
    EXPECT_EQ(result.verdict.state, VerdictState::stop) << arm;
    EXPECT_EQ(result.verdict.code, ReasonCode::no_robot_state) << arm;
    EXPECT_EQ(result.verdict.reason, "no robot state");
    EXPECT_FALSE(result.valid);
  }
}

TEST(RobotStatePerFrame, NonFiniteJointIsStop) {
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    Pipeline pipeline(stick_params());
    learn(pipeline);
    Frame frame;
    FrameResult result;
    RobotState state = joints(0.0);
    state.q_rad[4] = bad;
    fill_frame(3, 0.0F, frame);
    test::process_and_decide(pipeline, frame, state, result);
    EXPECT_EQ(result.verdict.state, VerdictState::stop);
    EXPECT_EQ(result.verdict.code, ReasonCode::non_finite_input);
  }
}

TEST(RobotStatePerFrame, FixedSourceStampsTheAskedTime) {
  JointAngles q{};
  q[2] = 1.25;
  FixedRobotState fixed(q);
  EXPECT_EQ(fixed.origin(), RobotStateOrigin::fixed);
  EXPECT_STREQ(robot_state_origin_name(fixed.origin()), "fixed");
  RobotState state;
  ASSERT_TRUE(fixed.state_at(123'456'789, state));
  EXPECT_TRUE(state.valid);
  EXPECT_EQ(state.host_time_ns, 123'456'789);
  EXPECT_EQ(state.q_rad[2], 1.25);
  EXPECT_EQ(state.qd_rad_s, JointAngles{});
}

// A robot state source that has nothing for the second frame, and remembers when it was asked.
class GapRobotState final : public RobotStateSource {
 public:
  RobotStateOrigin origin() const override { return RobotStateOrigin::udp_json; }
  bool state_at(int64_t host_time_ns, RobotState& out) override {
    asked_ns.push_back(host_time_ns);
    out = joints(0.0);
    out.host_time_ns = host_time_ns;
    out.origin = RobotStateOrigin::udp_json;
    if (asked_ns.size() == 5) {  // frames 0-2 learn; frame 3 has a state, frame 4 none
      out.valid = false;
      return false;
    }
    return true;
  }
  std::vector<int64_t> asked_ns;
};

TEST(RobotStatePerFrame, RunAsksTheSourceForEveryFrame) {
  test::FakeSource source({test::Step{}, test::Step{}, test::Step{}, test::Step{}, test::Step{}, test::Step{}});
  GapRobotState robot_states;
  Pipeline pipeline(stick_params());
  test::CollectingSink sink;
  const RunSummary summary = run_pipeline(source, robot_states, pipeline, sink, RunOptions{}, RunHeader{});
  ASSERT_EQ(summary.frames_processed, 6);
  ASSERT_EQ(robot_states.asked_ns.size(), 6U);
  for (size_t i = 1; i < robot_states.asked_ns.size(); ++i) {
    EXPECT_GE(robot_states.asked_ns[i], robot_states.asked_ns[i - 1]) << "host time went backwards at " << i;
  }
  const std::vector<FrameResult> results = sink.frame_results();
  ASSERT_EQ(results.size(), 6U);
  EXPECT_EQ(results[3].verdict.code, ReasonCode::no_foreground);
  EXPECT_EQ(results[4].verdict.code, ReasonCode::no_robot_state);
  EXPECT_EQ(results[5].verdict.code, ReasonCode::no_foreground);
  EXPECT_EQ(results[3].robot_state.origin, RobotStateOrigin::udp_json);
}

// A state whose newest sample is too old is stale, not missing: another reason code, and the
// age in the result (frame host time 1.08 s, sample at 1.0 s: 80 ms).
TEST(RobotStatePerFrame, StaleStateSaysHowOld) {
  Pipeline pipeline(stick_params());
  learn(pipeline);
  Frame frame;
  FrameResult result;
  fill_frame(3, 0.0F, frame);
  frame.host_time_ns = 1'080'000'000;
  RobotState stale = joints(0.0);
  stale.valid = false;
  stale.sample_time_ns = 1'000'000'000;
  test::process_and_decide(pipeline, frame, stale, result);
  EXPECT_EQ(result.verdict.state, VerdictState::stop);
  EXPECT_EQ(result.verdict.code, ReasonCode::robot_state_stale);
  EXPECT_EQ(result.verdict.reason, "robot state stale (80.0 ms old)");
  EXPECT_DOUBLE_EQ(result.robot_state_age_ms, 80.0);
  EXPECT_EQ(result.host_time_ns, 1'080'000'000);
  // A valid state 4 ms old: measured, with its age.
  RobotState fresh = joints(0.0);
  fresh.sample_time_ns = 1'076'000'000;
  test::process_and_decide(pipeline, frame, fresh, result);
  EXPECT_EQ(result.verdict.code, ReasonCode::no_foreground);
  EXPECT_DOUBLE_EQ(result.robot_state_age_ms, 4.0);
}

// Records the times it is asked for; answers like a live source (origin rtde) or a fixed one.
class AskedTimes final : public RobotStateSource {
 public:
  explicit AskedTimes(RobotStateOrigin origin) : origin_(origin) {}
  RobotStateOrigin origin() const override { return origin_; }
  bool state_at(int64_t host_time_ns, RobotState& out) override {
    asked_ns.push_back(host_time_ns);
    out = joints(0.0);
    out.host_time_ns = host_time_ns;
    return true;
  }
  std::vector<int64_t> asked_ns;

 private:
  RobotStateOrigin origin_;
};

// Unpaced with a fixed arm: the frames live on the source's timeline, so the state is asked
// for at each timestamp (index · 33 333 333 ns) minus robot.state.camera_latency_s (10 ms), and
// host_time_ns is the timestamp.
TEST(RobotStateClocks, UnpacedFixedRunUsesTheSourceTimeMinusTheCameraLatency) {
  test::FakeSource source({test::Step{}, test::Step{}, test::Step{}, test::Step{}});
  AskedTimes robot_states(RobotStateOrigin::fixed);
  Pipeline pipeline(stick_params());
  test::CollectingSink sink;
  FakeClock clock(500'000'000'000);
  RunOptions options;
  options.clock = &clock;
  options.camera_latency_s = 0.010;
  run_pipeline(source, robot_states, pipeline, sink, options, RunHeader{});
  ASSERT_EQ(robot_states.asked_ns.size(), 4U);
  const std::vector<FrameResult> results = sink.frame_results();
  ASSERT_EQ(results.size(), 4U);
  for (int64_t i = 0; i < 4; ++i) {
    const size_t k = static_cast<size_t>(i);
    EXPECT_EQ(robot_states.asked_ns[k], i * 33'333'333 - 10'000'000) << i;
    EXPECT_EQ(results[k].host_time_ns, i * 33'333'333) << i;
  }
}

// With a live robot state the frames of a file are stamped when delivered, on the run's clock:
// the fake clock does not move, so every frame is at its start time.
TEST(RobotStateClocks, LiveStateUsesTheDeliveryTime) {
  test::FakeSource source({test::Step{}, test::Step{}, test::Step{}});
  AskedTimes robot_states(RobotStateOrigin::rtde);
  Pipeline pipeline(stick_params());
  test::CollectingSink sink;
  FakeClock clock(500'000'000'000);
  RunOptions options;
  options.clock = &clock;
  run_pipeline(source, robot_states, pipeline, sink, options, RunHeader{});
  ASSERT_EQ(robot_states.asked_ns.size(), 3U);
  for (const int64_t t : robot_states.asked_ns) EXPECT_EQ(t, 500'000'000'000);
  for (const FrameResult& r : sink.frame_results()) EXPECT_EQ(r.host_time_ns, 500'000'000'000);
}

// A source that stamps host time itself (a live camera) keeps it.
class HostStampedSource final : public Source {
 public:
  SourceInfo info() const override { return inner_.info(); }
  Status next(Frame& out) override {
    const Status status = inner_.next(out);
    if (status == Status::frame) out.host_time_ns = 7'000'000'000 + out.index;
    return status;
  }

 private:
  test::FakeSource inner_{{test::Step{}, test::Step{}}};
};

TEST(RobotStateClocks, ASourceHostTimeIsKept) {
  HostStampedSource source;
  AskedTimes robot_states(RobotStateOrigin::rtde);
  Pipeline pipeline(stick_params());
  test::CollectingSink sink;
  run_pipeline(source, robot_states, pipeline, sink, RunOptions{}, RunHeader{});
  ASSERT_EQ(robot_states.asked_ns.size(), 2U);
  EXPECT_EQ(robot_states.asked_ns[0], 7'000'000'000);
  EXPECT_EQ(robot_states.asked_ns[1], 7'000'000'001);
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// The unknown share of the background: -1 before there is one; the share of pixels without a
// depth after (a loaded model with 600 of the fake scene's 4800 pixels unknown: 0.125).
TEST(UnknownBackground, ShareOfPixelsWithoutDepth) {
  Pipeline pipeline(test::fake_params());
  EXPECT_EQ(pipeline.unknown_background_share(), -1.0);
  BackgroundModel model = test::learn_empty_background();
  ASSERT_EQ(model.mean_m.size(), 4800U);
  pipeline.set_background(model);
  EXPECT_EQ(pipeline.unknown_background_share(), 0.0);
  for (size_t i = 0; i < 600; ++i) model.mean_m[i] = 0.0F;
  pipeline.set_background(model);
  EXPECT_EQ(pipeline.unknown_background_share(), 0.125);
}

}  // namespace
}  // namespace hrcsense

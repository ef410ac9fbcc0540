// SPDX-License-Identifier: Apache-2.0
// RtdeRobotState against the fake controller (tests/net/fake_rtde_controller.hpp) on 127.0.0.1:
// good streaming matches the fake's trajectory; each misbehaviour is counted and, for a closed or
// stalled stream, gives no valid state until good data resumes. Every wait has a deadline.
#include "rtde_rig.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/net/rtde.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <memory>

namespace hrcsense {
namespace {

using test::FakeRtdeController;
using test::FakeRtdeScript;
using test::RtdeFault;

using test::Rig;
using test::wait_until;

class RtdeStreaming : public ::testing::TestWithParam<double> {};

// 30 s of trajectory at 125 or 500 Hz. Between two samples T apart, linear interpolation of
// q = 0.5 sin(ωt + φ) errs by at most 0.5 ω² T² / 8 (ω = 0.4π rad/s): 6.3e-6 rad at 125 Hz,
// 3.9e-7 rad at 500 Hz; the arrival times are exact (the fake waits for the client), so the
// states must match within 1e-5 rad.
TEST_P(RtdeStreaming, StatesFollowTheTrajectoryAtTheLookedUpTime) {
  const double rate_hz = GetParam();
  FakeRtdeScript script;
  script.samples_per_connection = static_cast<int64_t>(30 * rate_hz);
  const int64_t period_ns = static_cast<int64_t>(1e9 / rate_hz);
  std::mutex mutex;
  int64_t checked = 0, failed = 0;
  Rig rig(script, rate_hz);
  rig.check = [&](int64_t sent) {
    if (sent < 10 || sent % 25 != 0) return;
    const int64_t now = rig.clock.now_ns();  // the newest sample's arrival
    const bool ok = rig.matches_at(now - period_ns / 2) && rig.matches_at(now - 7 * period_ns - period_ns / 3) &&
                    rig.matches_at(now);
    std::lock_guard<std::mutex> lock(mutex);
    ++checked;
    failed += ok ? 0 : 1;
  };
  ASSERT_TRUE(rig.consumed(script.samples_per_connection));
  const RobotStateStats stats = rig.client->stats();
  const RtdeStatus status = rig.client->status();
  rig.fake.stop();  // joins the fake's thread: `checked` and `failed` are final
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_GE(checked, script.samples_per_connection / 25 - 1);
  EXPECT_EQ(failed, 0);
  EXPECT_EQ(stats.samples.accepted, script.samples_per_connection);
  EXPECT_EQ(stats.samples.rejected(), 0);
  EXPECT_EQ(stats.connections, 1);
  EXPECT_EQ(stats.malformed, 0);
  EXPECT_EQ(status.controller.major, 5U);
  EXPECT_EQ(status.frequency_hz, rate_hz);
  EXPECT_FALSE(status.frequency_clamped);
  EXPECT_EQ(status.robot_mode, 7);
  EXPECT_EQ(status.safety_mode, 1);
  EXPECT_EQ(status.speed_scaling, 1.0);
  EXPECT_EQ(status.text_messages, 1);
  EXPECT_EQ(status.last_text_message, "fake: Program running");
  EXPECT_EQ(rig.fake.frequencies(), std::vector<double>{rate_hz});
}

INSTANTIATE_TEST_SUITE_P(Rates, RtdeStreaming, ::testing::Values(125.0, 500.0));

TEST(RtdeClient, CB3ControllerGetsAtMost125Hz) {
  FakeRtdeScript script;
  script.major = 3;
  script.samples_per_connection = 50;
  Rig rig(script, 500.0);
  ASSERT_TRUE(rig.consumed(50));
  EXPECT_EQ(rig.fake.frequencies(), std::vector<double>{125.0});
  EXPECT_TRUE(rig.client->status().frequency_clamped);
  EXPECT_EQ(rig.client->status().frequency_hz, 125.0);
  EXPECT_NE(rig.client->stats().last_problem.find("to 125 Hz"), std::string::npos);
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
}

FakeRtdeScript faulty(RtdeFault fault) {
  FakeRtdeScript script;
  script.fault = fault;
  return script;  // the fault at package 100 of 200, on the first connection
}

TEST(RtdeClient, ClosedConnectionGivesNoStateThenReconnectsWithTheSameFrequency) {
  Rig rig(faulty(RtdeFault::close), 500.0);
  ASSERT_TRUE(wait_until([&] { return rig.fake.faulted() && rig.client->stats().disconnects >= 1; }));
  EXPECT_FALSE(rig.valid_now());
  EXPECT_NE(rig.client->error().find("closed by the controller"), std::string::npos) << rig.client->error();
  rig.fake.release();
  ASSERT_TRUE(rig.consumed(300));
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
  EXPECT_EQ(rig.client->stats().connections, 2);
  EXPECT_EQ(rig.client->stats().disconnects, 1);
  EXPECT_EQ(rig.fake.frequencies(), (std::vector<double>{500.0, 500.0}));
  EXPECT_TRUE(rig.client->error().empty());
}

TEST(RtdeClient, StallIsStaleThenValidWhenDataResumes) {
  Rig rig(faulty(RtdeFault::stall), 500.0);
  ASSERT_TRUE(wait_until([&] { return rig.fake.faulted(); }));
  ASSERT_TRUE(rig.consumed(100));
  EXPECT_TRUE(rig.valid_now());
  rig.clock.advance(100'000'000);  // 100 ms of silence: past max_age_s (50 ms), within the 1 s timeout
  EXPECT_FALSE(rig.valid_now());
  rig.fake.release();
  ASSERT_TRUE(rig.consumed(200));
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
  EXPECT_EQ(rig.client->stats().disconnects, 0);
}

TEST(RtdeClient, StallLongerThanTheReceiveTimeoutReconnects) {
  Rig rig(faulty(RtdeFault::stall), 500.0);
  ASSERT_TRUE(wait_until([&] { return rig.fake.faulted(); }));
  ASSERT_TRUE(rig.consumed(100));
  rig.clock.advance(2'000'000'000);  // 2 s of silence: past the 1 s receive timeout
  ASSERT_TRUE(wait_until([&] { return rig.client->stats().disconnects >= 1; }));
  EXPECT_FALSE(rig.valid_now());
  EXPECT_NE(rig.client->stats().last_problem.find("no data from the controller"), std::string::npos)
      << rig.client->stats().last_problem;
  rig.fake.release();
  ASSERT_TRUE(rig.consumed(300));
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
  EXPECT_EQ(rig.client->stats().connections, 2);
}

TEST(RtdeClient, TruncatedPackageAtCloseIsMalformedThenReconnects) {
  Rig rig(faulty(RtdeFault::truncated), 500.0);
  ASSERT_TRUE(wait_until([&] { return rig.fake.faulted() && rig.client->stats().disconnects >= 1; }));
  EXPECT_FALSE(rig.valid_now());
  EXPECT_EQ(rig.client->stats().malformed, 1);
  EXPECT_NE(rig.client->stats().last_problem.find("truncated DATA_PACKAGE"), std::string::npos);
  rig.fake.release();
  ASSERT_TRUE(rig.consumed(300));
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
}

// One package dropped in the stream: counted, the stream goes on and stays valid.
struct InStream {
  RtdeFault fault;
  const char* problem;  // in last_problem
};

class RtdeInStreamFault : public ::testing::TestWithParam<InStream> {};

TEST_P(RtdeInStreamFault, IsCountedAndTheStreamGoesOn) {
  const InStream param = GetParam();
  Rig rig(faulty(param.fault), 500.0);
  ASSERT_TRUE(rig.consumed(200));
  const RobotStateStats stats = rig.client->stats();
  const RtdeStatus status = rig.client->status();
  EXPECT_NE(stats.last_problem.find(param.problem), std::string::npos) << stats.last_problem;
  EXPECT_EQ(stats.disconnects, 0);
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
  switch (param.fault) {
    case RtdeFault::unknown_type:
      EXPECT_EQ(status.skipped_packages, 1);
      EXPECT_EQ(stats.malformed, 0);
      EXPECT_EQ(stats.samples.accepted, 200);
      break;
    case RtdeFault::nan_joints:
      EXPECT_EQ(stats.samples.rejected_non_finite, 1);
      EXPECT_EQ(stats.samples.accepted, 199);
      break;
    default:  // oversized, wrong recipe
      EXPECT_EQ(stats.malformed, 1);
      EXPECT_EQ(stats.samples.accepted, 199);
  }
}

INSTANTIATE_TEST_SUITE_P(Faults, RtdeInStreamFault,
                         ::testing::Values(InStream{RtdeFault::oversized, "DATA_PACKAGE: payload of 185 bytes"},
                                           InStream{RtdeFault::wrong_recipe, "recipe id 7, expected 1"},
                                           InStream{RtdeFault::unknown_type, "skipped package type 88 (unknown package type, 8 bytes)"},
                                           InStream{RtdeFault::nan_joints, "rejected: a non-finite joint"}));

// A package whose shoulder_lift reads 1e300 is finite but no pose of a UR5 (±2π): with the
// arm's limits (what the assembly sets from robot.model), it is rejected, counted apart and
// named; the stream goes on.
TEST(RtdeClient, AJointOutsideTheArmsLimitsIsRejectedAndNamed) {
  Rig rig(faulty(RtdeFault::huge_joint), 500.0, [](RtdeParams& params) {
    params.history.q_min_rad.fill(-2.0 * M_PI);
    params.history.q_max_rad.fill(2.0 * M_PI);
  });
  ASSERT_TRUE(rig.consumed(200));
  const RobotStateStats stats = rig.client->stats();
  EXPECT_EQ(stats.samples.rejected_limits, 1);
  EXPECT_EQ(stats.samples.rejected(), 1);
  EXPECT_EQ(stats.samples.accepted, 199);
  EXPECT_NE(stats.last_problem.find(" s rejected: joint 2 (shoulder_lift) 1e+300 rad outside the arm's limits "
                                    "-6.283..6.283 rad"),
            std::string::npos)
      << stats.last_problem;
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
}

// A refusal in the handshake: an error saying why, no state, retried with back-off.
class RtdeHandshakeFault : public ::testing::TestWithParam<InStream> {};

TEST_P(RtdeHandshakeFault, SaysWhyGivesNoStateAndRetries) {
  Rig rig(faulty(GetParam().fault), 500.0);
  ASSERT_TRUE(wait_until([&] { return rig.fake.faulted() && !rig.client->error().empty(); }));
  EXPECT_NE(rig.client->error().find(GetParam().problem), std::string::npos) << rig.client->error();
  EXPECT_FALSE(rig.valid_now());
  EXPECT_EQ(rig.client->stats().samples.accepted, 0);
  rig.fake.release();
  ASSERT_TRUE(rig.consumed(200));
  EXPECT_TRUE(rig.matches_at(rig.clock.now_ns()));
  EXPECT_GE(rig.client->stats().connections, 2);
}

INSTANTIATE_TEST_SUITE_P(
    Faults, RtdeHandshakeFault,
    ::testing::Values(InStream{RtdeFault::not_found, "variable 'actual_TCP_pose' NOT_FOUND"},
                      InStream{RtdeFault::protocol1_only, "refused protocol version 2"}));

TEST(RtdeClient, NoControllerIsAnErrorAndNoState) {
  FakeClock clock;
  int port = 0;
  {
    FakeRtdeController closed(FakeRtdeScript{}, clock);  // a port that nothing listens on after this
    port = closed.port();
  }
  RtdeParams params;
  params.host = "127.0.0.1";
  params.port = port;
  RtdeRobotState client(params, clock);
  ASSERT_TRUE(wait_until([&] { return !client.error().empty(); }));
  EXPECT_NE(client.error().find("connect"), std::string::npos) << client.error();
  RobotState state;
  EXPECT_FALSE(client.state_at(clock.now_ns(), state));
  EXPECT_EQ(client.stats().connections, 0);
}

// robot.state.source rtde: the assembly builds the client from robot.state.host, port and
// frequency_hz, stamping with the given clock.
TEST(RtdeAssembly, RobotStateSourceRtdeBuildsTheClient) {
  FakeClock clock{1'000'000'000'000};
  FakeRtdeScript script;
  script.samples_per_connection = 20;
  FakeRtdeController fake(script, clock);
  const Config config = load_config("", {"robot.state.source=rtde", "robot.state.host=127.0.0.1",
                                         "robot.state.port=" + std::to_string(fake.port()),
                                         "robot.state.frequency_hz=500"});
  std::unique_ptr<RobotStateSource> source = make_robot_state_source(config, &clock);
  ASSERT_EQ(source->origin(), RobotStateOrigin::rtde);
  auto* rtde = dynamic_cast<RtdeRobotState*>(source.get());
  ASSERT_NE(rtde, nullptr);
  std::atomic<bool> stopping{false};
  fake.start([&](int64_t sent) { wait_until([&] { return stopping || rtde->status().data_packages >= sent; }); });
  ASSERT_TRUE(wait_until([&] { return rtde->status().data_packages >= 20; }));
  EXPECT_EQ(fake.frequencies(), std::vector<double>{500.0});
  RobotState state;
  EXPECT_TRUE(source->state_at(clock.now_ns(), state));
  EXPECT_NEAR(state.q_rad[1], Rig::expected_q(clock.now_ns(), 1), 1e-9);
  stopping = true;
  fake.stop();
}

}  // namespace
}  // namespace hrcsense

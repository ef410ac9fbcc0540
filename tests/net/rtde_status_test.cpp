// SPDX-License-Identifier: Apache-2.0
// The controller's own report through the RTDE client: robot_mode, safety_mode and speed_scaling
// reach each state as the sample in force at the looked-up time had them, and the check of
// actual_TCP_pose against the forward kinematics of actual_q tells a consistent controller from
// one whose frame is turned π about z or whose arm is another one. The poses the fake sends are
// written out by hand for joint states where UR's DH chain reduces to a few rotations.
#include "rtde_rig.hpp"

#include "hrcsense/robot.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <mutex>
#include <vector>

namespace hrcsense {
namespace {

using test::FakeModes;
using test::FakeRtdeScript;
using test::Rig;

// ---- robot_mode, safety_mode, speed_scaling

// Packages 0-59 running and normal at full speed; 60-119 a protective stop (speed 0); from 120
// idle (robot_mode 5) and normal at half speed with the speed slider at 0.4: the arm runs at
// 0.5 × 0.4 = 0.2 of its programmed speed.
FakeModes modes_of(int64_t k) {
  if (k < 60) return FakeModes{7, 1, 1.0, 1.0};
  if (k < 120) return FakeModes{7, 3, 0.0, 1.0};
  return FakeModes{5, 1, 0.5, 0.4};
}

// 0.5 × 0.4 and the others, worked by hand.
double programmed_share(int64_t k) { return k < 60 ? 1.0 : k < 120 ? 0.0 : 0.2; }

TEST(RtdeStatus, EachStateCarriesTheModesInForceAtItsTime) {
  FakeRtdeScript script;
  script.samples_per_connection = 160;
  script.modes = modes_of;
  std::mutex mutex;
  std::vector<RobotState> seen;  // the state at each package's arrival
  std::vector<RobotState> between;  // a third of a period before package k arrived: package k-1's
  Rig rig(script, 500.0);
  const int64_t period_ns = 2'000'000;
  rig.check = [&](int64_t sent) {
    RobotState now, before;
    rig.client->state_at(rig.clock.now_ns(), now);
    rig.client->state_at(rig.clock.now_ns() - period_ns / 3, before);
    std::lock_guard<std::mutex> lock(mutex);
    seen.push_back(now);
    if (sent > 1) between.push_back(before);
  };
  ASSERT_TRUE(rig.consumed(160));
  rig.fake.stop();
  std::lock_guard<std::mutex> lock(mutex);
  ASSERT_EQ(seen.size(), 160U);
  for (size_t k = 0; k < seen.size(); ++k) {
    const FakeModes expected = modes_of(static_cast<int64_t>(k));
    const RobotStatus& status = seen[k].status;
    ASSERT_TRUE(status.known) << k;
    EXPECT_EQ(status.robot_mode, expected.robot_mode) << k;
    EXPECT_EQ(status.safety_mode, expected.safety_mode) << k;
    EXPECT_EQ(status.speed_scaling, expected.speed_scaling) << k;
    EXPECT_EQ(status.target_speed_fraction, expected.target_speed_fraction) << k;
    EXPECT_DOUBLE_EQ(seen[k].speed_fraction, programmed_share(static_cast<int64_t>(k))) << k;
    EXPECT_FALSE(status.tcp_pose_mismatch) << k;  // no arm configured: not checked
    EXPECT_TRUE(seen[k].valid) << k;             // whatever the modes, the joints are valid
  }
  // Between packages k-1 and k the state is interpolated, but the modes are package k-1's.
  ASSERT_EQ(between.size(), 159U);
  for (size_t i = 0; i < between.size(); ++i) {
    EXPECT_EQ(between[i].status.safety_mode, modes_of(static_cast<int64_t>(i)).safety_mode) << i;
    EXPECT_EQ(between[i].status.robot_mode, modes_of(static_cast<int64_t>(i)).robot_mode) << i;
    EXPECT_DOUBLE_EQ(between[i].speed_fraction, programmed_share(static_cast<int64_t>(i))) << i;  // the slider steps
  }
}

TEST(RtdeStatus, NoStateNoStatus) {
  FakeRtdeScript script;
  script.samples_per_connection = 20;
  Rig rig(script, 500.0);
  ASSERT_TRUE(rig.consumed(20));
  rig.clock.advance(100'000'000);  // past max_age_s: stale
  RobotState state;
  EXPECT_FALSE(rig.client->state_at(rig.clock.now_ns(), state));
  EXPECT_FALSE(state.status.known);
}

TEST(RobotStatusNames, AsUrNamesThem) {
  EXPECT_STREQ(robot_mode_name(7), "running");
  EXPECT_STREQ(robot_mode_name(-1), "no_controller");
  EXPECT_STREQ(robot_mode_name(5), "idle");
  EXPECT_STREQ(robot_mode_name(42), "unknown");
  EXPECT_STREQ(safety_mode_name(1), "normal");
  EXPECT_STREQ(safety_mode_name(3), "protective_stop");
  EXPECT_STREQ(safety_mode_name(5), "safeguard_stop");
  EXPECT_STREQ(safety_mode_name(0), "unknown");
}

// ---- actual_TCP_pose against forward kinematics

// UR5's DH table as UR publishes it (metres).
constexpr double kD1 = 0.089159, kA2 = -0.425, kA3 = -0.39225, kD4 = 0.10915, kD5 = 0.09465, kD6 = 0.0823;

// The fake arm moves joints 1 and 6 only (the others stay 0): q1 = 0.6 sin(2π·0.5 t),
// q6 = 1.2 sin(2π·0.3 t).
void pan_and_wrist(double t_s, JointAngles& q, JointAngles& qd) {
  q = {};
  qd = {};
  q[0] = 0.6 * std::sin(2.0 * M_PI * 0.5 * t_s);
  qd[0] = 0.6 * 2.0 * M_PI * 0.5 * std::cos(2.0 * M_PI * 0.5 * t_s);
  q[5] = 1.2 * std::sin(2.0 * M_PI * 0.3 * t_s);
  qd[5] = 1.2 * 2.0 * M_PI * 0.3 * std::cos(2.0 * M_PI * 0.3 * t_s);
}

// The flange in UR's DH frame 0 for q = (q1, 0, 0, 0, 0, q6), by hand: with joints 2-5 at 0 the
// chain is Rz(q1) · Rx(π/2) · [Rx(π/2) · Rx(-π/2) = I] · Rz(q6); the flange sits at
// (a2 + a3, -(d4 + d6), d1 - d5) turned by q1 about z, whatever q6.
Pose flange_dh(const JointAngles& q) {
  Pose T = Pose::Identity();
  T.linear() = (Eigen::AngleAxisd(q[0], Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()) *
                Eigen::AngleAxisd(q[5], Eigen::Vector3d::UnitZ()))
                   .toRotationMatrix();
  T.translation() = Eigen::AngleAxisd(q[0], Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(kA2 + kA3, -(kD4 + kD6), kD1 - kD5);
  return T;
}

// hrcsense's `base`, the pendant's frame, is UR's DH frame 0 itself: with UR's table (a2, a3 < 0)
// the arm at q = 0 reaches along −x, as the pendant shows it, while ROS's base_link, turned π
// about z, has it along +x (ur_description, "Robot Frames"; docs/ROBOT.md, "Frames").
Pose pendant_from_dh() { return Pose::Identity(); }

// A gripper's TCP: 0.15 m out along the flange's z, turned 30° about it.
Pose tool() {
  Pose T = Pose::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(0.0, 0.0, 0.15);
  return T;
}

std::array<double, 6> ur_vector(const Pose& T) {
  const Eigen::AngleAxisd rotation(T.linear());
  const Eigen::Vector3d r = rotation.axis() * rotation.angle();
  return {T.translation().x(), T.translation().y(), T.translation().z(), r.x(), r.y(), r.z()};
}

// The fake's joints move on the controller clock; `turn` is an extra frame it reports in.
FakeRtdeScript moving_arm(const Pose& turn) {
  FakeRtdeScript script;
  script.samples_per_connection = 600;  // 1.2 s at 500 Hz: q6 sweeps ±1.2 rad
  script.controller_offset_s = 0.0;     // so that t_s is the FakeClock's seconds (1000 s on)
  script.joints = pan_and_wrist;
  script.tcp_pose = [turn](const JointAngles& q) { return ur_vector(turn * pendant_from_dh() * flange_dh(q) * tool()); };
  return script;
}

// The client with `arm` for the check.
std::function<void(RtdeParams&)> with_arm(BuiltinArm arm) {
  return [arm](RtdeParams& params) { params.arm = builtin_robot(arm); };
}

// Every state mismatched (or not) as `expected` says, counted by the client.
struct Seen {
  std::mutex mutex;
  int64_t checked = 0, mismatched = 0;
};

void watch(Rig& rig, Seen& seen) {
  rig.check = [&](int64_t) {
    RobotState state;
    const bool valid = rig.client->state_at(rig.clock.now_ns(), state);
    std::lock_guard<std::mutex> lock(seen.mutex);
    ++seen.checked;
    seen.mismatched += valid && state.status.tcp_pose_mismatch ? 1 : 0;
  };
}

TEST(RtdeTcpPoseCheck, ConsistentControllerGivesNoMismatch) {
  Rig rig(moving_arm(Pose::Identity()), 500.0, with_arm(BuiltinArm::ur5));
  Seen seen;
  watch(rig, seen);
  ASSERT_TRUE(rig.consumed(600));
  // Before the fake stops: its closing the connection is a problem of its own.
  EXPECT_EQ(rig.client->status().tcp_pose_mismatches, 0);
  EXPECT_EQ(rig.client->stats().last_problem, "");
  rig.fake.stop();  // joins the fake's thread: `seen` is final
  EXPECT_EQ(seen.checked, 600);
  EXPECT_EQ(seen.mismatched, 0);
}

TEST(RtdeTcpPoseCheck, BaseFrameTurnedByPiIsAMismatchNamingTheMixUp) {
  Pose turned = Pose::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Rig rig(moving_arm(turned), 500.0, with_arm(BuiltinArm::ur5));
  Seen seen;
  watch(rig, seen);
  ASSERT_TRUE(rig.consumed(600));
  // The TCP is ~0.9 m from the base axis: turned π about z it lands ~1.8 m from the flange.
  EXPECT_EQ(rig.client->status().tcp_pose_mismatches, 600);
  const std::string problem = rig.client->stats().last_problem;
  // Reported only: the joints are valid and follow the fake.
  RobotState state;
  EXPECT_TRUE(rig.client->state_at(rig.clock.now_ns(), state));
  rig.fake.stop();
  EXPECT_EQ(seen.mismatched, 600);
  EXPECT_NE(problem.find("disagrees with the ur5 forward kinematics of the joints"), std::string::npos) << problem;
  EXPECT_NE(problem.find("base/base_link mix-up"), std::string::npos) << problem;
  EXPECT_NE(problem.find("it would be 0.150 m"), std::string::npos) << problem;  // the tool's length
}

TEST(RtdeTcpPoseCheck, AnotherArmIsAMismatchOnceTheWristTurns) {
  // A UR5 controller, hrcsense told ur10e: the flanges are 0.38 m apart at first (a plausible
  // tool), but that "tool" turns with the wrist instead of staying fixed to the flange.
  Rig rig(moving_arm(Pose::Identity()), 500.0, with_arm(BuiltinArm::ur10e));
  Seen seen;
  watch(rig, seen);
  ASSERT_TRUE(rig.consumed(600));
  EXPECT_GT(rig.client->status().tcp_pose_mismatches, 300);
  EXPECT_LT(rig.client->status().tcp_pose_mismatches, 600);  // the first samples agree with the first
  const std::string problem = rig.client->stats().last_problem;
  rig.fake.stop();
  EXPECT_NE(problem.find("flange-to-TCP offset moved"), std::string::npos) << problem;
  EXPECT_NE(problem.find("wrong robot.model"), std::string::npos) << problem;
}

// check_tcp_pose on its own, at q = 0 (flange at (a2 + a3, -(d4 + d6), d1 - d5) in DH frame 0).
TEST(TcpPoseCheck, ImpliedOffsetIsTheToolAndATurnedFrameIsNot) {
  const RobotDescription& ur5 = builtin_robot(BuiltinArm::ur5);
  const JointAngles zero{};
  const Pose reported = pendant_from_dh() * flange_dh(zero) * tool();
  const TcpPoseCheck good = check_tcp_pose(ur5, zero, ur_vector(reported), nullptr, TcpPoseCheckParams{});
  EXPECT_TRUE(good.consistent);
  EXPECT_NEAR(good.offset_m, 0.15, 1e-9);
  EXPECT_TRUE(good.T_flange_tcp.isApprox(tool(), 1e-9));
  // Read in base_link the TCP (a2 + a3, -(d4 + d6 + 0.15), d1 - d5) becomes its negative in x and
  // y: from the flange (a2 + a3, -(d4 + d6), d1 - d5) that is (-2 (a2 + a3), 2 (d4 + d6) + 0.15, 0).
  EXPECT_NEAR(good.offset_turned_m, std::hypot(2.0 * (kA2 + kA3), 2.0 * (kD4 + kD6) + 0.15), 1e-9);

  Pose half_turn = Pose::Identity();  // the pose as it would read in base_link
  half_turn.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const TcpPoseCheck turned = check_tcp_pose(ur5, zero, ur_vector(half_turn * reported), nullptr, {});
  EXPECT_FALSE(turned.consistent);
  EXPECT_NEAR(turned.offset_turned_m, 0.15, 1e-9);

  // Against a reference, a drift of 3 cm of the implied tool is too much, 1 cm is not.
  Pose moved = tool();
  moved.translation().x() += 0.03;
  const Pose reference = tool();
  EXPECT_FALSE(check_tcp_pose(ur5, zero, ur_vector(pendant_from_dh() * flange_dh(zero) * moved), &reference, {}).consistent);
  moved.translation().x() -= 0.02;
  EXPECT_TRUE(check_tcp_pose(ur5, zero, ur_vector(pendant_from_dh() * flange_dh(zero) * moved), &reference, {}).consistent);

  JointAngles nan{};
  nan[2] = std::nan("");
  EXPECT_FALSE(check_tcp_pose(ur5, nan, ur_vector(reported), nullptr, {}).consistent);
}

}  // namespace
}  // namespace hrcsense

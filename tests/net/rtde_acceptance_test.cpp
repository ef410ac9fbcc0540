// SPDX-License-Identifier: Apache-2.0
// Issue G1's RTDE acceptance, on the injected clock: the fake controller streams the moving cell's
// arm (config/cell-ur5-moving.yaml's robot.trajectory, and the same waypoints with cubic
// interpolation) at 125 and 500 Hz, and at every camera frame the client's joints, and the
// distance from a point to the robot's capsules built from them, match the exact trajectory
// within an interpolation error bound derived by hand from the waypoints; a stalled controller
// is a stop within robot.state.max_age_s plus one frame, and the verdict is run again once data
// resumes.
#include "../support/scenes.hpp"
#include "../support/decide.hpp"
#include "rtde_rig.hpp"

#include "../pipeline/fake_scene.hpp"

#include "hrcsense/config/config.hpp"
#include "hrcsense/proximity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <tuple>

namespace hrcsense {
namespace {

using test::FakeRtdeScript;
using test::Rig;
using test::wait_until;

constexpr int64_t kStartNs = 1'000'000'000'000;      // Rig's FakeClock starts at 1000 s
constexpr int64_t kFramePeriodNs = 33'333'333;       // the camera at 30 frames/s
constexpr int64_t kFramePhaseNs = 1'234'567;         // frames fall between the controller's samples

Config moving_cell() { return load_config(test::scene_path("cell-ur5-moving.yaml"), {}); }

// Trajectory time of a host time: the fake's controller clock is the FakeClock (offset 0), and
// the trajectory starts with the stream at 1000 s.
double trajectory_s(int64_t host_ns) { return static_cast<double>(host_ns - kStartNs) * 1e-9; }

// Segment slopes of a piecewise-linear trajectory, per joint, including the wrap of a loop.
// Between two samples T apart that straddle a kink where the slope changes by Δv, linear
// interpolation errs by at most |Δv|·s(1 - s)·T ≤ |Δv|·T/4 (s the kink's place in the interval);
// extrapolation with the older slope for h ≤ T by at most |Δv|·h.
double max_slope_change(const RobotTrajectory& trajectory) {
  const std::vector<TrajectoryWaypoint>& w = trajectory.waypoints;
  double worst = 0.0;
  for (size_t j = 0; j < kJointCount; ++j) {
    std::vector<double> slopes;
    for (size_t k = 0; k + 1 < w.size(); ++k) slopes.push_back((w[k + 1].q_rad[j] - w[k].q_rad[j]) / (w[k + 1].t_s - w[k].t_s));
    for (size_t k = 0; k + 1 < slopes.size(); ++k) worst = std::max(worst, std::fabs(slopes[k + 1] - slopes[k]));
    if (trajectory.loop) worst = std::max(worst, std::fabs(slopes.front() - slopes.back()));
  }
  return worst;
}

// The largest |q''| of the cubic Hermite spline robot.hpp describes (tangent 0 at the ends,
// (q[k+1] - q[k-1]) / (t[k+1] - t[k-1]) inside). On a segment of length h from p0 (tangent m0) to
// p1 (m1), q'' is linear in time, so its largest magnitude is at an end:
// q''(start) = (6 (p1 - p0)/h - 4 m0 - 2 m1)/h, q''(end) = (-6 (p1 - p0)/h + 2 m0 + 4 m1)/h.
double max_cubic_acceleration(const RobotTrajectory& trajectory) {
  const std::vector<TrajectoryWaypoint>& w = trajectory.waypoints;
  const size_t n = w.size();
  double worst = 0.0;
  for (size_t j = 0; j < kJointCount; ++j) {
    std::vector<double> m(n, 0.0);
    for (size_t k = 1; k + 1 < n; ++k) m[k] = (w[k + 1].q_rad[j] - w[k - 1].q_rad[j]) / (w[k + 1].t_s - w[k - 1].t_s);
    for (size_t k = 0; k + 1 < n; ++k) {
      const double h = w[k + 1].t_s - w[k].t_s;
      const double slope = (w[k + 1].q_rad[j] - w[k].q_rad[j]) / h;
      worst = std::max(worst, std::fabs((6.0 * slope - 4.0 * m[k] - 2.0 * m[k + 1]) / h));
      worst = std::max(worst, std::fabs((-6.0 * slope + 2.0 * m[k] + 4.0 * m[k + 1]) / h));
    }
  }
  return worst;
}

struct Bounds {
  double interpolated_rad = 0.0;  ///< a frame between two samples
  double extrapolated_rad = 0.0;  ///< a frame half a period past the newest sample
};

// Linear: the kinks (|Δv|·T/4, |Δv|·T/2); cubic: a·T²/8 and a·(T/2)²/2 (Taylor with q'' ≤ a).
Bounds bounds_for(const RobotTrajectory& trajectory, double period_s) {
  if (trajectory.interpolation == TrajectoryInterpolation::linear) {
    const double dv = max_slope_change(trajectory);
    return {dv * period_s / 4.0, dv * period_s / 2.0};
  }
  const double a = max_cubic_acceleration(trajectory);
  return {a * period_s * period_s / 8.0, a * period_s * period_s / 8.0};
}

// Distance from `point_base` to the robot's capsules at `q`.
double distance_m(const RobotParams& robot, const JointAngles& q, const Eigen::Vector3f& point_base) {
  double best = std::numeric_limits<double>::infinity();
  for (const Capsule& capsule : robot_model_at(robot, q).capsules) {
    best = std::min(best, static_cast<double>(point_capsule_distance(point_base, capsule)));
  }
  return best;
}

// The largest distance of a capsule end from the base's z axis: how far a capsule point moves
// per radian of joint 1 (the only joint this trajectory moves), the distance being 1-Lipschitz
// in the capsules' ends.
double max_lever_m(const RobotParams& robot, const JointAngles& q) {
  double lever = 0.0;
  for (const Capsule& c : robot_model_at(robot, q).capsules) {
    lever = std::max({lever, static_cast<double>(c.a.head<2>().norm()), static_cast<double>(c.b.head<2>().norm())});
  }
  return lever;
}

class RtdeFollowsTheTrajectory
    : public ::testing::TestWithParam<std::tuple<TrajectoryInterpolation, double>> {};

TEST_P(RtdeFollowsTheTrajectory, AtEveryFrameWithinTheInterpolationBound) {
  const auto [interpolation, rate_hz] = GetParam();
  const Config config = moving_cell();
  ASSERT_TRUE(config.robot_state.trajectory.has_value());
  RobotTrajectory trajectory = *config.robot_state.trajectory;
  trajectory.interpolation = interpolation;
  // Only the pan joint moves in this cycle: the contact bound below relies on it.
  for (size_t j = 1; j < kJointCount; ++j) {
    for (const TrajectoryWaypoint& w : trajectory.waypoints) ASSERT_EQ(w.q_rad[j], trajectory.waypoints[0].q_rad[j]);
  }
  const double period_s = 1.0 / rate_hz;
  const Bounds bound = bounds_for(trajectory, period_s);
  // By hand for the linear cycle: the swing's 1.77 rad in 1.1 s is 1.609 rad/s, so |Δv|·T/4 is
  // 3.2 mrad at 125 Hz and 0.80 mrad at 500 Hz.
  if (interpolation == TrajectoryInterpolation::linear) {
    EXPECT_NEAR(bound.interpolated_rad, 1.77 / 1.1 * period_s / 4, 1e-9);
  }

  const RobotParams& robot = config.pipeline.robot;
  ASSERT_TRUE(robot.arm.has_value());
  const Eigen::Vector3f hand_base(0.45f, 0.35f, 0.25f);  // a hand over the table, in the arm's reach
  const double lever_m = max_lever_m(robot, trajectory.waypoints[0].q_rad);
  ASSERT_GT(lever_m, 0.5);
  ASSERT_LT(lever_m, 1.2);

  FakeRtdeScript script;
  script.controller_offset_s = 0.0;
  script.samples_per_connection = static_cast<int64_t>(std::llround(5.4 * rate_hz));  // two cycles
  script.joints = [trajectory](double t_s, JointAngles& q, JointAngles& qd) {
    const TrajectorySample sample = joints_at(trajectory, t_s - 1000.0);
    q = sample.q_rad;
    qd = sample.qd_rad_s;
  };
  std::mutex mutex;
  int64_t frames = 0, extrapolated = 0;
  double worst_interpolated = 0.0, worst_extrapolated = 0.0, worst_contact = 0.0;
  int64_t previous_ns = -1;
  int64_t next_frame = 0;
  Rig rig(script, rate_hz);
  rig.check = [&](int64_t) {
    const int64_t now_ns = rig.clock.now_ns();
    std::lock_guard<std::mutex> lock(mutex);
    // Every frame since the previous sample: bracketed by two samples, interpolated.
    for (;; ++next_frame) {
      const int64_t frame_ns = kStartNs + kFramePhaseNs + next_frame * kFramePeriodNs;
      if (frame_ns > now_ns) break;
      if (frame_ns <= previous_ns) continue;
      RobotState state;
      if (!rig.client->state_at(frame_ns, state)) {
        worst_interpolated = std::numeric_limits<double>::infinity();
        continue;
      }
      const TrajectorySample exact = joints_at(trajectory, trajectory_s(frame_ns));
      for (size_t j = 0; j < kJointCount; ++j) {
        worst_interpolated = std::max(worst_interpolated, std::fabs(state.q_rad[j] - exact.q_rad[j]));
      }
      worst_contact = std::max(worst_contact, std::fabs(distance_m(robot, state.q_rad, hand_base) -
                                                        distance_m(robot, exact.q_rad, hand_base)));
      ++frames;
    }
    // A live frame half a period past the newest sample: extrapolated with its qd.
    if (previous_ns >= 0) {
      const int64_t ahead_ns = now_ns + static_cast<int64_t>(period_s * 0.5e9);
      RobotState state;
      const bool valid = rig.client->state_at(ahead_ns, state);
      const TrajectorySample exact = joints_at(trajectory, trajectory_s(ahead_ns));
      for (size_t j = 0; j < kJointCount && valid; ++j) {
        worst_extrapolated = std::max(worst_extrapolated, std::fabs(state.q_rad[j] - exact.q_rad[j]));
      }
      if (!valid) worst_extrapolated = std::numeric_limits<double>::infinity();
      ++extrapolated;
    }
    previous_ns = now_ns;
  };
  ASSERT_TRUE(rig.consumed(script.samples_per_connection));
  rig.fake.stop();  // joins the fake's thread: the figures are final
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_GE(frames, 160);  // 5.4 s at 30 frames/s
  EXPECT_EQ(extrapolated, script.samples_per_connection - 1);
  // 1e-9 rad: the samples' doubles and the host-time rounding to whole nanoseconds.
  EXPECT_LE(worst_interpolated, bound.interpolated_rad + 1e-9);
  EXPECT_LE(worst_extrapolated, bound.extrapolated_rad + 1e-9);
  // The contact moves at most lever × joint error; 1e-5 m for the capsules' float coordinates.
  EXPECT_LE(worst_contact, lever_m * bound.interpolated_rad + 1e-5);
  EXPECT_EQ(rig.client->stats().samples.rejected(), 0);
}

INSTANTIATE_TEST_SUITE_P(Cell, RtdeFollowsTheTrajectory,
                         ::testing::Combine(::testing::Values(TrajectoryInterpolation::linear,
                                                              TrajectoryInterpolation::cubic),
                                            ::testing::Values(125.0, 500.0)));

// ---- stall: stop within max_age_s + one frame, run again after the controller resumes

class RtdeStallVerdict : public ::testing::TestWithParam<double> {};

TEST_P(RtdeStallVerdict, StopWithinMaxAgePlusOneFrameAndRunAgainAfterResume) {
  const double rate_hz = GetParam();
  FakeRtdeScript script;
  script.fault = test::RtdeFault::stall;
  script.fault_at = 100;
  script.samples_per_connection = 200;
  Rig rig(script, rate_hz);
  const double max_age_s = RtdeParams{}.history.max_age_s;
  ASSERT_EQ(max_age_s, 0.05);  // robot.state.max_age_s's default

  // The pipeline of tests/pipeline's fake scene: an object 1.5 m from the robot point is a run.
  Pipeline pipeline(test::fake_params());
  Frame frame;
  FrameResult result;
  for (int i = 0; i < test::kLearnFrames; ++i) {
    test::fill_frame(i, 0.0F, frame);
    test::process_and_decide(pipeline, frame, fixed_robot_state({}), result);
  }
  int64_t index = test::kLearnFrames;
  auto verdict_at = [&](int64_t host_ns) {
    test::fill_frame(index++, 1.5F, frame);
    frame.host_time_ns = host_ns;
    RobotState state;
    if (!rig.client->state_at(host_ns, state)) state.valid = false;
    test::process_and_decide(pipeline, frame, state, result);
    return result.verdict;
  };

  ASSERT_TRUE(wait_until([&] { return rig.fake.faulted() && rig.client->status().data_packages >= 100; }));
  RobotState newest;
  ASSERT_TRUE(rig.client->state_at(rig.clock.now_ns(), newest));
  const int64_t stalled_ns = newest.sample_time_ns;  // the last sample before the controller went quiet
  ASSERT_GT(stalled_ns, 0);
  const int64_t bound_ns = static_cast<int64_t>(std::llround(max_age_s * 1e9)) + kFramePeriodNs;
  // Cameras of any phase against the stall: the first frame that is a stop comes at most
  // max_age_s + one frame period after the last sample, and every frame before it runs.
  for (int64_t phase_ns : {100'000LL, 7'000'000LL, 16'666'667LL, 33'000'000LL}) {
    int64_t first_stop_ns = -1;
    for (int64_t t_ns = stalled_ns + phase_ns; t_ns < stalled_ns + 4 * bound_ns; t_ns += kFramePeriodNs) {
      if (t_ns > rig.clock.now_ns()) rig.clock.set(t_ns);
      const Verdict verdict = verdict_at(t_ns);
      if (verdict.state == VerdictState::stop) {
        EXPECT_EQ(verdict.code, ReasonCode::robot_state_stale) << verdict.reason;
        if (first_stop_ns < 0) first_stop_ns = t_ns;
      } else {
        EXPECT_LT(first_stop_ns, 0) << "a run after a stop, " << (t_ns - stalled_ns) << " ns after the stall";
        EXPECT_EQ(verdict.state, VerdictState::run) << verdict.reason;
        EXPECT_LE(t_ns - stalled_ns, static_cast<int64_t>(std::llround(max_age_s * 1e9)));
      }
    }
    ASSERT_GE(first_stop_ns, 0) << "phase " << phase_ns;
    EXPECT_LE(first_stop_ns - stalled_ns, bound_ns) << "phase " << phase_ns;
  }
  EXPECT_EQ(rig.client->stats().disconnects, 0);  // within the 1 s receive timeout: stale, not lost

  // The controller resumes: within a few samples the frames run again.
  rig.fake.release();
  ASSERT_TRUE(rig.consumed(110));
  EXPECT_EQ(verdict_at(rig.clock.now_ns()).state, VerdictState::run) << result.verdict.reason;
}

INSTANTIATE_TEST_SUITE_P(Rates, RtdeStallVerdict, ::testing::Values(125.0, 500.0));

}  // namespace
}  // namespace hrcsense

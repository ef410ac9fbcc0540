// SPDX-License-Identifier: Apache-2.0
// CellFusion: the fuser's memory of a cell's cameras and the one measurement it makes of them
// (docs/MULTICAMERA.md). Hand-made measurements; every expected value is worked out here.
#include "hrcsense/fusion.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int64_t kMs = 1'000'000;
constexpr int64_t kT0 = 1'800'000'000'000'000'000;  // a shared-clock time in 2027

LinkContact link_at(int link, float distance_m, float z_d_m = 0.02F, float speed_mps = 0.0F) {
  LinkContact l;
  l.link = link;
  l.contact.valid = true;
  l.contact.distance_m = distance_m;
  l.contact.robot_link = link;
  l.contact.closest_base = {distance_m, 0.0F, 1.0F};
  l.speed_towards_mps = speed_mps;
  l.distance_uncertainty_m = z_d_m;
  return l;
}

// A valid measurement of camera `name` captured at `capture_ns`, with `links` (the overall
// contact their nearest).
CameraMeasurement measured(const std::string& name, int64_t capture_ns, std::vector<LinkContact> links,
                           uint32_t session = 7, uint64_t sequence = 1) {
  CameraMeasurement m;
  m.camera_name = name;
  m.session = session;
  m.sequence = sequence;
  m.frame = 100;
  m.capture_ns = capture_ns;
  m.nominal_fps = 30.0;
  m.valid = true;
  m.reason_code = ReasonCode::clear;
  m.links = std::move(links);
  for (const LinkContact& l : m.links) {
    if (!m.contact.valid || l.contact.distance_m < m.contact.distance_m) m.contact = l.contact;
  }
  m.foreground_points = m.links.empty() ? 0U : 500U;
  m.valid_share = 0.9F;
  m.robot_state.valid = true;
  m.robot_state.q_rad = {0.1, -1.0, 1.2, 0.0, 1.5, 0.0};
  return m;
}

FusionParams zones_params() {
  FusionParams p;
  p.safety.mode = SafetyParams::Mode::zones;
  p.safety.max_frame_gap_periods = 2.0;
  return p;
}

CellFusion two_cameras(FusionParams params = zones_params()) {
  return CellFusion({{"front", 30.0}, {"left", 30.0}}, std::move(params));
}

TEST(CellFusion, EachLinkTakesTheNearestCameraAndTheOldestCaptureStartsTr) {
  CellFusion fusion = two_cameras();
  // front sees link 2 at 1.0 m; left, 10 ms earlier, sees link 2 at 0.8 m and link 3 at 1.5 m.
  ASSERT_EQ(fusion.add(measured("front", kT0, {link_at(2, 1.0F)}), kT0 + 5 * kMs), FusionIntake::accepted);
  ASSERT_EQ(fusion.add(measured("left", kT0 - 10 * kMs, {link_at(2, 0.8F), link_at(3, 1.5F)}), kT0 + 5 * kMs),
            FusionIntake::accepted);
  Measurement out;
  fusion.fuse(kT0, 100, kT0 + 6 * kMs, out);
  ASSERT_TRUE(out.valid) << out.withheld_reason;
  ASSERT_EQ(out.links.size(), 2U);
  EXPECT_EQ(out.links[0].link, 2);
  EXPECT_FLOAT_EQ(out.links[0].contact.distance_m, 0.8F);
  EXPECT_EQ(out.links[1].link, 3);
  EXPECT_FLOAT_EQ(out.links[1].contact.distance_m, 1.5F);
  EXPECT_FLOAT_EQ(out.contact.distance_m, 0.8F);
  EXPECT_EQ(fusion.camera_of_link(2), "left");
  EXPECT_EQ(fusion.camera_of_link(3), "left");
  EXPECT_EQ(out.seen_ns, kT0 - 10 * kMs);  // left's capture, the older one
  EXPECT_EQ(out.timestamp_ns, kT0);
  EXPECT_EQ(out.foreground_points, 1000U);
  ASSERT_EQ(out.cameras.size(), 2U);
  EXPECT_EQ(out.cameras[0].name, "front");
  EXPECT_NEAR(out.cameras[0].age_ms, 6.0, 1e-9);
  EXPECT_NEAR(out.cameras[1].age_ms, 16.0, 1e-9);
  EXPECT_TRUE(out.cameras[1].valid);
  EXPECT_EQ(out.cameras[1].session, 7U);
}

TEST(CellFusion, ACameraOlderThanTwoPeriodsIsStaleByName) {
  CellFusion fusion = two_cameras();
  fusion.add(measured("front", kT0, {}), kT0);
  fusion.add(measured("left", kT0, {}), kT0);
  Measurement out;
  // 2 periods at 30 frames/s are 66.7 ms: at 60 ms both are fresh.
  fusion.fuse(kT0, 1, kT0 + 60 * kMs, out);
  EXPECT_TRUE(out.valid) << out.withheld_reason;
  // front goes on; left's newest valid capture is then 70 ms old.
  fusion.add(measured("front", kT0 + 66 * kMs, {}, 7, 2), kT0 + 66 * kMs);
  fusion.fuse(kT0 + 66 * kMs, 3, kT0 + 70 * kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::camera_stale);
  EXPECT_NE(out.withheld_reason.find("'left'"), std::string::npos) << out.withheld_reason;
  EXPECT_EQ(out.withheld_reason.find("'front'"), std::string::npos) << out.withheld_reason;
  EXPECT_EQ(out.cameras[1].reason_code, ReasonCode::camera_stale);
  EXPECT_FALSE(out.cameras[1].valid);
  EXPECT_TRUE(out.cameras[0].valid);
}

TEST(CellFusion, TheClockOffsetBoundAgesEveryCaptureForTrAndTheStaleRule) {
  // cell.clock_offset_max_s 5 ms: each capture counts as 5 ms older than its stamp.
  FusionParams params = zones_params();
  params.clock_offset_max_ns = 5 * kMs;
  CellFusion fusion = two_cameras(params);
  fusion.add(measured("front", kT0, {link_at(2, 1.0F)}), kT0);
  fusion.add(measured("left", kT0 - 10 * kMs, {link_at(2, 0.8F)}), kT0);
  Measurement out;
  fusion.fuse(kT0, 1, kT0 + 50 * kMs, out);
  ASSERT_TRUE(out.valid) << out.withheld_reason;
  EXPECT_EQ(out.seen_ns, kT0 - 15 * kMs);  // left's capture, 5 ms earlier
  EXPECT_NEAR(out.cameras[0].age_ms, 55.0, 1e-9);
  EXPECT_NEAR(out.cameras[1].age_ms, 65.0, 1e-9);
  // At 53 ms left is 63 ms old by its stamp, within two periods (66.7 ms), but 68 ms with the
  // bound: stale. Without the bound it would still count.
  fusion.fuse(kT0, 1, kT0 + 53 * kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::camera_stale);
  EXPECT_NE(out.withheld_reason.find("'left'"), std::string::npos) << out.withheld_reason;
  CellFusion unbounded = two_cameras();
  unbounded.add(measured("front", kT0, {link_at(2, 1.0F)}), kT0);
  unbounded.add(measured("left", kT0 - 10 * kMs, {link_at(2, 0.8F)}), kT0);
  unbounded.fuse(kT0, 1, kT0 + 53 * kMs, out);
  EXPECT_TRUE(out.valid) << out.withheld_reason;
  EXPECT_EQ(out.seen_ns, kT0 - 10 * kMs);
}

TEST(CellFusion, ACameraNeverHeardIsStale) {
  CellFusion fusion = two_cameras();
  fusion.add(measured("front", kT0, {}), kT0);
  Measurement out;
  fusion.fuse(kT0, 1, kT0 + kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::camera_stale);
  EXPECT_NE(out.withheld_reason.find("'left': no measurement yet"), std::string::npos) << out.withheld_reason;
  EXPECT_TRUE(std::isnan(out.cameras[1].age_ms));
}

TEST(CellFusion, ACamerasOwnStopStopsTheCellAtOnceWithItsCode) {
  CellFusion fusion = two_cameras();
  fusion.add(measured("front", kT0, {}), kT0);
  fusion.add(measured("left", kT0, {}), kT0);
  CameraMeasurement blocked = measured("left", kT0 + 33 * kMs, {}, 7, 2);
  blocked.valid = false;
  blocked.reason_code = ReasonCode::camera_blocked;
  blocked.reason = "a surface 0.1 m in front of the camera";
  ASSERT_EQ(fusion.add(blocked, kT0 + 34 * kMs), FusionIntake::accepted);
  Measurement out;
  fusion.fuse(kT0 + 33 * kMs, 2, kT0 + 35 * kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::camera_blocked);
  EXPECT_NE(out.withheld_reason.find("camera 'left': a surface 0.1 m"), std::string::npos) << out.withheld_reason;
}

TEST(CellFusion, ARestartedCameraIsStaleUntilItsNewSessionsFirstValidMeasurement) {
  CellFusion fusion = two_cameras();
  fusion.add(measured("front", kT0, {}), kT0);
  fusion.add(measured("left", kT0, {}, 7, 40), kT0);
  // left restarts (session 9, sequence from 1) and learns its background first.
  CameraMeasurement learning = measured("left", kT0 + 20 * kMs, {}, 9, 1);
  learning.valid = false;
  learning.reason_code = ReasonCode::learning_background;
  ASSERT_EQ(fusion.add(learning, kT0 + 20 * kMs), FusionIntake::accepted);
  fusion.add(measured("front", kT0 + 20 * kMs, {}, 7, 2), kT0 + 20 * kMs);
  Measurement out;
  fusion.fuse(kT0 + 20 * kMs, 2, kT0 + 21 * kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::camera_stale);
  EXPECT_NE(out.withheld_reason.find("restarted (session 00000009 after 00000007)"), std::string::npos)
      << out.withheld_reason;
  EXPECT_EQ(out.cameras[1].session, 9U);
  // Its first valid measurement ends it.
  fusion.add(measured("left", kT0 + 40 * kMs, {}, 9, 2), kT0 + 40 * kMs);
  fusion.add(measured("front", kT0 + 40 * kMs, {}, 7, 3), kT0 + 40 * kMs);
  fusion.fuse(kT0 + 40 * kMs, 3, kT0 + 41 * kMs, out);
  EXPECT_TRUE(out.valid) << out.withheld_reason;
  EXPECT_EQ(fusion.counters(1).sessions, 2);
}

TEST(CellFusion, BadMeasurementsAreRejectedAndCounted) {
  CellFusion fusion = two_cameras();
  EXPECT_EQ(fusion.add(measured("intruder", kT0, {}), kT0), FusionIntake::unknown_camera);
  EXPECT_EQ(fusion.unknown_camera_count(), 1);
  CameraMeasurement nan = measured("left", kT0, {link_at(1, std::numeric_limits<float>::quiet_NaN())});
  EXPECT_EQ(fusion.add(nan, kT0), FusionIntake::malformed);
  EXPECT_EQ(fusion.counters(1).malformed, 1);
  EXPECT_NE(fusion.counters(1).last_problem.find("links[0].contact.distance_m"), std::string::npos)
      << fusion.counters(1).last_problem;
  CameraMeasurement twice = measured("left", kT0, {link_at(1, 1.0F), link_at(1, 2.0F)});
  EXPECT_EQ(fusion.add(twice, kT0), FusionIntake::malformed);
  CameraMeasurement no_rate = measured("left", kT0, {});
  no_rate.nominal_fps = 0.0;
  EXPECT_EQ(fusion.add(no_rate, kT0), FusionIntake::malformed);
  // A clock 60 ms ahead of the fuser's (the limit is 50 ms).
  EXPECT_EQ(fusion.add(measured("left", kT0 + 60 * kMs, {}), kT0), FusionIntake::clock_ahead);
  EXPECT_EQ(fusion.counters(1).clock_ahead, 1);
  ASSERT_EQ(fusion.add(measured("left", kT0, {}, 7, 5), kT0), FusionIntake::accepted);
  // The same session going back in sequence, or in capture time: out of order.
  EXPECT_EQ(fusion.add(measured("left", kT0 + kMs, {}, 7, 5), kT0 + kMs), FusionIntake::out_of_order);
  EXPECT_EQ(fusion.add(measured("left", kT0 - kMs, {}, 7, 6), kT0 + kMs), FusionIntake::out_of_order);
  EXPECT_EQ(fusion.counters(1).out_of_order, 2);
  EXPECT_EQ(fusion.counters(1).accepted, 1);
  // None of them replaced what was accepted.
  EXPECT_EQ(fusion.newest(1)->sequence, 5U);
}

// Found by fuzz_ros2_measurement: code 0 is how the fuser marks a camera without a fault, so a
// withheld measurement that carried it (and a link's garbage, unchecked on a withheld one) made
// the cell's measurement valid with a negative distance.
TEST(CellFusion, AWithheldMeasurementWithoutAReasonIsRejectedAndTheCellStaysStopped) {
  CellFusion fusion = two_cameras();
  ASSERT_EQ(fusion.add(measured("front", kT0, {link_at(2, 1.5F)}), kT0), FusionIntake::accepted);
  CameraMeasurement silent = measured("left", kT0, {link_at(2, -9.0F)});
  silent.valid = false;
  silent.reason_code = ReasonCode::clear;
  EXPECT_EQ(fusion.add(silent, kT0), FusionIntake::malformed);
  EXPECT_NE(fusion.counters(1).last_problem.find("reason_code: 0"), std::string::npos) << fusion.counters(1).last_problem;
  Measurement out;
  fusion.fuse(kT0, 1, kT0 + kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::camera_stale);
  // With a reason it is accepted, and its own stop is the cell's.
  silent.reason_code = ReasonCode::no_valid_depth;
  EXPECT_EQ(fusion.add(silent, kT0), FusionIntake::accepted);
  fusion.fuse(kT0, 2, kT0 + kMs, out);
  EXPECT_FALSE(out.valid);
  EXPECT_EQ(out.withheld_code, ReasonCode::no_valid_depth);
}

TEST(CellFusion, AGridOfAnotherSizeIsRejected) {
  FusionParams params = zones_params();
  params.grid.enabled = true;
  params.grid.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 1, 1));
  params.grid.voxel_m = 0.5F;  // 2 x 2 x 2 = 8 cubes, one byte
  CellFusion fusion({{"front", 30.0}}, params);
  CameraMeasurement m = measured("front", kT0, {});
  m.seen_free.reset(27);
  EXPECT_EQ(fusion.add(m, kT0), FusionIntake::grid_mismatch);
  m.seen_free.reset(8);
  EXPECT_EQ(fusion.add(m, kT0), FusionIntake::accepted);
}

TEST(CellFusion, TheUnknownDistanceIsToTheNearestCubeNoCameraSawFree) {
  FusionParams params = zones_params();
  params.grid.enabled = true;
  params.grid.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 1, 1));
  params.grid.voxel_m = 0.5F;  // 8 cubes; cube 0's centre (0.25, 0.25, 0.25), cube 1's (0.75, 0.25, 0.25)
  Capsule point;  // the robot: a point at x = -1 beside the box (robot.model points)
  point.a = point.b = Eigen::Vector3f(-1.0F, 0.25F, 0.25F);
  params.robot.points.capsules = {point};
  CellFusion fusion({{"front", 30.0}, {"left", 30.0}}, params);
  CameraMeasurement front = measured("front", kT0, {});
  CameraMeasurement left = measured("left", kT0, {});
  front.seen_free.reset(8);
  left.seen_free.reset(8);
  for (size_t i = 2; i < 8; ++i) front.seen_free.set(i);  // front saw neither cube 0 nor cube 1
  left.seen_free.set(0);                                    // left saw cube 0 (and nothing else)
  front.unknown_distance_m = 0.1F;  // their own per-ray distances are not used with grids
  left.unknown_distance_m = 0.1F;
  ASSERT_EQ(fusion.add(front, kT0), FusionIntake::accepted);
  ASSERT_EQ(fusion.add(left, kT0), FusionIntake::accepted);
  Measurement out;
  fusion.fuse(kT0, 1, kT0, out);
  ASSERT_TRUE(out.valid) << out.withheld_reason;
  // Only cube 1 is seen free by neither: its centre is 1.75 m from the point.
  EXPECT_NEAR(out.unknown_distance_m, 1.75F, 1e-5F);
  ASSERT_EQ(out.seen_free.cells, 8U);
  EXPECT_TRUE(out.seen_free.test(0));
  EXPECT_FALSE(out.seen_free.test(1));
}

TEST(CellFusion, InSsmAFartherButLessCertainContactGovernsItsLink) {
  FusionParams params;
  params.safety.mode = SafetyParams::Mode::ssm;
  // Link 4: front at d with Z_d 0.05 m, left at d + 0.02 m with Z_d 0.30 m; the arm moves towards
  // both at 0.5 m/s. S_p differs only by Z_d, so left's d − S_p is 0.23 m smaller at every d;
  // where that changes the speed scale, left's contact must govern.
  bool compared = false;
  for (float d = 1.0F; d < 5.0F && !compared; d += 0.25F) {
    CellFusion fusion({{"front", 30.0}, {"left", 30.0}}, params);
    fusion.add(measured("front", kT0, {link_at(4, d, 0.05F, 0.5F)}), kT0);
    fusion.add(measured("left", kT0, {link_at(4, d + 0.02F, 0.30F, 0.5F)}), kT0);
    Measurement out;
    fusion.fuse(kT0, 1, kT0, out);
    ASSERT_TRUE(out.valid);
    ASSERT_EQ(out.links.size(), 1U);
    EXPECT_FLOAT_EQ(out.links[0].contact.distance_m, d + 0.02F) << "at d = " << d;
    EXPECT_FLOAT_EQ(out.links[0].distance_uncertainty_m, 0.30F);
    EXPECT_EQ(fusion.camera_of_link(4), "left");
    // The fused decision is the stricter of the two cameras' own.
    Decision fused, front_alone, left_alone;
    decide_measurement(params.safety, out, 0.0, 1.0, fused);
    Measurement one = out;
    one.links = {link_at(4, d, 0.05F, 0.5F)};
    decide_measurement(params.safety, one, 0.0, 1.0, front_alone);
    one.links = {link_at(4, d + 0.02F, 0.30F, 0.5F)};
    decide_measurement(params.safety, one, 0.0, 1.0, left_alone);
    EXPECT_FLOAT_EQ(fused.verdict.speed_scale, left_alone.verdict.speed_scale);
    compared = left_alone.verdict.speed_scale < front_alone.verdict.speed_scale;
  }
  EXPECT_TRUE(compared) << "no distance in 1-5 m where the two contacts' speed scales differ";
}

TEST(CellFusion, WithoutGridsTheUnknownDistanceIsTheLargestOfTheCamerasOwn) {
  CellFusion fusion = two_cameras();
  CameraMeasurement front = measured("front", kT0, {});
  front.unknown_distance_m = 0.4F;  // front's view is partly hidden near the arm
  CameraMeasurement left = measured("left", kT0, {});
  left.unknown_distance_m = 0.9F;
  fusion.add(front, kT0);
  fusion.add(left, kT0);
  Measurement out;
  fusion.fuse(kT0, 1, kT0, out);
  // Space hidden from the cell is hidden from both: at least 0.9 m away.
  EXPECT_FLOAT_EQ(out.unknown_distance_m, 0.9F);
  // A camera that knows of no unknown space says nothing: the other's distance stands.
  left.unknown_distance_m = std::numeric_limits<float>::quiet_NaN();
  left.sequence = 2;
  left.capture_ns += kMs;
  fusion.add(left, kT0 + kMs);
  fusion.fuse(kT0 + kMs, 2, kT0 + kMs, out);
  EXPECT_FLOAT_EQ(out.unknown_distance_m, 0.4F);
}

TEST(CellFusion, TheRobotStateGapIsTheLargestAnyCameraHad) {
  CellFusion fusion = two_cameras();
  CameraMeasurement front = measured("front", kT0, {});
  front.robot_state_age_ms = 10.0;
  front.robot_state.extrapolated_ns = 5 * kMs;  // gap 5 ms
  CameraMeasurement left = measured("left", kT0 - 5 * kMs, {});
  left.robot_state_age_ms = 24.0;
  left.robot_state.extrapolated_ns = 4 * kMs;  // gap 20 ms
  fusion.add(front, kT0);
  fusion.add(left, kT0);
  Measurement out;
  fusion.fuse(kT0, 1, kT0, out);
  EXPECT_NEAR(robot_state_gap_s(out), 0.020, 1e-9);
}

TEST(CellFusion, TruthIsTheNearestOverTheCameras) {
  CellFusion fusion = two_cameras();
  CameraMeasurement front = measured("front", kT0, {});
  Contact t;
  t.valid = true;
  t.distance_m = 0.7F;
  front.truth = t;
  front.truth_links = {{1, 0.9F, 0.1F}, {2, 0.7F, 0.0F}};
  CameraMeasurement left = measured("left", kT0, {});
  t.distance_m = 0.5F;
  left.truth = t;
  left.truth_links = {{1, 0.5F, -0.2F}};
  fusion.add(front, kT0);
  fusion.add(left, kT0);
  Measurement out;
  fusion.fuse(kT0, 1, kT0, out);
  ASSERT_TRUE(out.truth);
  EXPECT_FLOAT_EQ(out.truth->distance_m, 0.5F);
  ASSERT_EQ(out.truth_links.size(), 2U);
  EXPECT_FLOAT_EQ(out.truth_links[0].distance_m, 0.5F);
  EXPECT_FLOAT_EQ(out.truth_links[0].speed_towards_mps, -0.2F);
  EXPECT_FLOAT_EQ(out.truth_links[1].distance_m, 0.7F);
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// What `ros2.publish` writes, without a network: the Verdict fields of hand-made results, the
// camera's static transforms against poses worked out by hand, the PointCloud2 bytes of two
// points, and the safety markers (../shared/specs/ros2-interop.md for the message fields).
#include "dds/ros2_output_messages.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace hrcsense::ros2 {
namespace {

// A rigid transform from a quaternion message and a translation, composed by hand (no Eigen
// geometry): R from the unit quaternion's textbook formula.
struct HandPose {
  double R[3][3];
  double t[3];
};

HandPose hand_pose(const geometry_msgs_msg_dds__Quaternion_& q, const geometry_msgs_msg_dds__Vector3_& v) {
  const double x = q.x, y = q.y, z = q.z, w = q.w;
  HandPose p{{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
              {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
              {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}},
             {v.x, v.y, v.z}};
  return p;
}

HandPose compose(const HandPose& a, const HandPose& b) {
  HandPose c{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 3; ++k) c.R[i][j] += a.R[i][k] * b.R[k][j];
    }
    c.t[i] = a.t[i];
    for (int k = 0; k < 3; ++k) c.t[i] += a.R[i][k] * b.t[k];
  }
  return c;
}

// The camera 1 m above the base origin looking along base +x: optical z (forward) = base +x,
// optical x (right) = base -y, optical y (down) = base -z.
Pose camera_up_looking_along_x() {
  Pose T = Pose::Identity();
  Eigen::Matrix3d R;
  R << 0, 0, 1,  //
      -1, 0, 0,  //
      0, -1, 0;
  T.linear() = R;
  T.translation() = Eigen::Vector3d(0.0, 0.0, 1.0);
  return T;
}

TEST(Ros2OutputMessages, VerdictFieldsOfASlowFrameWithAContact) {
  FrameResult result;
  result.timestamp_ns = 1'500'000'123;
  result.verdict.state = VerdictState::slow;
  result.verdict.code = ReasonCode::in_slow_zone;
  result.verdict.speed_scale = 0.5F;
  result.verdict.protective_distance_m = 0.6F;
  result.contact.valid = true;
  result.contact.distance_m = 0.8F;
  result.governing_link = 3;
  result.frame_age_s = 0.04;
  const std::string frame_id = "base_link";
  const hrcsense_msgs_msg_dds__Verdict_ msg = verdict_message(result, 0xCAFEu, 7, frame_id);
  EXPECT_EQ(msg.header.stamp.sec, 1);
  EXPECT_EQ(msg.header.stamp.nanosec, 500'000'123U);
  EXPECT_STREQ(msg.header.frame_id, "base_link");
  EXPECT_EQ(msg.session, 0xCAFEu);
  EXPECT_EQ(msg.seq, 7U);
  EXPECT_EQ(msg.verdict, 1);  // slow
  EXPECT_EQ(msg.reason_code, 2);  // in_slow_zone
  EXPECT_FLOAT_EQ(msg.speed_scale, 0.5F);
  EXPECT_FLOAT_EQ(msg.distance_m, 0.8F);
  EXPECT_FLOAT_EQ(msg.protective_distance_m, 0.6F);
  EXPECT_EQ(msg.governing_link, 3);
  EXPECT_FLOAT_EQ(msg.frame_age_s, 0.04F);
}

TEST(Ros2OutputMessages, VerdictWithoutContactHasNanDistanceAndNoLink) {
  FrameResult result;
  result.timestamp_ns = 33'000'000;
  result.verdict.state = VerdictState::stop;
  result.verdict.code = ReasonCode::below_protective_distance;
  result.verdict.speed_scale = 0.0F;
  const hrcsense_msgs_msg_dds__Verdict_ msg = verdict_message(result, 1, 1, "base");
  EXPECT_EQ(msg.verdict, 2);  // stop
  EXPECT_EQ(msg.reason_code, 28);
  EXPECT_TRUE(std::isnan(msg.distance_m));
  EXPECT_EQ(msg.governing_link, -1);
  EXPECT_EQ(msg.header.stamp.sec, 0);
  EXPECT_EQ(msg.header.stamp.nanosec, 33'000'000U);
  result.verdict.state = VerdictState::run;
  EXPECT_EQ(verdict_message(result, 1, 1, "base").verdict, 0);
  EXPECT_STREQ(base_frame_id(BaseFrame::base), "base");
  EXPECT_STREQ(base_frame_id(BaseFrame::base_link), "base_link");
}

TEST(Ros2OutputMessages, OpticalRotationIsTheD435s) {
  const geometry_msgs_msg_dds__Quaternion_ q = quaternion_msg(T_link_optical_fixed().linear());
  EXPECT_NEAR(q.x, -0.5, 1e-12);
  EXPECT_NEAR(q.y, 0.5, 1e-12);
  EXPECT_NEAR(q.z, -0.5, 1e-12);
  EXPECT_NEAR(q.w, 0.5, 1e-12);
  // Optical z (forward) is link x; optical x (right) is link -y; optical y (down) is link -z.
  const HandPose R = hand_pose(q, {0, 0, 0});
  EXPECT_NEAR(R.R[0][2], 1.0, 1e-12);
  EXPECT_NEAR(R.R[1][2], 0.0, 1e-12);
  EXPECT_NEAR(R.R[2][2], 0.0, 1e-12);
  EXPECT_NEAR(R.R[1][0], -1.0, 1e-12);
  EXPECT_NEAR(R.R[2][1], -1.0, 1e-12);
}

TEST(Ros2OutputMessages, CameraEdgesMultiplyBackToTheCameraPose) {
  const Pose T_base_camera = camera_up_looking_along_x();
  const std::vector<TfEdge> edges = camera_tf_edges(T_base_camera, "base", "d435");
  ASSERT_EQ(edges.size(), 2U);
  EXPECT_EQ(edges[0].parent_frame, "base");
  EXPECT_EQ(edges[0].child_frame, "d435_link");
  EXPECT_EQ(edges[1].parent_frame, "d435_link");
  EXPECT_EQ(edges[1].child_frame, "d435_depth_optical_frame");

  std::vector<geometry_msgs_msg_dds__TransformStamped_> storage;
  tf2_msgs_msg_dds__TFMessage_ msg{};
  fill_tf_message(edges, 0, storage, msg);
  ASSERT_EQ(msg.transforms._length, 2U);
  const geometry_msgs_msg_dds__TransformStamped_& link = msg.transforms._buffer[0];
  const geometry_msgs_msg_dds__TransformStamped_& optical = msg.transforms._buffer[1];
  EXPECT_STREQ(link.header.frame_id, "base");
  EXPECT_STREQ(link.child_frame_id, "d435_link");
  EXPECT_STREQ(optical.header.frame_id, "d435_link");
  EXPECT_STREQ(optical.child_frame_id, "d435_depth_optical_frame");
  EXPECT_EQ(link.header.stamp.sec, 0);
  // Looking along base +x, the camera body's axes are the base's: 1 m up, no rotation.
  EXPECT_NEAR(link.transform.translation.x, 0.0, 1e-12);
  EXPECT_NEAR(link.transform.translation.y, 0.0, 1e-12);
  EXPECT_NEAR(link.transform.translation.z, 1.0, 1e-12);
  EXPECT_NEAR(link.transform.rotation.w, 1.0, 1e-12);
  // Both edges together are camera.T_base_camera.
  const HandPose product = compose(hand_pose(link.transform.rotation, link.transform.translation),
                                   hand_pose(optical.transform.rotation, optical.transform.translation));
  const double want_R[3][3] = {{0, 0, 1}, {-1, 0, 0}, {0, -1, 0}};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(product.R[i][j], want_R[i][j], 1e-12) << i << "," << j;
  }
  EXPECT_NEAR(product.t[2], 1.0, 1e-12);
}

TEST(Ros2OutputMessages, CameraTurnedTowardsBaseYGivesALinkTurnedByNinetyDegrees) {
  // Looking along base +y from (0.5, 0, 2): optical z = +y, optical x (right) = +x, y (down) = -z.
  Pose T_base_camera = Pose::Identity();
  Eigen::Matrix3d R;
  R << 1, 0, 0,  //
      0, 0, 1,   //
      0, -1, 0;
  T_base_camera.linear() = R;
  T_base_camera.translation() = Eigen::Vector3d(0.5, 0.0, 2.0);
  const std::vector<TfEdge> edges = camera_tf_edges(T_base_camera, "base_link", "camera");
  const geometry_msgs_msg_dds__Quaternion_ q = quaternion_msg(edges[0].T_parent_child.linear());
  // 90° about z: (0, 0, sin 45°, cos 45°).
  EXPECT_NEAR(q.x, 0.0, 1e-12);
  EXPECT_NEAR(q.y, 0.0, 1e-12);
  EXPECT_NEAR(q.z, std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(q.w, std::sqrt(0.5), 1e-12);
  EXPECT_EQ(edges[0].parent_frame, "base_link");
}

TEST(Ros2OutputMessages, ChainThroughTheDepthFrame) {
  // realsense-ros: camera_link → camera_depth_frame (a translation) → camera_depth_optical_frame.
  Pose T_link_depth = Pose::Identity();
  T_link_depth.translation() = Eigen::Vector3d(0.0, 0.015, 0.0);
  const std::vector<TfEdge> edges = {
      TfEdge{"camera_depth_frame", "camera_depth_optical_frame", T_link_optical_fixed()},
      TfEdge{"camera_link", "camera_depth_frame", T_link_depth},
      TfEdge{"camera_link", "camera_color_frame", Pose::Identity()},
  };
  const std::optional<Pose> chain = chain_transform(edges, "camera_link", "camera_depth_optical_frame");
  ASSERT_TRUE(chain.has_value());
  // A point 1 m in front of the optical frame is 1 m along link x, 15 mm to its left.
  const Eigen::Vector3d p = *chain * Eigen::Vector3d(0.0, 0.0, 1.0);
  EXPECT_NEAR(p.x(), 1.0, 1e-12);
  EXPECT_NEAR(p.y(), 0.015, 1e-12);
  EXPECT_NEAR(p.z(), 0.0, 1e-12);
  EXPECT_FALSE(chain_transform(edges, "camera_link", "camera_infra1_optical_frame").has_value());
  // A loop ends.
  const std::vector<TfEdge> loop = {TfEdge{"a", "b", Pose::Identity()}, TfEdge{"b", "a", Pose::Identity()}};
  EXPECT_FALSE(chain_transform(loop, "c", "a").has_value());
}

TEST(Ros2OutputMessages, TwoPointsPackToTwentyFourLittleEndianBytes) {
  PointCloud points;
  points.push_back(1.0F, -2.0F, 0.5F, 0);
  points.push_back(0.25F, 0.0F, 3.0F, 1);
  std::vector<uint8_t> bytes;
  pack_xyz(points, bytes);
  const std::vector<uint8_t> want = {
      0x00, 0x00, 0x80, 0x3F,  0x00, 0x00, 0x00, 0xC0,  0x00, 0x00, 0x00, 0x3F,  // 1, -2, 0.5
      0x00, 0x00, 0x80, 0x3E,  0x00, 0x00, 0x00, 0x00,  0x00, 0x00, 0x40, 0x40,  // 0.25, 0, 3
  };
  EXPECT_EQ(bytes, want);

  std::array<sensor_msgs_msg_dds__PointField_, 3> fields{};
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  const std::string frame_id = "base";
  fill_point_cloud(bytes, 2'000'000'001, frame_id, fields, cloud);
  EXPECT_STREQ(cloud.header.frame_id, "base");
  EXPECT_EQ(cloud.header.stamp.sec, 2);
  EXPECT_EQ(cloud.header.stamp.nanosec, 1U);
  EXPECT_EQ(cloud.height, 1U);
  EXPECT_EQ(cloud.width, 2U);
  EXPECT_EQ(cloud.point_step, 12U);
  EXPECT_EQ(cloud.row_step, 24U);
  EXPECT_FALSE(cloud.is_bigendian);
  EXPECT_TRUE(cloud.is_dense);
  ASSERT_EQ(cloud.fields._length, 3U);
  const char* names[3] = {"x", "y", "z"};
  for (uint32_t i = 0; i < 3; ++i) {
    EXPECT_STREQ(cloud.fields._buffer[i].name, names[i]);
    EXPECT_EQ(cloud.fields._buffer[i].offset, 4U * i);
    EXPECT_EQ(cloud.fields._buffer[i].datatype, 7);  // FLOAT32
    EXPECT_EQ(cloud.fields._buffer[i].count, 1U);
  }
  ASSERT_EQ(cloud.data._length, 24U);
  EXPECT_EQ(std::vector<uint8_t>(cloud.data._buffer, cloud.data._buffer + 24), want);
}

// Two capsules, link 2 upright 0.4 m with radius 5 cm, link 3 a point; a person 0.532 m from
// link 2, which governs with S_p 0.3 m.
FrameResult stop_near_link_two(RobotModel& robot) {
  robot.capsules = {Capsule{Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0, 0, 0.4F), 0.05F, 2},
                    Capsule{Eigen::Vector3f(1, 0, 0), Eigen::Vector3f(1, 0, 0), 0.0F, 3}};
  FrameResult result;
  result.verdict.state = VerdictState::stop;
  result.verdict.protective_distance_m = 0.9F;  // not the governing link's own S_p: must not be used
  result.contact.valid = true;
  result.contact.distance_m = 0.532F;
  result.contact.closest_base = Eigen::Vector3f(0.582F, 0.0F, 0.2F);
  result.contact.closest_robot_base = Eigen::Vector3f(0.05F, 0.0F, 0.2F);
  result.governing_link = 2;
  LinkContact far_link;
  far_link.link = 3;
  LinkContact near_link;
  near_link.link = 2;
  result.links = {far_link, near_link};
  result.link_protective_distance_m = {0.1F, 0.3F};
  return result;
}

TEST(Ros2OutputMessages, MarkersStartWithDeleteAllAndShowCapsulesShellAndContact) {
  RobotModel robot;
  const FrameResult result = stop_near_link_two(robot);
  const std::vector<MarkerSpec> markers = safety_markers(result, robot);
  ASSERT_FALSE(markers.empty());
  EXPECT_EQ(markers[0].action, 3);  // DELETEALL

  std::vector<const MarkerSpec*> robot_markers, shell, contact;
  for (const MarkerSpec& m : markers) {
    if (m.ns == "robot") robot_markers.push_back(&m);
    if (m.ns == "protective_distance") shell.push_back(&m);
    if (m.ns == "contact") contact.push_back(&m);
  }
  // Link 2: cylinder + 2 spheres; link 3 (a point): 1 sphere.
  ASSERT_EQ(robot_markers.size(), 4U);
  const MarkerSpec& cylinder = *robot_markers[0];
  EXPECT_EQ(cylinder.type, 3);
  EXPECT_NEAR(cylinder.position.z(), 0.2, 1e-6);
  EXPECT_NEAR(cylinder.scale.x(), 0.1, 1e-6);
  EXPECT_NEAR(cylinder.scale.z(), 0.4, 1e-6);
  EXPECT_EQ(robot_markers[1]->type, 2);
  EXPECT_EQ(robot_markers[3]->type, 2);
  EXPECT_NEAR(robot_markers[3]->position.x(), 1.0, 1e-6);
  // The shell: link 2's capsule grown by its own S_p 0.3 m (diameter 2 * 0.35), red, translucent.
  ASSERT_EQ(shell.size(), 3U);
  for (const MarkerSpec* m : shell) {
    EXPECT_NEAR(m->scale.x(), 0.7, 1e-6);
    EXPECT_FLOAT_EQ(m->color.r, 0.9F);
    EXPECT_FLOAT_EQ(m->color.g, 0.0F);
    EXPECT_LT(m->color.a, 1.0F);
  }
  // The closest pair as a line, the distance as text.
  ASSERT_EQ(contact.size(), 2U);
  EXPECT_EQ(contact[0]->type, 5);  // LINE_LIST
  ASSERT_EQ(contact[0]->points.size(), 2U);
  EXPECT_NEAR(contact[0]->points[0].x(), 0.582, 1e-6);
  EXPECT_NEAR(contact[0]->points[1].x(), 0.05, 1e-6);
  EXPECT_NEAR(contact[0]->points[1].z(), 0.2, 1e-6);
  EXPECT_EQ(contact[1]->type, 9);  // TEXT_VIEW_FACING
  EXPECT_NE(contact[1]->text.find("0.532"), std::string::npos) << contact[1]->text;
  // ids are unique within each namespace
  for (size_t i = 0; i < markers.size(); ++i) {
    for (size_t j = i + 1; j < markers.size(); ++j) {
      EXPECT_FALSE(markers[i].ns == markers[j].ns && markers[i].id == markers[j].id) << markers[i].ns << markers[i].id;
    }
  }
}

TEST(Ros2OutputMessages, MarkerColoursFollowTheVerdict) {
  RobotModel robot;
  FrameResult result = stop_near_link_two(robot);
  const auto line_colour = [&](VerdictState state) {
    result.verdict.state = state;
    for (const MarkerSpec& m : safety_markers(result, robot)) {
      if (m.type == 5) return m.color;
    }
    return MarkerColor{-1, -1, -1, -1};
  };
  const MarkerColor run = line_colour(VerdictState::run);
  const MarkerColor slow = line_colour(VerdictState::slow);
  const MarkerColor stop = line_colour(VerdictState::stop);
  EXPECT_TRUE(run.g > run.r && run.g > run.b) << "run is green";
  EXPECT_TRUE(slow.r > 0.9F && slow.g > 0.5F && slow.b < 0.1F) << "slow is amber";
  EXPECT_TRUE(stop.r > stop.g && stop.r > stop.b) << "stop is red";
}

TEST(Ros2OutputMessages, NoContactNoShellOnlyTheRobot) {
  RobotModel robot;
  FrameResult result = stop_near_link_two(robot);
  result.contact.valid = false;
  result.governing_link = -1;
  const std::vector<MarkerSpec> markers = safety_markers(result, robot);
  ASSERT_EQ(markers.size(), 5U);  // DELETEALL and the robot's 4
  for (size_t i = 1; i < markers.size(); ++i) EXPECT_EQ(markers[i].ns, "robot");
}

TEST(Ros2OutputMessages, MarkerArrayCarriesStampFrameAndText) {
  RobotModel robot;
  const FrameResult result = stop_near_link_two(robot);
  const std::vector<MarkerSpec> specs = safety_markers(result, robot);
  MarkerArrayBuffers buffers;
  visualization_msgs_msg_dds__MarkerArray_ array{};
  const std::string frame_id = "base";
  fill_marker_array(specs, 5'000'000'000, frame_id, buffers, array);
  ASSERT_EQ(array.markers._length, specs.size());
  EXPECT_EQ(array.markers._buffer[0].action, 3);
  for (uint32_t i = 0; i < array.markers._length; ++i) {
    const visualization_msgs_msg_dds__Marker_& m = array.markers._buffer[i];
    EXPECT_STREQ(m.header.frame_id, "base");
    EXPECT_EQ(m.header.stamp.sec, 5);
    EXPECT_NEAR(m.pose.orientation.x * m.pose.orientation.x + m.pose.orientation.y * m.pose.orientation.y +
                    m.pose.orientation.z * m.pose.orientation.z + m.pose.orientation.w * m.pose.orientation.w,
                1.0, 1e-9);
  }
  const visualization_msgs_msg_dds__Marker_& text = array.markers._buffer[array.markers._length - 1];
  EXPECT_EQ(text.type, 9);
  EXPECT_STREQ(text.text, "0.532 m");
  const visualization_msgs_msg_dds__Marker_& line = array.markers._buffer[array.markers._length - 2];
  ASSERT_EQ(line.points._length, 2U);
  EXPECT_NEAR(line.points._buffer[0].x, 0.582, 1e-6);
}

TEST(Ros2OutputMessages, ATransformThatIsNoPoseIsLeftOut) {
  // Another node's /tf_static: a NaN translation, an infinite quaternion and a zero one are no
  // poses; only the good edge, a quarter turn about z (w = x = 0, z = y = sqrt(1/2), given here
  // at twice unit length), comes back, normalised.
  geometry_msgs_msg_dds__TransformStamped_ t[4]{};
  const char* children[] = {"a", "b", "c", "d"};
  for (int i = 0; i < 4; ++i) {
    t[i].header.frame_id = const_cast<char*>("camera_link");
    t[i].child_frame_id = const_cast<char*>(children[i]);
    t[i].transform.rotation = {0.0, 0.0, 0.0, 1.0};
  }
  t[0].transform.translation.x = std::nan("");
  t[1].transform.rotation = {0.0, 0.0, INFINITY, 1.0};
  t[2].transform.rotation = {0.0, 0.0, 0.0, 0.0};
  t[3].transform.rotation = {0.0, 0.0, std::sqrt(2.0), std::sqrt(2.0)};
  t[3].transform.translation = {0.0, 0.015, 0.0};
  tf2_msgs_msg_dds__TFMessage_ message{};
  message.transforms._buffer = t;
  message.transforms._length = message.transforms._maximum = 4;
  const std::vector<TfEdge> edges = tf_edges_from_msg(message);
  ASSERT_EQ(edges.size(), 1U);
  EXPECT_EQ(edges[0].child_frame, "d");
  // x of d is y of camera_link.
  EXPECT_LT((edges[0].T_parent_child.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_EQ(edges[0].T_parent_child.translation(), Eigen::Vector3d(0.0, 0.015, 0.0));
}

}  // namespace
}  // namespace hrcsense::ros2

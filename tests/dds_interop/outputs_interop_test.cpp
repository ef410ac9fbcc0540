// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` with ros2.publish, read from outside: this process subscribes with types built
// from the spec (idl/ros2_spec_types.idl) while hrcsense runs the simulated UR5 cell as a child,
// then every verdict sample is compared with the JSON Lines line it stands for; the speed
// scaling, the markers, the foreground cloud and /tf_static are decoded and checked against the
// same lines and the configured camera pose; a reader on another domain hears nothing.
#include "../support/child_process.hpp"
#include "../support/scenes.hpp"
#include "interop_util.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <string>
#include <vector>

namespace hrcsense::test {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

struct VerdictSample {
  int64_t stamp_ns = 0;
  std::string frame_id;
  uint32_t session = 0, seq = 0;
  int verdict = -1, reason_code = -1, governing_link = 0;
  float speed_scale = 0, distance_m = 0, protective_distance_m = 0, frame_age_s = 0;
};

struct CloudSample {
  int64_t stamp_ns = 0;
  std::string frame_id;
  uint32_t width = 0, height = 0, point_step = 0, row_step = 0;
  std::vector<std::string> field_names;
  std::vector<uint32_t> field_offsets;
  std::vector<int> field_types;
  size_t bytes = 0;
  bool big_endian = true;
  std::vector<float> xyz;  ///< the points, x y z each
};

struct MarkerSample {
  int64_t stamp_ns = 0;
  std::string first_frame_id;
  int first_action = -1;
  size_t count = 0;
  int line_lists = 0;
  std::vector<std::string> texts;
};

Eigen::Isometry3d transform_of(const geometry_msgs_msg_dds__Transform_& t) {
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.translation() = Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
  out.linear() = Eigen::Quaterniond(t.rotation.w, t.rotation.x, t.rotation.y, t.rotation.z).toRotationMatrix();
  return out;
}

// cell-ur5.yaml's camera: translation [2.0, 0, 1.6] m, rpy [-125, 0, 90] deg with docs/CONFIG.md's
// R = Rz(yaw)·Ry(pitch)·Rx(roll).
Eigen::Isometry3d cell_ur5_T_base_camera() {
  const double deg = M_PI / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(90 * deg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(0.0, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(-125 * deg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(2.0, 0.0, 1.6);
  return T;
}

float json_float(const json& value) { return value.is_null() ? NAN : value.get<float>(); }

TEST(Ros2Outputs, EverySampleEqualsItsJsonLineAndTheFramesAreTheConfiguredPose) {
  if (!interop_loopback()) GTEST_SKIP() << kInteropNoLoopback;
  const uint32_t domain = interop_domain();
  Participant participant(domain);
  Participant elsewhere(domain + 1);
  // As a careful ROS 2 node would: reliable, the deadline not shorter than offered.
  const dds_entity_t verdicts =
      participant.endpoint(false, hrcsense_msgs_msg_dds__Verdict__desc, "/hrcsense/verdict", true, false, 256);
  const dds_entity_t other_domain =
      elsewhere.endpoint(false, hrcsense_msgs_msg_dds__Verdict__desc, "/hrcsense/verdict", false, false, 256);
  const dds_entity_t scales = participant.endpoint(false, control_msgs_msg_dds__SpeedScalingFactor__desc,
                                                   "/hrcsense/speed_scaling", true, true, 256);
  const dds_entity_t markers = participant.endpoint(false, visualization_msgs_msg_dds__MarkerArray__desc,
                                                    "/hrcsense/markers", true, false, 64);
  const dds_entity_t clouds =
      participant.endpoint(false, sensor_msgs_msg_dds__PointCloud2__desc, "/hrcsense/foreground", false, false, 64);

  const std::string out = ::testing::TempDir() + "ros2_outputs_" + std::to_string(getpid()) + ".jsonl";
  // Paced, so that the run lasts long enough (4.7 s) to check the cloud's rate against it; the
  // person enters at frame 100.
  ChildProcess child({HRCSENSE_CLI, "run", "--config", scene_path("cell-ur5.yaml"), "--frames", "140", "--out", out,
                      "--set", "ros2.publish=true", "--set", "ros2.domain_id=" + std::to_string(domain), "--set",
                      "ros2.cloud_hz=5", "--set", "source.pace=true"});

  std::vector<VerdictSample> got;
  std::vector<double> factors;
  std::vector<MarkerSample> arrays;
  std::vector<CloudSample> got_clouds;
  int heard_elsewhere = 0;
  bool tf_checked = false;
  std::vector<geometry_msgs_msg_dds__TransformStamped_> tf;
  std::vector<std::string> tf_children, tf_parents;
  std::unique_ptr<Participant> late;  // joins after the first verdict: /tf_static must still reach it
  dds_entity_t tf_reader = 0, late_scales = 0;
  int late_scale_samples = 0;
  const auto drain = [&] {
    take_all<hrcsense_msgs_msg_dds__Verdict_>(verdicts, [&](const hrcsense_msgs_msg_dds__Verdict_& v) {
      got.push_back({stamp_ns(v.header.stamp), v.header.frame_id, v.session, v.seq, v.verdict, v.reason_code,
                     v.governing_link, v.speed_scale, v.distance_m, v.protective_distance_m, v.frame_age_s});
    });
    heard_elsewhere += take_all<hrcsense_msgs_msg_dds__Verdict_>(other_domain, [](const auto&) {});
    take_all<control_msgs_msg_dds__SpeedScalingFactor_>(
        scales, [&](const control_msgs_msg_dds__SpeedScalingFactor_& s) { factors.push_back(s.factor); });
    take_all<visualization_msgs_msg_dds__MarkerArray_>(markers, [&](const visualization_msgs_msg_dds__MarkerArray_& a) {
      MarkerSample sample;
      sample.count = a.markers._length;
      if (sample.count > 0) {
        sample.stamp_ns = stamp_ns(a.markers._buffer[0].header.stamp);
        sample.first_frame_id = a.markers._buffer[0].header.frame_id;
        sample.first_action = a.markers._buffer[0].action;
      }
      for (uint32_t i = 0; i < a.markers._length; ++i) {
        const visualization_msgs_msg_dds__Marker_& m = a.markers._buffer[i];
        if (m.type == 5) ++sample.line_lists;  // LINE_LIST
        if (m.type == 9 && m.text != nullptr) sample.texts.emplace_back(m.text);  // TEXT_VIEW_FACING
      }
      arrays.push_back(sample);
    });
    take_all<sensor_msgs_msg_dds__PointCloud2_>(clouds, [&](const sensor_msgs_msg_dds__PointCloud2_& c) {
      CloudSample s;
      s.stamp_ns = stamp_ns(c.header.stamp);
      s.frame_id = c.header.frame_id;
      s.width = c.width;
      s.height = c.height;
      s.point_step = c.point_step;
      s.row_step = c.row_step;
      s.bytes = c.data._length;
      s.big_endian = c.is_bigendian;
      for (uint32_t i = 0; i < c.fields._length; ++i) {
        s.field_names.emplace_back(c.fields._buffer[i].name);
        s.field_offsets.push_back(c.fields._buffer[i].offset);
        s.field_types.push_back(c.fields._buffer[i].datatype);
      }
      if (c.point_step == 12 && c.data._length % 12 == 0) {
        s.xyz.resize(c.data._length / 4);
        std::memcpy(s.xyz.data(), c.data._buffer, c.data._length);
      }
      got_clouds.push_back(s);
    });
    if (!got.empty() && !late) {
      late = std::make_unique<Participant>(domain);
      tf_reader = late->endpoint(false, tf2_msgs_msg_dds__TFMessage__desc, "/tf_static", true, true, 1);
      late_scales = late->endpoint(false, control_msgs_msg_dds__SpeedScalingFactor__desc, "/hrcsense/speed_scaling",
                                   true, true, 1);
    }
    if (late) {
      take_all<tf2_msgs_msg_dds__TFMessage_>(tf_reader, [&](const tf2_msgs_msg_dds__TFMessage_& m) {
        tf.assign(m.transforms._buffer, m.transforms._buffer + m.transforms._length);
        tf_children.clear();
        tf_parents.clear();
        for (const auto& t : tf) {
          tf_children.emplace_back(t.child_frame_id);
          tf_parents.emplace_back(t.header.frame_id);
        }
        tf_checked = true;
      });
      late_scale_samples += take_all<control_msgs_msg_dds__SpeedScalingFactor_>(late_scales, [](const auto&) {});
    }
  };
  const auto started = std::chrono::steady_clock::now();
  poll_until([&] {
    drain();
    return !child.running();
  }, 120s);
  const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  poll_until([&] { drain(); return false; }, 300ms);  // what was still on its way
  ASSERT_EQ(child.wait(5.0), 0) << "hrcsense run failed";

  // The lines a sample stands for: frame and verdict lines, in order.
  std::vector<json> lines;
  json header;
  for (json& line : json_lines(out)) {
    if (line["type"] == "header") header = line;
    if (line["type"] == "frame" || line["type"] == "verdict") lines.push_back(std::move(line));
  }
  ASSERT_GE(lines.size(), 141U);  // 140 frames and the final stop
  ASSERT_GE(got.size(), 100U) << "most samples arrive (the first ones may go before discovery)";
  // The newest sample is the final stop; seq counts back from it one per line.
  for (size_t i = 1; i < got.size(); ++i) EXPECT_EQ(got[i].seq, got[i - 1].seq + 1) << "a sample was lost";
  const uint32_t last_seq = got.back().seq;
  int contacts = 0;
  for (const VerdictSample& s : got) {
    const size_t back = last_seq - s.seq;
    ASSERT_LT(back, lines.size());
    const json& line = lines[lines.size() - 1 - back];
    SCOPED_TRACE("seq " + std::to_string(s.seq) + ", line " + line.dump().substr(0, 120));
    EXPECT_EQ(s.stamp_ns, line["timestamp_ns"].get<int64_t>());
    EXPECT_EQ(s.frame_id, "base");
    EXPECT_EQ(s.session, header["session"].get<uint32_t>());
    const std::map<std::string, int> verdict_numbers = {{"run", 0}, {"slow", 1}, {"stop", 2}};
    EXPECT_EQ(s.verdict, verdict_numbers.at(line["verdict"].get<std::string>()));
    EXPECT_EQ(s.reason_code, reason_numbers().at(line["reason_code"].get<std::string>()));
    EXPECT_FLOAT_EQ(s.speed_scale, line["speed_scale"].get<float>());
    const float distance = json_float(line["distance_m"]);
    if (std::isnan(distance)) {
      EXPECT_TRUE(std::isnan(s.distance_m));
    } else {
      EXPECT_NEAR(s.distance_m, distance, 1e-5F);
      ++contacts;
    }
    EXPECT_NEAR(s.protective_distance_m, line["protective_distance_m"].get<float>(), 1e-5F);
    EXPECT_EQ(s.governing_link, line["governing_link"].is_null() ? -1 : line["governing_link"].get<int>());
    EXPECT_NEAR(s.frame_age_s, line["frame_age_s"].get<float>(), 1e-5F);
  }
  EXPECT_GT(contacts, 10) << "the person is in the cell from frame 100";
  EXPECT_EQ(lines.back()["type"], "verdict");
  EXPECT_EQ(got.back().verdict, 2);
  EXPECT_EQ(heard_elsewhere, 0) << "a reader on domain " << domain + 1 << " heard hrcsense on " << domain;

  // speed_scaling: each sample is its line's speed_scale, in order, ending with the final stop's
  // pause; latched.
  ASSERT_FALSE(factors.empty());
  ASSERT_LE(factors.size(), lines.size());
  EXPECT_EQ(factors.back(), 0.0);
  for (size_t i = 0; i < factors.size(); ++i) {
    const json& line = lines[lines.size() - factors.size() + i];
    EXPECT_FLOAT_EQ(static_cast<float>(factors[i]), line["speed_scale"].get<float>()) << line.dump().substr(0, 120);
  }
  EXPECT_GE(late_scale_samples, 1) << "a late subscriber gets the latest speed scaling (transient-local)";

  // markers: each array starts by deleting the last one's, in the base frame.
  ASSERT_GE(arrays.size(), 10U);
  int with_pair = 0;
  // One array per line, in order (the first ones may go before discovery): array k of n is line
  // lines.size() - n + k.
  ASSERT_LE(arrays.size(), lines.size());
  for (size_t k = 0; k < arrays.size(); ++k) {
    const MarkerSample& a = arrays[k];
    const json& line = lines[lines.size() - arrays.size() + k];
    SCOPED_TRACE(line.dump().substr(0, 120));
    ASSERT_GE(a.count, 1U);  // a stop without a robot state draws nothing but the DELETEALL
    EXPECT_EQ(a.first_action, 3) << "DELETEALL first";
    EXPECT_EQ(a.first_frame_id, "base");
    EXPECT_EQ(a.stamp_ns, line["timestamp_ns"].get<int64_t>());
    const bool contact = !line["distance_m"].is_null();
    EXPECT_EQ(a.line_lists > 0, contact) << "the closest pair is drawn when the line has one";
    if (!contact) continue;
    ++with_pair;
    // The distance as text, "0.532 m", to the millimetre (half of one for rounding).
    const double distance = line["distance_m"].get<double>();
    bool has_distance = false;
    for (const std::string& text : a.texts) {
      double value = NAN;
      char unit[4] = {};
      if (std::sscanf(text.c_str(), "%lf %3s", &value, unit) == 2 && std::string(unit) == "m") {
        has_distance |= std::abs(value - distance) <= 0.0005 + 1e-6;
      }
    }
    EXPECT_TRUE(has_distance) << "no text giving " << distance << " m";
  }
  EXPECT_GT(with_pair, 0) << "the closest pair is drawn once the person is in the cell";

  // foreground: x, y, z float32, packed, in the base frame, at most cloud_hz per second, each the
  // foreground of the frame with its stamp.
  ASSERT_FALSE(got_clouds.empty());
  int clouds_with_contact = 0;
  EXPECT_LE(static_cast<double>(got_clouds.size()), run_s * 5.0 + 1.0);
  for (const CloudSample& c : got_clouds) {
    EXPECT_EQ(c.frame_id, "base");
    EXPECT_EQ(c.field_names, (std::vector<std::string>{"x", "y", "z"}));
    EXPECT_EQ(c.field_offsets, (std::vector<uint32_t>{0, 4, 8}));
    EXPECT_EQ(c.field_types, (std::vector<int>{7, 7, 7}));  // FLOAT32
    EXPECT_EQ(c.point_step, 12U);
    EXPECT_FALSE(c.big_endian);
    EXPECT_EQ(c.bytes, size_t{c.width} * c.height * 12U);
    EXPECT_EQ(c.row_step, c.width * 12U);
    bool matched = false;
    for (const json& line : lines) {
      if (line["type"] != "frame" || line["timestamp_ns"].get<int64_t>() != c.stamp_ns) continue;
      matched = true;
      EXPECT_EQ(size_t{c.width} * c.height, line["foreground_points"].get<size_t>());
      if (line["closest_base"].is_null()) continue;
      // The closest pair's foreground point (base frame) is one of the cloud's points.
      const std::vector<float> p = line["closest_base"].get<std::vector<float>>();
      double nearest = INFINITY;
      for (size_t i = 0; i + 2 < c.xyz.size(); i += 3) {
        nearest = std::min(nearest, std::hypot(double{c.xyz[i]} - p[0], double{c.xyz[i + 1]} - p[1],
                                               double{c.xyz[i + 2]} - p[2]));
      }
      EXPECT_LT(nearest, 1e-4) << "the cloud lacks the closest pair's point: not the base frame?";
      ++clouds_with_contact;
    }
    EXPECT_TRUE(matched) << "a cloud stamped " << c.stamp_ns << " stands for no frame";
  }
  EXPECT_GT(clouds_with_contact, 0);

  // /tf_static: base → camera_link → camera_depth_optical_frame, equal to camera.T_base_camera.
  ASSERT_TRUE(tf_checked) << "no /tf_static reached a late transient-local reader";
  ASSERT_EQ(tf.size(), 2U);
  std::map<std::string, size_t> by_child;
  for (size_t i = 0; i < tf.size(); ++i) by_child[tf_children[i]] = i;
  ASSERT_EQ(by_child.count("camera_link"), 1U);
  ASSERT_EQ(by_child.count("camera_depth_optical_frame"), 1U);
  const size_t link = by_child["camera_link"], optical = by_child["camera_depth_optical_frame"];
  EXPECT_EQ(tf_parents[link], "base");
  EXPECT_EQ(tf_parents[optical], "camera_link");
  const Eigen::Isometry3d T = transform_of(tf[link].transform) * transform_of(tf[optical].transform);
  const Eigen::Isometry3d expected = cell_ur5_T_base_camera();
  EXPECT_LT((T.translation() - expected.translation()).norm(), 1e-6);
  EXPECT_LT((T.linear() - expected.linear()).norm(), 1e-6);
  // The optical rotation alone: optical z (forward) is the link's x, optical x (right) its -y.
  const Eigen::Matrix3d R = transform_of(tf[optical].transform).linear();
  EXPECT_LT((R * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 1e-9);
  EXPECT_LT((R * Eigen::Vector3d::UnitX() + Eigen::Vector3d::UnitY()).norm(), 1e-9);
  std::remove(out.c_str());
}

}  // namespace
}  // namespace hrcsense::test

// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a camera's hrcsense_msgs/Measurement as Cyclone hands it to the fuser after
// deserialising (its CDR reader is Cyclone's, fuzzed upstream). Any bytes become a message —
// a camera name (one of the two configured, or any text), any session, sequence and stamp,
// links and truth links of any count up to the IDL's bound with any values (NaN, inf, negative,
// link numbers out of range, duplicates), a seen-free grid of any length for any cell count,
// joints of any count — and go through camera_measurement_from, measurement_problem and a
// fuser of two cameras (add, then fuse). The contract: no crash or sanitizer report; an
// accepted measurement has no problem; the fused measurement is either withheld with a reason
// or has finite, non-negative link distances.
#include "field_reader.hpp"
#include "dds/measurement_messages.hpp"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

using Reader = hrcsense::fuzz::FieldReader;

hrcsense_msgs_msg_dds__LinkContact_ any_link(Reader& in) {
  hrcsense_msgs_msg_dds__LinkContact_ l{};
  l.link = in.take<uint8_t>() < 200 ? in.take<uint8_t>() % 10 : in.take<int32_t>();
  l.distance_m = in.take<float>();
  l.inside = (in.take<uint8_t>() & 1U) != 0;
  l.closest_base = {in.take<double>(), in.take<double>(), in.take<double>()};
  l.closest_robot_base = {in.take<double>(), 0.0, 1.0};
  l.closest_camera = {0.0, 0.0, in.take<double>()};
  l.speed_towards_mps = in.take<float>();
  l.distance_uncertainty_m = in.take<float>();
  return l;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense;
  Reader in{data, size};
  FusionParams params;
  params.safety.mode = (in.take<uint8_t>() & 1U) != 0 ? SafetyParams::Mode::ssm : SafetyParams::Mode::zones;
  params.grid.enabled = true;
  params.grid.box_base = Eigen::AlignedBox3f(Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1, 1, 0.5F));
  params.grid.voxel_m = 0.25F;  // 4 x 4 x 2 = 32 cubes
  params.robot.arm = builtin_robot(BuiltinArm::ur5);
  CellFusion fusion({{"front", 30.0}, {"left", 30.0}}, params);
  const int64_t now_ns = 1'800'000'000'000'000'000;

  const int messages = 1 + in.take<uint8_t>() % 4;
  for (int k = 0; k < messages && in.size > 0; ++k) {
    hrcsense_msgs_msg_dds__Measurement_ msg{};
    const uint8_t pick = in.take<uint8_t>();
    std::string name = pick < 100 ? "front" : pick < 200 ? "left" : in.text(40);
    std::string reason = in.text(60);
    std::string frame_id = "base";
    msg.camera_name = name.data();
    msg.reason = reason.data();
    msg.header.frame_id = frame_id.data();
    msg.header.stamp.sec = (in.take<uint8_t>() & 1U) != 0 ? 1'800'000'000 : in.take<int32_t>();
    msg.header.stamp.nanosec = in.take<uint32_t>() % 1'100'000'000U;
    msg.session = in.take<uint32_t>();
    msg.seq = in.take<uint64_t>();
    msg.frame = in.take<int64_t>();
    msg.nominal_fps = (in.take<uint8_t>() & 1U) != 0 ? 30.0 : in.take<double>();
    msg.valid = (in.take<uint8_t>() & 1U) != 0;
    msg.reason_code = in.take<uint16_t>() % 40U;
    msg.has_contact = (in.take<uint8_t>() & 1U) != 0;
    msg.contact = any_link(in);
    std::vector<hrcsense_msgs_msg_dds__LinkContact_> links(in.take<uint8_t>() % 70U);
    for (auto& l : links) l = any_link(in);
    msg.links._length = static_cast<uint32_t>(links.size());
    msg.links._buffer = links.data();
    msg.unknown_distance_m = in.take<float>();
    msg.seen_free_cells = (in.take<uint8_t>() & 1U) != 0 ? 32U : in.take<uint16_t>();
    std::vector<uint8_t> seen(in.take<uint8_t>() % 8U);
    for (uint8_t& b : seen) b = in.take<uint8_t>();
    msg.seen_free._length = static_cast<uint32_t>(seen.size());
    msg.seen_free._buffer = seen.data();
    msg.robot_state_valid = (in.take<uint8_t>() & 1U) != 0;
    std::vector<double> q(in.take<uint8_t>() % 8U), qd(in.take<uint8_t>() % 8U);
    for (double& v : q) v = in.take<double>();
    for (double& v : qd) v = in.take<double>();
    msg.joints_rad._length = static_cast<uint32_t>(q.size());
    msg.joints_rad._buffer = q.data();
    msg.joint_velocities_rad_s._length = static_cast<uint32_t>(qd.size());
    msg.joint_velocities_rad_s._buffer = qd.data();
    msg.robot_state_age_ms = in.take<double>();
    msg.robot_speed_fraction = in.take<double>();
    msg.latency_us = (in.take<uint8_t>() & 1U) != 0 ? 100.0 : in.take<double>();
    msg.has_truth = (in.take<uint8_t>() & 1U) != 0;
    msg.truth = any_link(in);

    CameraMeasurement m;
    if (!ros2::camera_measurement_from(msg, m).empty()) continue;
    if (fusion.add(m, now_ns) == FusionIntake::accepted && !measurement_problem(m).empty()) std::abort();
  }
  Measurement out;
  fusion.fuse(now_ns, 1, now_ns, out);
  if (!out.valid && out.withheld_reason.empty()) std::abort();
  if (out.valid) {
    for (const LinkContact& l : out.links) {
      if (!std::isfinite(l.contact.distance_m) || l.contact.distance_m < 0.0F) std::abort();
    }
  }
  return 0;
}

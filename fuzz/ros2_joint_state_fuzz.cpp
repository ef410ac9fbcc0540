// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a ROS 2 driver's JointState and speed scaling as Cyclone hands them to
// hrcsense after deserialising (its CDR reader is Cyclone's, fuzzed upstream): any bytes become
// a JointState — up to 16 names, each one of UR's six (with or without the tf_prefix looked
// for) or any text (empty, long, a duplicate), position and velocity arrays of any length,
// doubles of any value (NaN and inf among them), any stamp — and go through parse_joint_state;
// a double and a unit go through speed_fraction_from. The contract: no crash or sanitizer
// report; an accepted JointState has six finite positions and velocities and no error; a
// rejected one says why; a speed reading is NaN or within 0..1.
#include "field_reader.hpp"
#include "dds/ros2_joint_state.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

using Reader = hrcsense::fuzz::FieldReader;

// An array length: mostly one per name (what a driver sends), sometimes none, sometimes any.
uint32_t array_length(uint8_t pick, uint32_t names) {
  if (pick < 64) return 0;
  if (pick < 224) return names;
  return pick % 17U;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense::ros2;
  Reader in{data, size};
  const uint8_t flags = in.take<uint8_t>();
  const std::string prefix = (flags & 1U) != 0 ? "ur_" : "";
  const JointNames wanted = ur_joint_names(prefix);
  const JointNames other = ur_joint_names(prefix.empty() ? "ur_" : "");

  sensor_msgs_msg_dds__JointState_ msg{};
  msg.header.stamp.sec = in.take<int32_t>();
  msg.header.stamp.nanosec = in.take<uint32_t>();
  std::string frame_id;
  msg.header.frame_id = frame_id.data();

  const uint32_t count = in.take<uint8_t>() % 17U;
  std::vector<std::string> names;
  for (uint32_t i = 0; i < count; ++i) {
    const uint8_t pick = in.take<uint8_t>();
    if (pick < 120) {
      names.push_back(wanted[pick % 6U]);
    } else if (pick < 160) {
      names.push_back(other[pick % 6U]);
    } else {
      names.push_back(in.text(pick < 250 ? 24 : 255));
    }
  }
  std::vector<char*> name_pointers;
  for (std::string& name : names) name_pointers.push_back(name.data());
  msg.name._buffer = name_pointers.data();
  msg.name._length = msg.name._maximum = count;

  std::vector<double> position(array_length(in.take<uint8_t>(), count));
  std::vector<double> velocity(array_length(in.take<uint8_t>(), count));
  std::vector<double> effort(in.take<uint8_t>() % 4U);
  for (double& value : position) value = in.take<double>();
  for (double& value : velocity) value = in.take<double>();
  msg.position._buffer = position.data();
  msg.position._length = msg.position._maximum = static_cast<uint32_t>(position.size());
  msg.velocity._buffer = velocity.data();
  msg.velocity._length = msg.velocity._maximum = static_cast<uint32_t>(velocity.size());
  msg.effort._buffer = effort.data();
  msg.effort._length = msg.effort._maximum = static_cast<uint32_t>(effort.size());

  const JointStateSample sample = parse_joint_state(msg, wanted);
  if (sample.ok) {
    if (!sample.error.empty() || sample.non_finite) std::abort();
    for (size_t j = 0; j < wanted.size(); ++j) {
      if (!std::isfinite(sample.q_rad[j]) || !std::isfinite(sample.qd_rad_s[j])) std::abort();
    }
  } else if (sample.error.empty()) {
    std::abort();
  }

  const double value = in.take<double>();
  const hrcsense::SpeedScalingUnit unit =
      (flags & 2U) != 0 ? hrcsense::SpeedScalingUnit::fraction : hrcsense::SpeedScalingUnit::percent;
  const double fraction = speed_fraction_from(value, unit);
  if (!std::isnan(fraction) && !(fraction >= 0.0 && fraction <= 1.0)) std::abort();
  return 0;
}

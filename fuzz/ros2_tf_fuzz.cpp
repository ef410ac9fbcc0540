// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a camera node's /tf_static as Cyclone hands it to hrcsense after
// deserialising (its CDR reader is Cyclone's, fuzzed upstream): any bytes become a TFMessage —
// up to 24 transforms between a few realsense-ros frame names or any text (empty, a loop, a
// frame with two parents), translations and quaternions of any doubles (NaN, inf, zero among
// them) — and go through tf_edges_from_msg and chain_transform from camera_link to the depth
// optical frame, as `ros2.publish` with `source.type: ros2` reads it. The contract: no crash or
// sanitizer report, no endless walk; every edge kept and any chain found is a finite pose with
// a rotation (orthonormal, determinant 1).
#include "field_reader.hpp"
#include "dds/ros2_output_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

struct TfReader : hrcsense::fuzz::FieldReader {
  // One of realsense-ros's frames most of the time, so that chains form; else any short text.
  std::string frame() {
    static const char* const kFrames[] = {"camera_link", "camera_depth_frame", "camera_depth_optical_frame",
                                          "camera_color_frame", "base", ""};
    const uint8_t pick = take<uint8_t>();
    if (pick < 200) return kFrames[pick % 6];
    return text(23);
  }
};

bool is_rotation(const Eigen::Matrix3d& r) {
  return r.allFinite() && (r * r.transpose() - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         std::abs(r.determinant() - 1.0) < 1e-6;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense::ros2;
  TfReader in{{data, size}};
  const size_t count = in.take<uint8_t>() % 25;
  std::vector<std::string> parents(count), children(count);
  std::vector<geometry_msgs_msg_dds__TransformStamped_> transforms(count);
  for (size_t i = 0; i < count; ++i) {
    parents[i] = in.frame();
    children[i] = in.frame();
    geometry_msgs_msg_dds__TransformStamped_& t = transforms[i];
    t.header.frame_id = parents[i].data();
    t.child_frame_id = children[i].data();
    t.transform.translation = {in.take<double>(), in.take<double>(), in.take<double>()};
    t.transform.rotation = {in.take<double>(), in.take<double>(), in.take<double>(), in.take<double>()};
  }
  tf2_msgs_msg_dds__TFMessage_ message{};
  message.transforms._buffer = transforms.data();
  message.transforms._length = message.transforms._maximum = static_cast<uint32_t>(count);
  const std::vector<TfEdge> edges = tf_edges_from_msg(message);
  for (const TfEdge& edge : edges) {
    if (!edge.T_parent_child.translation().allFinite() || !is_rotation(edge.T_parent_child.linear())) std::abort();
  }
  const std::optional<hrcsense::Pose> chain =
      chain_transform(edges, camera_link_frame("camera"), camera_optical_frame("camera"));
  if (chain && (!chain->translation().allFinite() || !is_rotation(chain->linear()))) std::abort();
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a cell camera's previews as `hrcsense-view --fused` reads them after Cyclone
// deserialised them (its CDR reader is Cyclone's, fuzzed upstream): a sensor_msgs/PointCloud2 of
// any fields (names, offsets, types, counts), point_step, row_step, size and data, and a
// sensor_msgs/Image of any encoding, size, step and data, through points_from_cloud and
// depth_preview_from. The contract: no crash or sanitizer report; an accepted cloud has only
// finite points, at most width · height of them; an accepted preview has width · height pixels.
#include "field_reader.hpp"
#include "dds/camera_previews.hpp"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense;
  hrcsense::fuzz::FieldReader in{data, size};

  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  std::vector<std::string> names;
  std::vector<sensor_msgs_msg_dds__PointField_> fields(in.take<uint8_t>() % 6U);
  static const char* const kNames[] = {"x", "y", "z", "intensity"};
  for (size_t i = 0; i < fields.size(); ++i) {
    const uint8_t pick = in.take<uint8_t>();
    names.push_back(pick < 200 ? kNames[pick % 4U] : in.text(8));
  }
  for (size_t i = 0; i < fields.size(); ++i) {
    fields[i].name = names[i].data();
    fields[i].offset = in.take<uint8_t>() < 200 ? 4U * (i % 4U) : in.take<uint32_t>();
    fields[i].datatype = in.take<uint8_t>() < 200 ? 7 : in.take<uint8_t>();
    fields[i].count = in.take<uint8_t>() < 200 ? 1U : in.take<uint32_t>();
  }
  cloud.fields._buffer = fields.data();
  cloud.fields._length = static_cast<uint32_t>(fields.size());
  cloud.height = in.take<uint8_t>() < 200 ? 1U : in.take<uint32_t>();
  cloud.width = in.take<uint8_t>() % 64U;
  cloud.point_step = in.take<uint8_t>() < 200 ? 12U : in.take<uint32_t>();
  cloud.row_step = in.take<uint8_t>() < 200 ? cloud.point_step * cloud.width : in.take<uint32_t>();
  cloud.is_bigendian = (in.take<uint8_t>() & 7U) == 0;
  std::vector<uint8_t> bytes(in.take<uint16_t>() % 2048U);
  for (uint8_t& b : bytes) b = in.take<uint8_t>();
  cloud.data._buffer = bytes.data();
  cloud.data._length = static_cast<uint32_t>(bytes.size());
  PointCloud points;
  if (ros2::points_from_cloud(cloud, points).empty()) {
    if (points.size() > uint64_t{cloud.width} * cloud.height) std::abort();
    for (size_t i = 0; i < points.size(); ++i) {
      if (!std::isfinite(points.x[i]) || !std::isfinite(points.y[i]) || !std::isfinite(points.z[i])) std::abort();
    }
  }

  sensor_msgs_msg_dds__Image_ image{};
  std::string encoding = in.take<uint8_t>() < 200 ? "16UC1" : in.text(10);
  image.encoding = encoding.data();
  image.width = in.take<uint8_t>() < 200 ? in.take<uint8_t>() % 32U : in.take<uint32_t>();
  image.height = in.take<uint8_t>() < 200 ? in.take<uint8_t>() % 32U : in.take<uint32_t>();
  image.step = in.take<uint8_t>() < 200 ? 2U * image.width : in.take<uint32_t>();
  image.is_bigendian = in.take<uint8_t>() % 3U;
  std::vector<uint8_t> pixels(in.take<uint8_t>() < 200 ? size_t{image.step} * image.height % 4096U : in.take<uint16_t>());
  for (uint8_t& b : pixels) b = in.take<uint8_t>();
  image.data._buffer = pixels.data();
  image.data._length = static_cast<uint32_t>(pixels.size());
  ros2::DepthPreview preview;
  if (ros2::depth_preview_from(image, preview).empty()) {
    if (preview.depth_mm.size() != static_cast<size_t>(preview.width) * static_cast<size_t>(preview.height)) std::abort();
  }
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the ROS 2 messages a camera node sends, as Cyclone hands them to
// hrcsense after deserialising (its own CDR reader is Cyclone's, fuzzed upstream): any
// bytes become an Image and a CameraInfo — sizes, step, encoding, endianness flag, a data
// length that need not match, K and D with any doubles (NaN and inf among them), any
// distortion model — and go through depth_image_problem / copy_depth_image,
// color_image_problem / copy_color_image and intrinsics_from_camera_info. The contract: no
// crash or sanitizer report; an image is copied only when accepted; CameraInfo either maps
// to finite intrinsics or throws Ros2Error.
#include "field_reader.hpp"
#include "dds/ros2_messages.hpp"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

using Reader = hrcsense::fuzz::FieldReader;

const char* const kEncodings[] = {"16UC1", "mono16", "rgb8", "bgr8", "32FC1", ""};
const char* const kModels[] = {"plumb_bob", "rational_polynomial", "equidistant", "none", "", "fisheye"};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense::ros2;
  Reader in{data, size};
  // Small images only: the point is the checks, not the copy of megabytes.
  const uint32_t width = in.take<uint8_t>() % 65U;
  const uint32_t height = in.take<uint8_t>() % 65U;
  const uint32_t step = in.take<uint16_t>();
  const uint8_t pick = in.take<uint8_t>();
  std::string encoding = pick < 200 ? kEncodings[pick % 6] : in.text(16);
  const uint8_t is_bigendian = in.take<uint8_t>();
  const int expect_w = static_cast<int>(in.take<uint8_t>() % 65U);
  const int expect_h = static_cast<int>(in.take<uint8_t>() % 65U);

  sensor_msgs_msg_dds__CameraInfo_ info{};
  info.width = in.take<uint16_t>();
  info.height = in.take<uint16_t>();
  for (double& k : info.k) k = in.take<double>();
  std::vector<double> d(in.take<uint8_t>() % 10U);
  for (double& value : d) value = in.take<double>();
  const uint8_t model_pick = in.take<uint8_t>();
  std::string model = model_pick < 200 ? kModels[model_pick % 6] : in.text(24);
  info.distortion_model = model.data();
  info.d._buffer = d.data();
  info.d._length = info.d._maximum = static_cast<uint32_t>(d.size());

  std::vector<uint8_t> pixels(in.data, in.data + in.size);  // the rest: any length
  sensor_msgs_msg_dds__Image_ image{};
  image.width = width;
  image.height = height;
  image.step = step;
  image.encoding = encoding.data();
  image.is_bigendian = is_bigendian;
  image.data._buffer = pixels.data();
  image.data._length = image.data._maximum = static_cast<uint32_t>(pixels.size());

  if (depth_image_problem(image, expect_w, expect_h).empty()) {
    hrcsense::DepthImage depth;
    copy_depth_image(image, depth);
    if (depth.width != expect_w || depth.height != expect_h) std::abort();
  }
  if (color_image_problem(image).empty()) {
    hrcsense::ColorImage color;
    copy_color_image(image, color);
    if (color.rgb.size() != 3U * width * height) std::abort();
  }
  try {
    const hrcsense::Intrinsics intrinsics = intrinsics_from_camera_info(info, "/fuzz/camera_info");
    if (!(intrinsics.fx > 0.0F) || !(intrinsics.fy > 0.0F) || intrinsics.width <= 0 || intrinsics.height <= 0) {
      std::abort();
    }
  } catch (const Ros2Error&) {
  }
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — ROS 2 names and message conversions (ros2_messages.hpp).
#include "dds/ros2_messages.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace hrcsense::ros2 {
namespace {

std::string text_of(const char* value) { return value != nullptr ? std::string(value) : std::string(); }

bool is_zero(const double* values, size_t count) {
  return std::all_of(values, values + count, [](double v) { return v == 0.0; });
}

std::string size_text(uint32_t width, uint32_t height) { return std::to_string(width) + "x" + std::to_string(height); }

}  // namespace

CameraTopics realsense_topics(const std::string& node_namespace) {
  CameraTopics topics;
  topics.depth_image = node_namespace + "/depth/image_rect_raw";
  topics.depth_info = node_namespace + "/depth/camera_info";
  topics.color_image = node_namespace + "/color/image_raw";
  topics.color_info = node_namespace + "/color/camera_info";
  topics.extrinsics = node_namespace + "/extrinsics/depth_to_color";
  return topics;
}

std::string camera_info_topic(const std::string& image_topic) {
  const size_t slash = image_topic.rfind('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash)) + "/camera_info";
}

std::string dds_topic_name(const std::string& ros_topic) {
  if (ros_topic.empty() || ros_topic.front() != '/') {
    throw Ros2Error("ROS 2 topic '" + ros_topic + "': expected an absolute name (starting with '/')");
  }
  return "rt" + ros_topic;
}

std::string camera_name_of(const std::string& node_namespace) {
  const size_t slash = node_namespace.rfind('/');
  return slash == std::string::npos ? node_namespace : node_namespace.substr(slash + 1);
}

int64_t stamp_ns(const builtin_interfaces_msg_dds__Time_& stamp) {
  return static_cast<int64_t>(stamp.sec) * 1'000'000'000 + static_cast<int64_t>(stamp.nanosec);
}

builtin_interfaces_msg_dds__Time_ stamp_from_ns(int64_t ns) {
  // Floor division, so that nanosec stays in [0, 1e9) for times before the epoch too.
  int64_t sec = ns / 1'000'000'000;
  int64_t rest = ns % 1'000'000'000;
  if (rest < 0) {
    rest += 1'000'000'000;
    --sec;
  }
  builtin_interfaces_msg_dds__Time_ stamp{};
  stamp.sec = static_cast<int32_t>(sec);
  stamp.nanosec = static_cast<uint32_t>(rest);
  return stamp;
}

namespace {

bool fits_float(double value) { return std::isfinite(value) && std::fabs(value) <= std::numeric_limits<float>::max(); }

// The pinhole part from CameraInfo's K and size (`where` starts every error message); the
// distortion is left to distortion_from_camera_info.
Intrinsics pinhole_from_camera_info(const sensor_msgs_msg_dds__CameraInfo_& info, const std::string& where) {
  const double* k = info.k;
  // Intrinsics are float32 (as the SDK's): a double beyond float's range would become inf.
  for (double value : info.k) {
    if (!fits_float(value)) throw Ros2Error(where + "k: not finite as float32");
  }
  // K = [fx 0 cx; 0 fy cy; 0 0 1] (row-major): anything else is not a pinhole this maps.
  if (!(k[0] > 0.0) || !(k[4] > 0.0) || k[3] != 0.0 || k[6] != 0.0 || k[7] != 0.0 || k[8] != 1.0) {
    throw Ros2Error(where + "k: expected [fx 0 cx; 0 fy cy; 0 0 1] with fx, fy > 0");
  }
  if (info.width == 0 || info.height == 0 || info.width > 65535 || info.height > 65535) {
    throw Ros2Error(where + "size " + size_text(info.width, info.height) + ": expected 1..65535 pixels each way");
  }
  Intrinsics intrinsics;
  intrinsics.width = static_cast<int>(info.width);
  intrinsics.height = static_cast<int>(info.height);
  intrinsics.fx = static_cast<float>(k[0]);
  intrinsics.fy = static_cast<float>(k[4]);
  intrinsics.ppx = static_cast<float>(k[2]);
  intrinsics.ppy = static_cast<float>(k[5]);
  if (!(intrinsics.fx > 0.0F) || !(intrinsics.fy > 0.0F)) {  // a positive double below float's range is 0
    throw Ros2Error(where + "k: fx, fy are 0 as float32");
  }
  // k[1] (skew) is ignored: realsense-ros writes 0, and DESIGN's model has none.
  return intrinsics;
}

// CameraInfo's distortion_model and D as the SDK's model and coefficients, into `intrinsics`;
// throws Ros2Error (starting with `where`) for a model or coefficients the SDK cannot express.
void distortion_from_camera_info(const sensor_msgs_msg_dds__CameraInfo_& info, const std::string& where,
                                 Intrinsics& intrinsics) {
  const std::string model = text_of(info.distortion_model);
  const double* d = info.d._buffer;
  const size_t n = info.d._length;
  for (size_t i = 0; i < n; ++i) {
    if (!fits_float(d[i])) throw Ros2Error(where + "d[" + std::to_string(i) + "]: not finite as float32");
  }
  const std::string count_text = std::to_string(n) + " coefficients";
  if (model == "plumb_bob" || model == "rational_polynomial") {
    // plumb_bob's k1 k2 t1 t2 k3 are the SDK's Brown-Conrady coefficients in the same order;
    // rational_polynomial adds k4 k5 k6 in the denominator, which the SDK's model has not.
    const size_t expected = model == "plumb_bob" ? 5 : 8;
    if (n != expected && !(n < expected && is_zero(d, n))) {
      throw Ros2Error(where + "distortion_model '" + model + "' with " + count_text + ": expected " +
                      std::to_string(expected));
    }
    if (n > 5 && !is_zero(d + 5, n - 5)) {
      throw Ros2Error(where + "distortion_model 'rational_polynomial' with k4-k6 not zero: the SDK's models have "
                      "no rational term (hrcsense maps k1 k2 t1 t2 k3 only)");
    }
    intrinsics.model = Distortion::brown_conrady;
    for (size_t i = 0; i < std::min<size_t>(n, 5); ++i) intrinsics.coeffs[i] = static_cast<float>(d[i]);
    return;
  }
  if (model == "equidistant") {
    if (n != 4 && n != 5) throw Ros2Error(where + "distortion_model 'equidistant' with " + count_text + ": expected 4");
    if (n == 5 && d[4] != 0.0) throw Ros2Error(where + "distortion_model 'equidistant': d[4] must be 0");
    intrinsics.model = Distortion::kannala_brandt4;
    for (size_t i = 0; i < 4; ++i) intrinsics.coeffs[i] = static_cast<float>(d[i]);
    return;
  }
  if ((model.empty() || model == "none") && is_zero(d, n)) {
    intrinsics.model = Distortion::none;
    return;
  }
  throw Ros2Error(where + "distortion_model '" + model + "' (" + count_text +
                  "): hrcsense maps plumb_bob, rational_polynomial (k4-k6 zero), equidistant and none");
}

}  // namespace

Intrinsics intrinsics_from_camera_info(const sensor_msgs_msg_dds__CameraInfo_& info, const std::string& topic) {
  const std::string where = topic + ": CameraInfo ";
  Intrinsics intrinsics = pinhole_from_camera_info(info, where);
  distortion_from_camera_info(info, where, intrinsics);
  return intrinsics;
}

const char* distortion_model_name(Distortion model) {
  return model == Distortion::kannala_brandt4 ? "equidistant" : "plumb_bob";
}

void fill_camera_info(const Intrinsics& intrinsics, int64_t timestamp_ns, const std::string& frame_id,
                      std::vector<double>& d_storage, sensor_msgs_msg_dds__CameraInfo_& info) {
  info = sensor_msgs_msg_dds__CameraInfo_{};
  info.header.stamp = stamp_from_ns(timestamp_ns);
  info.header.frame_id = const_cast<char*>(frame_id.c_str());  // read only by dds_write
  info.width = static_cast<uint32_t>(intrinsics.width);
  info.height = static_cast<uint32_t>(intrinsics.height);
  info.distortion_model = const_cast<char*>(distortion_model_name(intrinsics.model));
  const size_t count = intrinsics.model == Distortion::kannala_brandt4 ? 4 : 5;
  d_storage.assign(intrinsics.coeffs.begin(), intrinsics.coeffs.begin() + static_cast<std::ptrdiff_t>(count));
  info.d._buffer = d_storage.data();
  info.d._length = info.d._maximum = static_cast<uint32_t>(count);
  info.d._release = false;
  const double fx = intrinsics.fx, fy = intrinsics.fy, cx = intrinsics.ppx, cy = intrinsics.ppy;
  const double k[9] = {fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0};
  const double p[12] = {fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  std::copy(std::begin(k), std::end(k), info.k);
  std::copy(std::begin(p), std::end(p), info.p);
  info.r[0] = info.r[4] = info.r[8] = 1.0;
}

std::string depth_image_problem(const sensor_msgs_msg_dds__Image_& image, int width, int height) {
  const std::string encoding = text_of(image.encoding);
  if (encoding != "16UC1" && encoding != "mono16") {
    return "encoding '" + encoding + "': expected 16UC1 (millimetres) or mono16";
  }
  if (image.width == 0 || image.height == 0) return "size " + size_text(image.width, image.height) + ": empty";
  if (image.width != static_cast<uint32_t>(width) || image.height != static_cast<uint32_t>(height)) {
    return "size " + size_text(image.width, image.height) + ": expected " +
           size_text(static_cast<uint32_t>(width), static_cast<uint32_t>(height)) + " (its CameraInfo at the start)";
  }
  if (image.step < 2U * image.width) {
    return "step " + std::to_string(image.step) + ": expected at least " + std::to_string(2U * image.width) +
           " bytes per row";
  }
  const uint64_t expected = static_cast<uint64_t>(image.step) * image.height;
  if (image.data._length != expected) {
    return "data " + std::to_string(image.data._length) + " bytes: expected step x height = " + std::to_string(expected);
  }
  if (image.is_bigendian > 1) return "is_bigendian " + std::to_string(image.is_bigendian) + ": expected 0 or 1";
  return {};
}

void copy_depth_image(const sensor_msgs_msg_dds__Image_& image, DepthImage& out) {
  out.resize(static_cast<int>(image.width), static_cast<int>(image.height));
  out.depth_scale_m = 0.001F;
  for (uint32_t v = 0; v < image.height; ++v) {
    const uint8_t* row = image.data._buffer + static_cast<size_t>(v) * image.step;
    uint16_t* dst = out.pixels.data() + static_cast<size_t>(v) * image.width;
    if (image.is_bigendian == 0) {
      std::memcpy(dst, row, 2U * image.width);  // the host is little-endian, as every ROS 2 tier-1 platform
      continue;
    }
    for (uint32_t u = 0; u < image.width; ++u) {
      dst[u] = static_cast<uint16_t>((row[2 * u] << 8) | row[2 * u + 1]);
    }
  }
}

std::string color_image_problem(const sensor_msgs_msg_dds__Image_& image) {
  const std::string encoding = text_of(image.encoding);
  if (encoding != "rgb8" && encoding != "bgr8") return "encoding '" + encoding + "': expected rgb8 or bgr8";
  if (image.width == 0 || image.height == 0) return "size " + size_text(image.width, image.height) + ": empty";
  if (image.step < 3U * image.width) {
    return "step " + std::to_string(image.step) + ": expected at least " + std::to_string(3U * image.width);
  }
  const uint64_t expected = static_cast<uint64_t>(image.step) * image.height;
  if (image.data._length != expected) {
    return "data " + std::to_string(image.data._length) + " bytes: expected step x height = " + std::to_string(expected);
  }
  return {};
}

void copy_color_image(const sensor_msgs_msg_dds__Image_& image, ColorImage& out) {
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgb.resize(3U * image.width * image.height);
  const bool bgr = text_of(image.encoding) == "bgr8";
  for (uint32_t v = 0; v < image.height; ++v) {
    const uint8_t* row = image.data._buffer + static_cast<size_t>(v) * image.step;
    uint8_t* dst = out.rgb.data() + 3U * image.width * v;
    if (!bgr) {
      std::memcpy(dst, row, 3U * image.width);
      continue;
    }
    for (uint32_t u = 0; u < image.width; ++u) {
      dst[3 * u] = row[3 * u + 2];
      dst[3 * u + 1] = row[3 * u + 1];
      dst[3 * u + 2] = row[3 * u];
    }
  }
}

Extrinsics extrinsics_from_msg(const realsense2_camera_msgs_msg_dds__Extrinsics_& msg) {
  Extrinsics extrinsics;
  for (size_t i = 0; i < 9; ++i) extrinsics.rotation[i] = static_cast<float>(msg.rotation[i]);
  for (size_t i = 0; i < 3; ++i) extrinsics.translation_m[i] = static_cast<float>(msg.translation[i]);
  return extrinsics;
}

realsense2_camera_msgs_msg_dds__Extrinsics_ extrinsics_to_msg(const Extrinsics& extrinsics) {
  realsense2_camera_msgs_msg_dds__Extrinsics_ msg{};
  for (size_t i = 0; i < 9; ++i) msg.rotation[i] = extrinsics.rotation[i];
  for (size_t i = 0; i < 3; ++i) msg.translation[i] = extrinsics.translation_m[i];
  return msg;
}

int64_t StampGapCounter::add(int64_t stamp_ns) {
  const int64_t previous = previous_ns;
  const bool had_previous = has_previous;
  previous_ns = stamp_ns;
  has_previous = true;
  if (!had_previous) return 0;
  const int64_t step_ns = stamp_ns - previous;
  if (step_ns <= 0) {  // a restarted publisher or a looped file: a new sequence
    period_ns = 0;
    return 0;
  }
  if (step_ns > outage_ns) {
    ++outages;
    return 0;
  }
  if (step_ns >= min_period_ns && (period_ns == 0 || step_ns < period_ns)) period_ns = step_ns;
  if (period_ns == 0) return 0;  // no believable period yet
  if (2 * step_ns <= 3 * period_ns) return 0;  // within 1.5 periods: jitter, nothing lost
  const int64_t missed = (step_ns + period_ns / 2) / period_ns - 1;
  frames_missed += missed;
  return missed;
}

int64_t host_time_of_stamp(int64_t stamp_ns, int64_t wall_now_ns, int64_t monotonic_now_ns, int64_t max_offset_ns) {
  const int64_t age_ns = wall_now_ns - stamp_ns;
  if (age_ns < -max_offset_ns || age_ns > max_offset_ns) return monotonic_now_ns;
  return monotonic_now_ns - std::max<int64_t>(age_ns, 0);
}

}  // namespace hrcsense::ros2

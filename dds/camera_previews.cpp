// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — a cell camera's previews (camera_previews.hpp).
#include "dds/camera_previews.hpp"

#include "dds/dds_entity.hpp"
#include "dds/ros2_output_messages.hpp"
#include "hrcsense/clock.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <utility>

namespace hrcsense::ros2 {
namespace {

int64_t previews_steady_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

int64_t preview_period_of(double hz) { return hz > 0.0 ? seconds_to_ns(1.0 / hz) : 0; }

// Due on the host's steady clock: the first at once, then at most one per period.
bool preview_due(int64_t period_ns, int64_t now_ns, int64_t& last_ns) {
  if (period_ns <= 0) return false;
  if (last_ns >= 0 && now_ns - last_ns < period_ns) return false;
  last_ns = now_ns;
  return true;
}

float preview_le_float(const uint8_t* bytes) {
  const uint32_t bits = uint32_t{bytes[0]} | uint32_t{bytes[1]} << 8 | uint32_t{bytes[2]} << 16 | uint32_t{bytes[3]} << 24;
  float value = 0.0F;
  std::memcpy(&value, &bits, sizeof value);
  return value;
}

}  // namespace

CameraPreviewTopics camera_preview_topics(const std::string& node_namespace, const std::string& camera_name) {
  if (!is_camera_name(camera_name)) {
    throw Ros2Error("camera name '" + camera_name + "' is no ROS 2 name token (a letter, then letters, digits, '_')");
  }
  const std::string prefix = node_namespace == "/" ? "" : node_namespace;
  CameraPreviewTopics topics{prefix + "/" + camera_name + "/foreground", prefix + "/" + camera_name + "/depth_preview"};
  dds_topic_name(topics.foreground);  // refuses a namespace that is not absolute
  return topics;
}

void decimate_depth_preview(const DepthImage& depth, int factor, int64_t timestamp_ns, DepthPreview& out) {
  const int f = std::max(factor, 1);
  out.timestamp_ns = timestamp_ns;
  const bool complete = depth.width > 0 && depth.height > 0 &&
                        depth.pixels.size() >= static_cast<size_t>(depth.width) * static_cast<size_t>(depth.height);
  out.width = complete ? depth.width / f : 0;
  out.height = complete ? depth.height / f : 0;
  out.depth_mm.assign(static_cast<size_t>(out.width) * static_cast<size_t>(out.height), 0);
  const double to_mm = static_cast<double>(depth.depth_scale_m) * 1000.0;
  for (int v = 0; v < out.height; ++v) {
    for (int u = 0; u < out.width; ++u) {
      uint16_t nearest = 0;
      for (int dv = 0; dv < f; ++dv) {
        const uint16_t* row = &depth.pixels[static_cast<size_t>(v * f + dv) * depth.width + static_cast<size_t>(u * f)];
        for (int du = 0; du < f; ++du) {
          if (row[du] != 0 && (nearest == 0 || row[du] < nearest)) nearest = row[du];
        }
      }
      const double mm = std::min(65535.0, std::round(nearest * to_mm));
      out.depth_mm[static_cast<size_t>(v) * out.width + u] = static_cast<uint16_t>(mm);
    }
  }
}

std::string points_from_cloud(const sensor_msgs_msg_dds__PointCloud2_& cloud, PointCloud& out) {
  out.clear();
  constexpr uint8_t kFloat32 = 7;
  std::array<int64_t, 3> offsets{-1, -1, -1};
  static const char* const kNames[3] = {"x", "y", "z"};
  if (cloud.fields._length > 0 && cloud.fields._buffer == nullptr) return "fields: no data";
  for (uint32_t i = 0; i < cloud.fields._length; ++i) {
    const sensor_msgs_msg_dds__PointField_& field = cloud.fields._buffer[i];
    if (field.name == nullptr) return "fields[" + std::to_string(i) + "].name: null";
    for (size_t k = 0; k < 3; ++k) {
      if (std::strcmp(field.name, kNames[k]) != 0) continue;
      if (field.datatype != kFloat32 || field.count != 1) {
        return std::string("fields.") + kNames[k] + ": expected one FLOAT32 (7), got datatype " +
               std::to_string(field.datatype) + " count " + std::to_string(field.count);
      }
      offsets[k] = field.offset;
    }
  }
  for (size_t k = 0; k < 3; ++k) {
    if (offsets[k] < 0) return std::string("fields: no '") + kNames[k] + "' field";
    if (offsets[k] + 4 > static_cast<int64_t>(cloud.point_step)) {
      return std::string("point_step: ") + std::to_string(cloud.point_step) + " too short for field " + kNames[k];
    }
  }
  if (cloud.is_bigendian) return "is_bigendian: big-endian clouds are not read";
  const uint64_t points = uint64_t{cloud.width} * uint64_t{cloud.height};
  if (points > kMaxPreviewPoints) return "width x height: " + std::to_string(points) + " points, above the limit";
  // An empty cloud (width or height 0) is read as such: not a loop over 4e9 empty rows (the fuzz
  // target's timeout).
  if (points == 0) return {};
  if (uint64_t{cloud.row_step} < uint64_t{cloud.width} * cloud.point_step) return "row_step: shorter than width x point_step";
  if (uint64_t{cloud.data._length} < uint64_t{cloud.row_step} * cloud.height || (points > 0 && cloud.data._buffer == nullptr)) {
    return "data: " + std::to_string(cloud.data._length) + " bytes, fewer than height x row_step";
  }
  out.reserve(points);
  for (uint32_t r = 0; r < cloud.height; ++r) {
    const uint8_t* row = cloud.data._buffer + uint64_t{r} * cloud.row_step;
    for (uint32_t c = 0; c < cloud.width; ++c) {
      const uint8_t* p = row + uint64_t{c} * cloud.point_step;
      const float x = preview_le_float(p + offsets[0]);
      const float y = preview_le_float(p + offsets[1]);
      const float z = preview_le_float(p + offsets[2]);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) continue;
      out.x.push_back(x);
      out.y.push_back(y);
      out.z.push_back(z);
    }
  }
  return {};
}

std::string depth_preview_from(const sensor_msgs_msg_dds__Image_& image, DepthPreview& out) {
  if (uint64_t{image.width} * image.height > kMaxPreviewPixels) {
    return "width x height: " + std::to_string(image.width) + "x" + std::to_string(image.height) + " above the limit";
  }
  const int width = static_cast<int>(image.width);
  const int height = static_cast<int>(image.height);
  std::string problem = depth_image_problem(image, width, height);
  if (!problem.empty()) return problem;
  DepthImage depth;
  copy_depth_image(image, depth);
  out.width = width;
  out.height = height;
  out.depth_mm = std::move(depth.pixels);
  out.timestamp_ns = stamp_ns(image.header.stamp);
  return {};
}

struct CameraPreviewWriter::Dds {
  ParticipantScope scope;
  dds_entity_t cloud = 0, preview = 0;
  std::array<sensor_msgs_msg_dds__PointField_, 3> cloud_fields{};
  explicit Dds(uint32_t domain_id) : scope(domain_id) {}

  dds_entity_t writer(const dds_topic_descriptor_t& type, const std::string& ros_topic) {
    const std::string name = dds_topic_name(ros_topic);
    const dds_entity_t topic =
        scope.own(dds_create_topic(scope.participant(), &type, name.c_str(), nullptr, nullptr), "DDS topic " + name);
    const QosHandle qos(EndpointQos{true, false, 1});
    return scope.own(dds_create_writer(scope.participant(), topic, qos.get(), nullptr), "DDS writer on " + name);
  }
};

CameraPreviewWriter::CameraPreviewWriter(const CameraPreviewParams& params)
    : topics_(camera_preview_topics(params.node_namespace, params.camera_name)),
      base_frame_(params.base_frame),
      optical_frame_(camera_optical_frame(params.camera_name)),
      dds_(std::make_unique<Dds>(params.domain_id)) {
  dds_->cloud = dds_->writer(sensor_msgs_msg_dds__PointCloud2__desc, topics_.foreground);
  dds_->preview = dds_->writer(sensor_msgs_msg_dds__Image__desc, topics_.depth_preview);
}

CameraPreviewWriter::~CameraPreviewWriter() = default;

bool CameraPreviewWriter::write_cloud(const PointCloud& points_base, int64_t stamp_ns) {
  pack_xyz(points_base, cloud_bytes_);
  sensor_msgs_msg_dds__PointCloud2_ cloud{};
  fill_point_cloud(cloud_bytes_, stamp_ns, base_frame_, dds_->cloud_fields, cloud);
  const dds_return_t ret = dds_write(dds_->cloud, &cloud);
  if (ret < 0) error_ = "DDS write on " + topics_.foreground + ": " + dds_strretcode(ret);
  return ret >= 0;
}

bool CameraPreviewWriter::write_depth_preview(const DepthPreview& preview) {
  sensor_msgs_msg_dds__Image_ image{};
  fill_depth_image_16uc1(preview.depth_mm.data(), preview.width, preview.height, preview.timestamp_ns, optical_frame_,
                         image);
  const dds_return_t ret = dds_write(dds_->preview, &image);
  if (ret < 0) error_ = "DDS write on " + topics_.depth_preview + ": " + dds_strretcode(ret);
  return ret >= 0;
}

int32_t CameraPreviewWriter::readers() const {
  dds_publication_matched_status_t cloud{}, preview{};
  dds_get_publication_matched_status(dds_->cloud, &cloud);
  dds_get_publication_matched_status(dds_->preview, &preview);
  return static_cast<int32_t>(std::min(cloud.current_count, preview.current_count));
}

CameraPreviewSink::CameraPreviewSink(const CameraPreviewParams& params)
    : writer_(params),
      decimation_(std::max(params.decimation, 1)),
      cloud_period_ns_(preview_period_of(params.cloud_hz)),
      preview_period_ns_(preview_period_of(params.preview_hz)) {}

void CameraPreviewSink::on_processed(const Frame& frame, const Pipeline& pipeline, const FrameResult& result) {
  const int64_t now_ns = previews_steady_now_ns();
  // A withheld frame (learning, blocked) has no foreground to show; its depth still does.
  if (result.valid && preview_due(cloud_period_ns_, now_ns, last_cloud_ns_)) {
    const PointCloud& points = pipeline.foreground().points_base;
    tap_.cloud.x.assign(points.x.begin(), points.x.end());
    tap_.cloud.y.assign(points.y.begin(), points.y.end());
    tap_.cloud.z.assign(points.z.begin(), points.z.end());
    tap_.cloud_stamp_ns = frame.timestamp_ns;
    tap_.has_cloud = true;
  }
  if (preview_due(preview_period_ns_, now_ns, last_preview_ns_)) {
    decimate_depth_preview(frame.depth, decimation_, frame.timestamp_ns, tap_.preview);
    tap_.has_preview = true;
  }
  if (!tap_.has_cloud && !tap_.has_preview) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  if (tap_.has_cloud) {
    std::swap(tap_.cloud, shared_.cloud);
    shared_.cloud_stamp_ns = tap_.cloud_stamp_ns;
    shared_.has_cloud = true;
    tap_.has_cloud = false;
  }
  if (tap_.has_preview) {
    std::swap(tap_.preview, shared_.preview);
    shared_.has_preview = true;
    tap_.has_preview = false;
  }
}

void CameraPreviewSink::frame(const FrameResult& /*result*/) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (shared_.has_cloud) {
      std::swap(out_.cloud, shared_.cloud);
      out_.cloud_stamp_ns = shared_.cloud_stamp_ns;
      out_.has_cloud = true;
      shared_.has_cloud = false;
    }
    if (shared_.has_preview) {
      std::swap(out_.preview, shared_.preview);
      out_.has_preview = true;
      shared_.has_preview = false;
    }
  }
  CameraPreviewCounters done;
  if (out_.has_cloud) (writer_.write_cloud(out_.cloud, out_.cloud_stamp_ns) ? done.clouds : done.failed_writes) += 1;
  if (out_.has_preview) (writer_.write_depth_preview(out_.preview) ? done.previews : done.failed_writes) += 1;
  out_.has_cloud = out_.has_preview = false;
  if (done.clouds + done.previews + done.failed_writes == 0) return;
  const std::lock_guard<std::mutex> lock(mutex_);
  counters_.clouds += done.clouds;
  counters_.previews += done.previews;
  counters_.failed_writes += done.failed_writes;
  if (done.failed_writes > 0) counters_.last_error = writer_.error();
}

CameraPreviewCounters CameraPreviewSink::counters() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return counters_;
}

}  // namespace hrcsense::ros2

// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — the 2D pane's pixels on the CPU (view_model.hpp).
#include "viewer/view_model.hpp"

#include "hrcsense/camera.hpp"
#include "hrcsense/proximity.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense::view {
namespace {

constexpr float kRayLength_m = 100.0F;  // the pixel ray as a segment: far beyond any cell

Eigen::Vector3f to_view(const Extrinsics& depth_to_view, const Eigen::Vector3f& p) {
  return transform_point(depth_to_view, p);
}

// Squared distance between segments p1–q1 and p2–q2.
float segment_segment_distance_sq(const Eigen::Vector3f& p1, const Eigen::Vector3f& q1, const Eigen::Vector3f& p2,
                                  const Eigen::Vector3f& q2) {
  float s = 0.0F;
  float t = 0.0F;
  closest_segment_params(p1, q1, p2, q2, s, t);
  return ((p1 + s * (q1 - p1)) - (p2 + t * (q2 - p2))).squaredNorm();
}

void blend_pixel(ColorImage& image, int u, int v, const Rgb& toward, int weight_256) {
  if (u < 0 || v < 0 || u >= image.width || v >= image.height) return;
  uint8_t* px = &image.rgb[3 * (static_cast<size_t>(v) * image.width + u)];
  for (int c = 0; c < 3; ++c) px[c] = static_cast<uint8_t>((px[c] * (256 - weight_256) + toward[c] * weight_256) / 256);
}

// A line of 3 px width (DDA over the longer axis), clipped by put_pixel.
void draw_line(ColorImage& image, const Eigen::Vector2f& from, const Eigen::Vector2f& to, const Rgb& color) {
  const Eigen::Vector2f delta = to - from;
  const float length = std::max(std::abs(delta.x()), std::abs(delta.y()));
  if (!std::isfinite(length)) return;
  const int steps = std::min(static_cast<int>(std::ceil(length)), 1 << 14);
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector2f p = steps == 0 ? from : from + delta * (static_cast<float>(i) / steps);
    const int u = static_cast<int>(std::lround(p.x()));
    const int v = static_cast<int>(std::lround(p.y()));
    for (int dv = -1; dv <= 1; ++dv) {
      for (int du = -1; du <= 1; ++du) put_pixel(image, u + du, v + dv, color);
    }
  }
}

}  // namespace

void put_pixel(ColorImage& image, int u, int v, const Rgb& color) {
  if (u < 0 || v < 0 || u >= image.width || v >= image.height) return;
  uint8_t* px = &image.rgb[3 * (static_cast<size_t>(v) * image.width + u)];
  px[0] = color[0];
  px[1] = color[1];
  px[2] = color[2];
}

void draw_disc(ColorImage& image, const Eigen::Vector2f& centre, int radius_px, const Rgb& color) {
  const int cu = static_cast<int>(std::lround(centre.x()));
  const int cv = static_cast<int>(std::lround(centre.y()));
  for (int dv = -radius_px; dv <= radius_px; ++dv) {
    for (int du = -radius_px; du <= radius_px; ++du) {
      if (du * du + dv * dv <= radius_px * radius_px) put_pixel(image, cu + du, cv + dv, color);
    }
  }
}

ViewCamera view_camera(const ViewFrame& frame) {
  ViewCamera camera;
  if (frame.color && frame.depth_to_color && frame.color_intrinsics.width == frame.color->width &&
      frame.color_intrinsics.height == frame.color->height && frame.color->width > 0) {
    camera.intrinsics = frame.color_intrinsics;
    camera.depth_to_view = *frame.depth_to_color;
  } else {
    camera.intrinsics = frame.depth_intrinsics;
    camera.depth_to_view = Extrinsics{};
  }
  return camera;
}

std::optional<Eigen::Vector2f> project_to_view(const ViewCamera& camera, const Eigen::Vector3f& point_depth_camera) {
  return project(camera.intrinsics, to_view(camera.depth_to_view, point_depth_camera));
}

Rgb jet(float t) {
  static constexpr std::array<std::array<float, 3>, 5> kStops{
      {{0.0F, 0.0F, 255.0F}, {0.0F, 255.0F, 255.0F}, {255.0F, 255.0F, 0.0F}, {255.0F, 0.0F, 0.0F}, {50.0F, 0.0F, 0.0F}}};
  if (!(t > 0.0F)) t = 0.0F;  // NaN too
  if (t > 1.0F) t = 1.0F;
  const float x = t * 4.0F;
  const int i = std::min(static_cast<int>(x), 3);
  const float f = x - static_cast<float>(i);
  Rgb out{};
  for (int c = 0; c < 3; ++c) {
    const float value = kStops[i][c] + (kStops[i + 1][c] - kStops[i][c]) * f;
    out[c] = static_cast<uint8_t>(std::lround(value));
  }
  return out;
}

void equalise_depth(const DepthImage& depth, std::vector<uint32_t>& histogram, std::vector<float>& out) {
  histogram.assign(65536, 0);
  for (uint16_t d : depth.pixels) ++histogram[d];
  histogram[0] = 0;
  for (size_t i = 1; i < histogram.size(); ++i) histogram[i] += histogram[i - 1];
  const float valid = static_cast<float>(histogram.back());
  out.resize(depth.pixels.size());
  for (size_t i = 0; i < depth.pixels.size(); ++i) {
    const uint16_t d = depth.pixels[i];
    out[i] = d == 0 ? -1.0F : static_cast<float>(histogram[d]) / valid;
  }
}

void colorize_depth(const DepthImage& depth, std::vector<uint32_t>& histogram, std::vector<uint32_t>& lut,
                    ColorImage& out) {
  // The colour depends on the raw value alone: one jet() per raw value present (a table over
  // [min, max]), then a lookup per pixel, rather than the map's arithmetic per pixel.
  histogram.assign(65536, 0);
  uint16_t lo = 65535;
  uint16_t hi = 0;
  for (uint16_t d : depth.pixels) {
    ++histogram[d];
    if (d != 0) {
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  histogram[0] = 0;
  out.width = depth.width;
  out.height = depth.height;
  out.rgb.assign(depth.pixels.size() * 3, 0);
  if (hi == 0) return;  // no valid pixel: all black
  for (size_t i = lo; i <= hi; ++i) histogram[i] += histogram[i - 1];
  const float valid = static_cast<float>(histogram[hi]);
  lut.resize(static_cast<size_t>(hi - lo) + 1);
  for (size_t d = lo; d <= hi; ++d) {
    const Rgb c = jet(static_cast<float>(histogram[d]) / valid);
    lut[d - lo] = uint32_t{c[0]} | (uint32_t{c[1]} << 8) | (uint32_t{c[2]} << 16);
  }
  uint8_t* rgb = out.rgb.data();
  for (size_t i = 0; i < depth.pixels.size(); ++i) {
    const uint16_t d = depth.pixels[i];
    if (d == 0) continue;
    const uint32_t packed = lut[d - lo];
    rgb[3 * i] = static_cast<uint8_t>(packed);
    rgb[3 * i + 1] = static_cast<uint8_t>(packed >> 8);
    rgb[3 * i + 2] = static_cast<uint8_t>(packed >> 16);
  }
}

void robot_mask(const std::vector<Capsule>& capsules_base, const Pose& T_camera_base, const ViewCamera& camera,
                std::vector<uint8_t>& mask) {
  const Intrinsics& in = camera.intrinsics;
  mask.assign(static_cast<size_t>(in.width) * in.height, 0);
  if (in.width <= 0 || in.height <= 0) return;
  const Eigen::Isometry3f T = T_camera_base.cast<float>();
  for (const Capsule& capsule : capsules_base) {
    if (!(capsule.radius_m >= 0.0F)) continue;
    const Eigen::Vector3f a = to_view(camera.depth_to_view, T * capsule.a);
    const Eigen::Vector3f b = to_view(camera.depth_to_view, T * capsule.b);
    if (!a.allFinite() || !b.allFinite()) continue;
    const float r = capsule.radius_m;
    const float radius_sq = r * r;
    // The projected bounding box (pixels), or the whole image when the capsule comes near the
    // camera's plane (its projection is unbounded there).
    int u0 = 0, v0 = 0, u1 = in.width - 1, v1 = in.height - 1;
    const float z_min = std::min(a.z(), b.z()) - r;
    if (z_min <= 0.0F && std::max(a.z(), b.z()) + r <= 0.0F) continue;  // wholly behind
    if (z_min > 0.05F) {
      const std::optional<Eigen::Vector2f> pa = project(in, a);
      const std::optional<Eigen::Vector2f> pb = project(in, b);
      if (!pa || !pb) continue;
      const float r_px = std::max(in.fx, in.fy) * r / z_min + 3.0F;
      u0 = std::max(u0, static_cast<int>(std::floor(std::min(pa->x(), pb->x()) - r_px)));
      u1 = std::min(u1, static_cast<int>(std::ceil(std::max(pa->x(), pb->x()) + r_px)));
      v0 = std::max(v0, static_cast<int>(std::floor(std::min(pa->y(), pb->y()) - r_px)));
      v1 = std::min(v1, static_cast<int>(std::ceil(std::max(pa->y(), pb->y()) + r_px)));
    }
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        uint8_t& m = mask[static_cast<size_t>(v) * in.width + u];
        if (m) continue;
        const std::optional<Eigen::Vector3f> ray =
            deproject(in, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)), 1.0F);
        if (!ray) continue;
        const Eigen::Vector3f far = ray->normalized() * kRayLength_m;
        if (segment_segment_distance_sq(Eigen::Vector3f::Zero(), far, a, b) <= radius_sq) m = 1;
      }
    }
  }
}

namespace {

// The depth image in the view camera's grid, coloured and blended over the colour image (or
// alone without one). False, with `out` left black, when the frame has no depth of the view's
// size.
bool paint_depth_over_color(const ViewFrame& frame, const ViewCamera& camera, float depth_alpha,
                            ComposeScratch& scratch, ColorImage& out) {
  const Intrinsics& in = camera.intrinsics;
  const bool with_color = in.width == frame.color_intrinsics.width && frame.color && frame.depth_to_color &&
                          in.width == frame.color->width;
  // Depth in the view camera's grid, coloured.
  const DepthImage* depth = &frame.depth;
  if (with_color) {
    scratch.align.apply(frame.depth, frame.depth_intrinsics, in, camera.depth_to_view, scratch.aligned_depth);
    depth = &scratch.aligned_depth;
  }
  out.width = in.width;
  out.height = in.height;
  out.rgb.assign(static_cast<size_t>(in.width) * in.height * 3, 0);
  if (depth->width != in.width || depth->height != in.height) return false;
  colorize_depth(*depth, scratch.histogram, scratch.lut, scratch.depth_rgb);
  // Blend in integers, weights out of 256, rounded to nearest: (1 - a)·colour + a·depth.
  const int weight = static_cast<int>(std::lround(std::clamp(depth_alpha, 0.0F, 1.0F) * 256.0F));
  if (with_color) {
    const uint8_t* color = frame.color->rgb.data();
    const uint8_t* depth_rgb = scratch.depth_rgb.rgb.data();
    uint8_t* dst = out.rgb.data();
    for (size_t i = 0; i < out.rgb.size(); ++i) {
      dst[i] = static_cast<uint8_t>(((256 - weight) * color[i] + weight * depth_rgb[i] + 128) >> 8);
    }
  } else {
    out.rgb = scratch.depth_rgb.rgb;
  }
  return true;
}

// Foreground points (depth-camera frame), tinted towards the contact marker's colour over their
// footprint scaled to the view camera's focal length. The mask keeps a pixel covered by two
// points from being tinted twice.
void tint_foreground_points(const ViewFrame& frame, const ViewCamera& camera, ComposeScratch& scratch,
                            ColorImage& out) {
  const Intrinsics& in = camera.intrinsics;
  const float focal_ratio = frame.depth_intrinsics.fx > 0.0F ? in.fx / frame.depth_intrinsics.fx : 1.0F;
  const int side = std::clamp(static_cast<int>(std::lround(frame.foreground_footprint * focal_ratio)), 1, 16);
  scratch.tinted.assign(static_cast<size_t>(in.width) * in.height, 0);
  for (size_t i = 0; i + 2 < frame.foreground_camera.size(); i += 3) {
    const Eigen::Vector3f p(frame.foreground_camera[i], frame.foreground_camera[i + 1], frame.foreground_camera[i + 2]);
    const std::optional<Eigen::Vector2f> px = project_to_view(camera, p);
    if (!px || !px->allFinite()) continue;
    const int u0 = static_cast<int>(std::lround(px->x() - 0.5F * static_cast<float>(side - 1)));
    const int v0 = static_cast<int>(std::lround(px->y() - 0.5F * static_cast<float>(side - 1)));
    for (int v = std::max(v0, 0); v < std::min(v0 + side, in.height); ++v) {
      for (int u = std::max(u0, 0); u < std::min(u0 + side, in.width); ++u) {
        uint8_t& done = scratch.tinted[static_cast<size_t>(v) * in.width + u];
        if (done) continue;
        done = 1;
        blend_pixel(out, u, v, kContactMarker, 96);
      }
    }
  }
}

// The robot's capsules as the view camera sees them: brightened, their outline exact (a pixel
// on the image border counts as outline).
void paint_robot_silhouette(const ViewFrame& frame, const ViewCamera& camera, ComposeScratch& scratch,
                            ColorImage& out) {
  const Intrinsics& in = camera.intrinsics;
  robot_mask(frame.capsules_base, frame.T_camera_base, camera, scratch.robot);
  const std::vector<uint8_t>& robot = scratch.robot;
  for (int v = 0; v < in.height; ++v) {
    for (int u = 0; u < in.width; ++u) {
      const size_t i = static_cast<size_t>(v) * in.width + u;
      if (!robot[i]) continue;
      const bool edge = u == 0 || v == 0 || u == in.width - 1 || v == in.height - 1 || !robot[i - 1] ||
                        !robot[i + 1] || !robot[i - in.width] || !robot[i + in.width];
      if (edge) {
        put_pixel(out, u, v, kRobotOutline);
      } else {
        blend_pixel(out, u, v, Rgb{255, 255, 255}, 128);
      }
    }
  }
}

// The closest pair (foreground point in the depth-camera frame, robot point in the base frame)
// and the line between them; an end that does not project into the view is left out.
void draw_closest_pair(const ViewFrame& frame, const ViewCamera& camera, int marker_radius_px, ColorImage& out) {
  if (!frame.contact.valid) return;
  const std::optional<Eigen::Vector2f> contact_px = project_to_view(camera, frame.contact.closest_camera);
  const Eigen::Vector3f robot_camera = frame.T_camera_base.cast<float>() * frame.contact.closest_robot_base;
  const std::optional<Eigen::Vector2f> robot_px = project_to_view(camera, robot_camera);
  if (contact_px && robot_px) draw_line(out, *contact_px, *robot_px, kContactLine);
  if (robot_px) draw_disc(out, *robot_px, marker_radius_px, kRobotMarker);
  if (contact_px) draw_disc(out, *contact_px, marker_radius_px, kContactMarker);
}

}  // namespace

void compose_2d(const ViewFrame& frame, float depth_alpha, int marker_radius_px, ComposeScratch& scratch,
                ColorImage& out) {
  const ViewCamera camera = view_camera(frame);
  // A frame without depth of the view's size stays black: nothing else would line up with it.
  if (!paint_depth_over_color(frame, camera, depth_alpha, scratch, out)) return;
  tint_foreground_points(frame, camera, scratch, out);
  paint_robot_silhouette(frame, camera, scratch, out);
  draw_closest_pair(frame, camera, marker_radius_px, out);
}

Timeline::Timeline(double window_s, size_t max_points) : window_s_(window_s), max_points_(max_points) {
  points_.reserve(max_points);
}

void Timeline::add(const TimelinePoint& point) {
  points_.push_back(point);
  const auto window_ns = static_cast<int64_t>(window_s_ * 1e9);
  size_t first = 0;
  while (first < points_.size() && (point.made_ns - points_[first].made_ns > window_ns ||
                                    points_.size() - first > max_points_)) {
    ++first;
  }
  if (first > 0) points_.erase(points_.begin(), points_.begin() + static_cast<std::ptrdiff_t>(first));
}

RateStats rate_stats(const std::vector<TimelinePoint>& points) {
  RateStats stats;
  if (points.size() < 2) return stats;
  const double frames = static_cast<double>(points.size() - 1);
  const double source_s = static_cast<double>(points.back().timestamp_ns - points.front().timestamp_ns) * 1e-9;
  const double made_s = static_cast<double>(points.back().made_ns - points.front().made_ns) * 1e-9;
  stats.capture_fps = source_s > 0.0 ? frames / source_s : 0.0;
  stats.processing_fps = made_s > 0.0 ? frames / made_s : 0.0;
  std::vector<double> latencies;
  latencies.reserve(points.size());
  for (const TimelinePoint& p : points) latencies.push_back(p.latency_us);
  std::sort(latencies.begin(), latencies.end());
  auto rank = [&](double q) {
    const size_t k = static_cast<size_t>(std::ceil(q * static_cast<double>(latencies.size())));
    return latencies[std::clamp<size_t>(k, 1, latencies.size()) - 1];
  };
  stats.latency_p50_us = rank(0.50);
  stats.latency_p99_us = rank(0.99);
  return stats;
}

ShownState shown_state(const ViewFrame& frame, int64_t now_ns, double max_frame_age_s) {
  if (frame.frame < 0) return ShownState::no_data;
  const double age_s = static_cast<double>(now_ns - frame.made_ns) * 1e-9;
  if (!(age_s <= max_frame_age_s)) return ShownState::no_data;  // NaN age too
  switch (frame.verdict.state) {
    case VerdictState::run: return ShownState::run;
    case VerdictState::slow: return ShownState::slow;
    case VerdictState::stop: return ShownState::stop;
  }
  return ShownState::stop;
}

Rgb state_color(ShownState state) {
  switch (state) {
    case ShownState::run: return kRunColor;
    case ShownState::slow: return kSlowColor;
    case ShownState::stop: return kStopColor;
    case ShownState::no_data: return kNoDataColor;
  }
  return kNoDataColor;
}

const char* state_word(ShownState state) {
  switch (state) {
    case ShownState::run: return "RUN";
    case ShownState::slow: return "SLOW";
    case ShownState::stop: return "STOP";
    case ShownState::no_data: return "NO DATA";
  }
  return "NO DATA";
}

Rect fit_rect(int image_width, int image_height, const Rect& area) {
  if (image_width <= 0 || image_height <= 0 || area.width <= 0 || area.height <= 0) return {area.x, area.y, 0, 0};
  Rect r;
  // Integer arithmetic: the same rule in the renderer and in the tests.
  if (static_cast<int64_t>(area.width) * image_height <= static_cast<int64_t>(area.height) * image_width) {
    r.width = area.width;
    r.height = static_cast<int>(static_cast<int64_t>(area.width) * image_height / image_width);
  } else {
    r.height = area.height;
    r.width = static_cast<int>(static_cast<int64_t>(area.height) * image_width / image_height);
  }
  r.x = area.x + (area.width - r.width) / 2;
  r.y = area.y + (area.height - r.height) / 2;
  return r;
}

Rect pane_area(int window_width, int window_height, int border_px, int status_px) {
  Rect r;
  r.x = border_px;
  r.y = border_px;
  r.width = std::max(0, window_width - 2 * border_px);
  r.height = std::max(0, window_height - 2 * border_px - status_px);
  return r;
}

std::optional<PaneMode> parse_pane_mode(const std::string& name) {
  if (name == "2d") return PaneMode::view_2d;
  if (name == "3d") return PaneMode::view_3d;
  if (name == "split") return PaneMode::split;
  return std::nullopt;
}

const char* pane_mode_name(PaneMode mode) {
  switch (mode) {
    case PaneMode::view_2d: return "2d";
    case PaneMode::view_3d: return "3d";
    case PaneMode::split: return "split";
  }
  return "2d";
}

PaneRects pane_rects(PaneMode mode, const Rect& pane, int gap_px) {
  PaneRects rects;
  if (mode == PaneMode::view_2d) rects.image_2d = pane;
  if (mode == PaneMode::view_3d) rects.cloud_3d = pane;
  if (mode == PaneMode::split) {
    const int inner = std::max(0, pane.width - gap_px);
    const int left = inner - inner / 2;
    rects.image_2d = Rect{pane.x, pane.y, left, pane.height};
    rects.cloud_3d = Rect{pane.x + left + gap_px, pane.y, inner / 2, pane.height};
  }
  return rects;
}

}  // namespace hrcsense::view

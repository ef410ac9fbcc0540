// SPDX-License-Identifier: Apache-2.0
// hrcsense viewer — what the 2D pane shows, computed on the CPU without OpenGL, so that every
// pixel rule is a plain function the tests check without a display. The GL part
// (viewer/gl_*.cpp) only uploads the composed image and draws the border and labels.
#pragma once

#include "hrcsense/align.hpp"
#include "hrcsense/types.hpp"

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace hrcsense::view {

using Rgb = std::array<uint8_t, 3>;

// Exact colours the pixel tests look for. None of them is a Jet colour (a Jet colour with red
// and blue both above 0 has green 255 and red + blue = 255), so a depth pixel cannot be
// mistaken for a marker.
inline constexpr Rgb kContactMarker{255, 0, 255};   ///< the foreground's closest point
inline constexpr Rgb kRobotMarker{255, 255, 255};   ///< the robot's closest point
inline constexpr Rgb kRobotOutline{128, 0, 255};    ///< edge pixels of the robot's projection
inline constexpr Rgb kContactLine{255, 0, 128};     ///< the line between the two closest points
inline constexpr Rgb kRunColor{0, 200, 0};
inline constexpr Rgb kSlowColor{255, 170, 0};
inline constexpr Rgb kStopColor{230, 0, 0};
inline constexpr Rgb kNoDataColor{128, 128, 128};

/// A copy of what the viewer shows of one processed frame, made on the processing thread by
/// the view tap, with the verdict the run's SafetyMonitor decided for it on the output thread
/// (its buffers are reused: no allocation once sized).
struct ViewFrame {
  int64_t frame = -1;            ///< source frame index; -1: nothing yet
  int64_t publication = 0;       ///< the view tap's number for it (1, 2, ...); 0: not published
  int64_t timestamp_ns = 0;
  int64_t made_ns = 0;           ///< steady-clock time the result was made (NO DATA)
  DepthImage depth;              ///< the source frame's depth, as received (before filters)
  Intrinsics depth_intrinsics;
  std::optional<ColorImage> color;
  Intrinsics color_intrinsics;   ///< width 0 without colour
  std::optional<Extrinsics> depth_to_color;
  std::vector<float> foreground_camera;  ///< foreground points, camera frame, x y z interleaved
  std::vector<Capsule> capsules_base;    ///< the robot's capsules of this frame (base frame)
  Pose T_camera_base = Pose::Identity(); ///< inverse of the configuration's T_base_camera
  Contact contact;
  Verdict verdict;               ///< the decided verdict (ViewTap::decided), never the viewer's own
  bool valid = false;
  size_t foreground_points = 0;
  /// Depth pixels per foreground point along a row: the depth image's width over the filtered
  /// image's (2 with decimation ×2), so that the highlight covers what the points stand for.
  float foreground_footprint = 1.0F;
  size_t invalid_pixels = 0;
  double latency_us = 0.0;
  float slow_distance_m = 0.0F;
  float stop_distance_m = 0.0F;
};

/// The camera the 2D pane's image is in: the colour camera when the frame has colour and the
/// depth→colour extrinsics, else the depth camera (extrinsics the identity).
struct ViewCamera {
  Intrinsics intrinsics;
  Extrinsics depth_to_view;  ///< depth camera → view camera
};
ViewCamera view_camera(const ViewFrame& frame);

/// Where a depth-camera point lands in the view image (pixel coordinates, pixel centres at
/// integers); none behind the camera.
std::optional<Eigen::Vector2f> project_to_view(const ViewCamera& camera, const Eigen::Vector3f& point_depth_camera);

/// The RealSense colouriser's Jet for t in [0, 1], clamped: linear between (0, 0, 255),
/// (0, 255, 255), (255, 255, 0), (255, 0, 0) and (50, 0, 0) at t = 0, 1/4, 1/2, 3/4 and 1,
/// each channel rounded to the nearest integer.
Rgb jet(float t);

/// Histogram equalisation of raw depth as the RealSense Viewer's colouriser does: each valid
/// raw value maps to the share of valid pixels at or below it (0..1), so that the colours
/// spread over the depths present. Invalid (0) pixels get -1. `out` has one value per pixel.
void equalise_depth(const DepthImage& depth, std::vector<uint32_t>& histogram_scratch, std::vector<float>& out);

/// Depth coloured with jet() after equalise_depth(), invalid black; rgb8 of the depth's size.
/// `lut_scratch` holds one packed colour per raw value between the image's nearest and
/// farthest valid depth.
void colorize_depth(const DepthImage& depth, std::vector<uint32_t>& histogram_scratch,
                    std::vector<uint32_t>& lut_scratch, ColorImage& out);

/// The robot's pixels in the view image: 1 where the ray through the pixel's centre passes
/// within a capsule's radius of its segment (capsules in the base frame, taken to the view
/// camera through T_camera_base and depth_to_view), else 0. Only each capsule's projected
/// bounding box is tested.
void robot_mask(const std::vector<Capsule>& capsules_base, const Pose& T_camera_base, const ViewCamera& camera,
                std::vector<uint8_t>& mask);

/// Sets pixel (u, v) of `image` to `color`; nothing outside the image.
void put_pixel(ColorImage& image, int u, int v, const Rgb& color);
/// A filled disc of `radius_px` around `centre` (rounded to the nearest pixel), clipped.
void draw_disc(ColorImage& image, const Eigen::Vector2f& centre, int radius_px, const Rgb& color);

/// Reusable buffers of compose_2d().
struct ComposeScratch {
  AlignDepthToColor align;
  DepthImage aligned_depth;
  std::vector<uint32_t> histogram;
  std::vector<uint32_t> lut;
  ColorImage depth_rgb;
  std::vector<uint8_t> robot;
  std::vector<uint8_t> tinted;
};

/// Everything the 2D pane draws into the image itself (what the GL part adds: the border, the
/// verdict word and the distance label). With `depth_alpha` a in [0, 1]:
/// - each pixel: (1 − a)·colour + a·jet(equalised aligned depth), invalid depth black in the
///   depth layer (integer weights out of 256, rounded to nearest); without colour the depth
///   layer alone;
/// - foreground points (projected into the view) tinted 3/8 of the way to kContactMarker, each
///   over a square of its footprint (foreground_footprint × the view's over the depth's focal
///   length, at least one pixel);
/// - the robot's pixels (robot_mask) brightened halfway to white, its edge pixels (a robot
///   pixel with a 4-neighbour that is not) exactly kRobotOutline;
/// - with a valid contact: a line between the two closest points, then discs of radius
///   `marker_radius_px` in exactly kContactMarker (foreground point, contact.closest_camera)
///   and kRobotMarker (robot point, contact.closest_robot_base taken to the camera).
/// `out` has the view camera's size.
void compose_2d(const ViewFrame& frame, float depth_alpha, int marker_radius_px, ComposeScratch& scratch,
                ColorImage& out);

/// One processed frame on the timeline: every frame the pipeline made, drawn or not.
struct TimelinePoint {
  int64_t timestamp_ns = 0;  ///< the source's
  int64_t made_ns = 0;       ///< steady clock, when the result was made
  float distance_m = -1.0F;  ///< < 0: no contact (nothing in the cell, or no valid frame)
  VerdictState state = VerdictState::stop;
  double latency_us = 0.0;
};

/// The last `window_s` seconds of results (by made_ns), oldest first, bounded in count.
class Timeline {
 public:
  explicit Timeline(double window_s = 10.0, size_t max_points = 4096);
  void add(const TimelinePoint& point);
  const std::vector<TimelinePoint>& points() const { return points_; }

 private:
  double window_s_;
  size_t max_points_;
  std::vector<TimelinePoint> points_;
};

/// The stats panel's figures over a timeline: source frames per second (by timestamp),
/// processed per second (by made_ns), latency p50 / p99 (nearest rank). Zero with fewer than
/// two points.
struct RateStats {
  double capture_fps = 0.0;
  double processing_fps = 0.0;
  double latency_p50_us = 0.0;
  double latency_p99_us = 0.0;
};
RateStats rate_stats(const std::vector<TimelinePoint>& points);

/// What the border and the word say.
enum class ShownState { run, slow, stop, no_data };

/// The pipeline's verdict of `frame`, or no_data when there is no frame yet or the newest one
/// is older than max_frame_age_s at now_ns (steady clock): a frozen pipeline never leaves a
/// green window. The viewer never computes a verdict of its own.
ShownState shown_state(const ViewFrame& frame, int64_t now_ns, double max_frame_age_s);
Rgb state_color(ShownState state);
const char* state_word(ShownState state);  ///< "RUN", "SLOW", "STOP", "NO DATA"

/// An axis-aligned rectangle in window pixels, origin top left.
struct Rect {
  int x = 0, y = 0, width = 0, height = 0;
};

/// The largest rectangle of the image's aspect ratio inside `area`, centred in it (integer
/// pixels: width and height rounded down, offsets rounded down).
Rect fit_rect(int image_width, int image_height, const Rect& area);

/// The 2D pane's area in a window: the window minus the state border of `border_px` on
/// every side and a status strip of `status_px` at the bottom, inside the border.
Rect pane_area(int window_width, int window_height, int border_px, int status_px);

/// Which panes the window shows: the 2D image, the 3D cloud, or both side by side.
enum class PaneMode { view_2d, view_3d, split };
/// "2d", "3d", "split"; nullopt for another name.
std::optional<PaneMode> parse_pane_mode(const std::string& name);
const char* pane_mode_name(PaneMode mode);

/// Where the panes go inside `pane` (pane_area()): the whole of it for one pane; for split,
/// the left half for the 2D image and the right half for the 3D cloud with a gap of
/// `gap_px` between them (the left half gets the odd pixel). A pane not shown has width 0.
/// The 2D image is then fitted into its rectangle (fit_rect); the 3D cloud is composed at
/// its rectangle's size.
struct PaneRects {
  Rect image_2d;
  Rect cloud_3d;
};
PaneRects pane_rects(PaneMode mode, const Rect& pane, int gap_px);

}  // namespace hrcsense::view

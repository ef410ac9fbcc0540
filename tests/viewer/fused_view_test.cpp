// SPDX-License-Identifier: Apache-2.0
// The fused view's model without a display or DDS (viewer/fused_view.hpp): the fused closest pair
// over hand-set per-link contacts (a withholding camera's nearer contact ignored), the camera
// rows' ages from hand-set capture stamps, and the composed pane's pixels (a camera's cloud in
// its colour at the hand-projected target, the pair's exact marker colours, a preview's frame).
#include "viewer/fused_view.hpp"

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

namespace hrcsense::fused_view_test {
namespace {

using ros2::FusedCameraView;
using ros2::FusedView;
using view::Rgb;

Rgb pixel_at(const ColorImage& image, int u, int v) {
  const size_t i = 3 * (static_cast<size_t>(v) * image.width + u);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

int pixels_of(const ColorImage& image, const Rgb& color) {
  int n = 0;
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) n += pixel_at(image, u, v) == color ? 1 : 0;
  }
  return n;
}

LinkContact link_contact(int link, float distance_m, const Eigen::Vector3f& person, const Eigen::Vector3f& robot) {
  LinkContact c;
  c.link = link;
  c.contact.valid = true;
  c.contact.distance_m = distance_m;
  c.contact.closest_base = person;
  c.contact.closest_robot_base = robot;
  c.contact.robot_link = link;
  return c;
}

FusedCameraView camera_with(const std::string& name, bool valid, std::vector<LinkContact> links, int64_t capture_ns) {
  FusedCameraView camera;
  camera.name = name;
  CameraMeasurement m;
  m.camera_name = name;
  m.valid = valid;
  m.reason_code = valid ? ReasonCode::clear : ReasonCode::learning_background;
  m.reason = valid ? "" : "learning the background";
  m.capture_ns = capture_ns;
  m.links = std::move(links);
  if (!m.links.empty()) m.contact = m.links.front().contact;
  camera.measurement = m;
  return camera;
}

TEST(FusedView, ClosestPairIsTheSmallestOverTheValidCamerasLinks) {
  FusedView view;
  view.cameras.push_back(camera_with("left", true,
                                     {link_contact(1, 0.90F, {1, 0, 1}, {0.2F, 0, 1}),
                                      link_contact(2, 0.70F, {1, 1, 1}, {0.4F, 0.5F, 1})},
                                     1000));
  view.cameras.push_back(camera_with("right", true,
                                     {link_contact(0, 1.20F, {2, 0, 1}, {0.1F, 0, 0.5F}),
                                      link_contact(3, 0.45F, {0.8F, -0.3F, 1.2F}, {0.5F, -0.1F, 0.9F})},
                                     2000));
  // Nearer still, but withheld: it must not count.
  view.cameras.push_back(camera_with("back", false, {link_contact(4, 0.05F, {0, 0, 1}, {0, 0, 0.95F})}, 3000));
  view.cameras.push_back(FusedCameraView{});  // never heard: nothing
  const view::FusedPair pair = view::fused_closest_pair(view);
  ASSERT_TRUE(pair.valid);
  EXPECT_EQ(pair.camera, "right");
  EXPECT_EQ(pair.link, 3);
  EXPECT_FLOAT_EQ(pair.distance_m, 0.45F);
  EXPECT_EQ(pair.closest_base, Eigen::Vector3f(0.8F, -0.3F, 1.2F));
  EXPECT_EQ(pair.closest_robot_base, Eigen::Vector3f(0.5F, -0.1F, 0.9F));
}

TEST(FusedView, NoValidCameraNoPair) {
  FusedView view;
  view.cameras.push_back(camera_with("back", false, {link_contact(4, 0.05F, {0, 0, 1}, {0, 0, 0.95F})}, 3000));
  EXPECT_FALSE(view::fused_closest_pair(view).valid);
}

TEST(FusedView, RowsSayEachCamerasAgeValidityAndReason) {
  const int64_t now_ns = 1'700'000'000'000'000'000;
  FusedView view;
  view.cameras.push_back(camera_with("left", true, {}, now_ns - 40'000'000));
  view.cameras.push_back(camera_with("right", false, {}, now_ns - 250'000'000));
  FusedCameraView silent;
  silent.name = "top";
  view.cameras.push_back(silent);
  const std::vector<view::FusedCameraRow> rows = view::fused_camera_rows(view, now_ns);
  ASSERT_EQ(rows.size(), 3U);
  EXPECT_EQ(rows[0].name, "left");
  ASSERT_TRUE(rows[0].age_ms.has_value());
  EXPECT_DOUBLE_EQ(*rows[0].age_ms, 40.0);
  EXPECT_TRUE(rows[0].valid);
  ASSERT_TRUE(rows[1].age_ms.has_value());
  EXPECT_DOUBLE_EQ(*rows[1].age_ms, 250.0);
  EXPECT_FALSE(rows[1].valid);
  EXPECT_EQ(rows[1].reason_code, static_cast<int>(ReasonCode::learning_background));
  EXPECT_EQ(rows[1].reason, "learning the background");
  EXPECT_FALSE(rows[2].age_ms.has_value());
  EXPECT_EQ(rows[2].reason, "no measurement yet");
  // Each camera its own colour.
  EXPECT_NE(rows[0].color, rows[1].color);
  EXPECT_NE(rows[1].color, rows[2].color);
}

TEST(FusedView, PaneDrawsEachCloudInItsColourAndThePairInTheMarkerColours) {
  FusedView view;
  FusedCameraView a;
  a.name = "a";
  a.T_base_camera.translation() = Eigen::Vector3d(3.0, 0.0, 2.0);
  FusedCameraView b = a;
  b.name = "b";
  b.T_base_camera.translation() = Eigen::Vector3d(-3.0, 0.0, 2.0);
  view.cameras = {a, b};
  view::OrbitCamera orbit;  // looks at the base origin from 5 m, 30° up, along +x
  orbit.target_base = Eigen::Vector3f(0.0F, 0.0F, 1.0F);
  // Camera a sees one point exactly at the target: the image centre, (50, 50) of 101 × 101.
  view.cameras[0].cloud_base.x = {0.0F};
  view.cameras[0].cloud_base.y = {0.0F};
  view.cameras[0].cloud_base.z = {1.0F};
  view::FusedScratch scratch;
  ColorImage out;
  view::compose_fused_3d(view, {}, view::FusedPair{}, orbit, 101, 101, scratch, out);
  ASSERT_EQ(out.width, 101);
  EXPECT_EQ(pixel_at(out, 50, 50), view::fused_camera_color(0));
  EXPECT_GT(pixels_of(out, view::fused_camera_color(1)), 0);  // b's frustum is drawn (b has no cloud)

  // The pair: the foreground point at the target, the robot's 1 m below it (straight down in the
  // image, fy · cos 30° / 5 m ≈ 15 px lower: the line shows between the 4 px discs).
  view::FusedPair pair;
  pair.valid = true;
  pair.closest_base = Eigen::Vector3f(0.0F, 0.0F, 1.0F);
  pair.closest_robot_base = Eigen::Vector3f(0.0F, 0.0F, 0.0F);
  view::compose_fused_3d(view, {}, pair, orbit, 101, 101, scratch, out);
  EXPECT_EQ(pixel_at(out, 50, 50), view::kContactMarker);
  EXPECT_GT(pixels_of(out, view::kRobotMarker), 0);
  EXPECT_GT(pixels_of(out, view::kContactLine), 0);
}

// A camera that withholds (here: learning its background) has its last cloud hidden: it no
// longer says what the camera sees. Valid again, the cloud is back.
TEST(FusedView, AWithholdingCamerasLastCloudIsNotDrawn) {
  FusedView view;
  view.cameras = {camera_with("a", false, {}, 1)};
  view.cameras[0].T_base_camera.translation() = Eigen::Vector3d(3.0, 0.0, 2.0);
  view.cameras[0].cloud_base.x = {0.0F};
  view.cameras[0].cloud_base.y = {0.0F};
  view.cameras[0].cloud_base.z = {1.0F};
  view::OrbitCamera orbit;
  orbit.target_base = Eigen::Vector3f(0.0F, 0.0F, 1.0F);  // the point projects to (50, 50)
  view::FusedScratch scratch;
  ColorImage out;
  view::compose_fused_3d(view, {}, view::FusedPair{}, orbit, 101, 101, scratch, out);
  EXPECT_NE(pixel_at(out, 50, 50), view::fused_camera_color(0));
  view.cameras[0].measurement->valid = true;
  view::compose_fused_3d(view, {}, view::FusedPair{}, orbit, 101, 101, scratch, out);
  EXPECT_EQ(pixel_at(out, 50, 50), view::fused_camera_color(0));
}

TEST(FusedView, PreviewsAlongTheBottomFramedInTheirCamerasColour) {
  FusedView view;
  FusedCameraView a;
  a.name = "a";
  a.preview.width = 8;
  a.preview.height = 4;
  a.preview.depth_mm.assign(32, 0);
  a.preview.depth_mm[31] = 1500;  // one valid pixel at the bottom right; the rest has no depth
  view.cameras = {a};
  view::OrbitCamera orbit;
  view::FusedScratch scratch;
  ColorImage out;
  view::compose_fused_3d(view, {}, view::FusedPair{}, orbit, 400, 300, scratch, out);
  // Scale 120 / 4 = 30: 240 × 120 at x = 8, y = 300 − 8 − 120 = 172, framed 2 px.
  EXPECT_EQ(pixel_at(out, 7, 171), view::fused_camera_color(0));
  EXPECT_EQ(pixel_at(out, 8 + 240, 172 + 120), view::fused_camera_color(0));
  EXPECT_EQ(pixel_at(out, 8, 172), (Rgb{0, 0, 0}));  // no depth: black
  EXPECT_NE(pixel_at(out, 8 + 239, 172 + 119), (Rgb{0, 0, 0}));  // the valid pixel, coloured
}

}  // namespace
}  // namespace hrcsense::fused_view_test

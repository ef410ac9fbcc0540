// SPDX-License-Identifier: Apache-2.0
// The simulated colour camera: its D435i intrinsics, the depth → colour extrinsics (a point
// lands where projecting it with them says), flat per-object colours, determinism, config.

#include "hrcsense/camera.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using Rgb = std::array<uint8_t, 3>;

SceneObject colored(Shape shape, bool is_static, std::optional<Rgb> color) {
  SceneObject o;
  o.shapes = {shape};
  o.is_static = is_static;
  o.color_rgb = color;
  return o;
}

Shape wall_at(float z_m) { return Shape::plane({0, 0, z_m}, {0, 0, -1}); }

Rgb pixel(const ColorImage& image, size_t i) { return {image.rgb[3 * i], image.rgb[3 * i + 1], image.rgb[3 * i + 2]}; }

/// Centroid (u, v) of the colour image's pixels of colour `c`, and their count.
Eigen::Vector2d centroid(const ColorImage& image, const Rgb& c, size_t& count) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  count = 0;
  for (int v = 0; v < image.height; ++v) {
    for (int u = 0; u < image.width; ++u) {
      if (pixel(image, static_cast<size_t>(v) * image.width + u) != c) continue;
      sum += Eigen::Vector2d(u, v);
      ++count;
    }
  }
  return count > 0 ? Eigen::Vector2d(sum / static_cast<double>(count)) : sum;
}

constexpr Rgb kWallColor{10, 20, 30};
constexpr Rgb kBallColor{200, 40, 40};

/// A wall at 2 m and a 2 cm ball at (0.1, −0.05, 1.0) m in the depth camera's frame.
Simulator ball_scene() {
  Simulator sim;
  sim.params.noise = false;
  sim.scene.objects = {colored(wall_at(2.0F), true, kWallColor),
                       colored(Shape::sphere({0.1F, -0.05F, 1.0F}, 0.02F), false, kBallColor)};
  return sim;
}

TEST(SimColor, IntrinsicsAreTheD435iCalibrationScaledToTheMode) {
  const std::optional<Intrinsics> hd = d435_color_intrinsics(1280, 720);
  ASSERT_TRUE(hd);
  EXPECT_FLOAT_EQ(hd->fx, 908.09F);
  EXPECT_FLOAT_EQ(hd->fy, 908.42F);
  EXPECT_FLOAT_EQ(hd->ppx, 646.97F);
  EXPECT_FLOAT_EQ(hd->ppy, 361.90F);
  EXPECT_EQ(hd->model, Distortion::inverse_brown_conrady);
  // 848x480: 2/3 of 1280x720 (853.3 px wide), 2.67 px cropped on each side.
  // ppx = (646.97 + 0.5)·2/3 − 0.5 − 2.667 = 428.480, ppy = 362.40·2/3 − 0.5 = 241.100.
  const std::optional<Intrinsics> wide = d435_color_intrinsics(848, 480);
  ASSERT_TRUE(wide);
  EXPECT_NEAR(wide->fx, 605.3933F, 1e-3F);
  EXPECT_NEAR(wide->fy, 605.6133F, 1e-3F);
  EXPECT_NEAR(wide->ppx, 428.480F, 1e-3F);
  EXPECT_NEAR(wide->ppy, 241.100F, 1e-3F);
  const std::optional<Intrinsics> vga = d435_color_intrinsics(640, 480);
  ASSERT_TRUE(vga);
  EXPECT_FLOAT_EQ(vga->fx, 605.39F);
  EXPECT_FLOAT_EQ(vga->ppx, 324.64F);
  EXPECT_FALSE(d435_color_intrinsics(800, 600));
}

TEST(SimColor, APointLandsWhereTheExtrinsicsProjectIt) {
  Simulator sim = ball_scene();
  // Larger than the D435's 15 mm, so that a wrong sign or a missing offset is many pixels off.
  sim.params.color_translation_m = {0.05F, 0.01F, 0.0F};
  Frame f;
  sim.render(0, f);
  ASSERT_TRUE(f.color);
  ASSERT_TRUE(f.depth_to_color);
  EXPECT_EQ(f.color->width, 848);
  EXPECT_EQ(f.color->height, 480);
  EXPECT_EQ(f.color_intrinsics.width, 848);
  EXPECT_NEAR(f.color_intrinsics.fx, 605.3933F, 1e-3F);
  const Extrinsics& e = *f.depth_to_color;
  EXPECT_EQ(e.rotation, (std::array<float, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(e.translation_m, (std::array<float, 3>{0.05F, 0.01F, 0.0F}));

  // By hand: in the colour frame the ball's centre is (0.15, −0.04, 1.0), so it projects to
  // u = 605.3933·0.15 + 428.48 = 519.289, v = 605.6133·(−0.04) + 241.10 = 216.875.
  size_t count = 0;
  const Eigen::Vector2d c = centroid(*f.color, kBallColor, count);
  ASSERT_GT(count, 0U);
  EXPECT_NEAR(c.x(), 519.289, 0.25);
  EXPECT_NEAR(c.y(), 216.875, 0.25);
  // The same through the library's projection with the frame's own intrinsics.
  const Eigen::Vector3f p_color(0.1F + e.translation_m[0], -0.05F + e.translation_m[1], 1.0F + e.translation_m[2]);
  const std::optional<Eigen::Vector2f> uv = project(f.color_intrinsics, p_color);
  ASSERT_TRUE(uv);
  EXPECT_NEAR(c.x(), uv->x(), 0.25);
  EXPECT_NEAR(c.y(), uv->y(), 0.25);
  // A disc of radius fx·r/z = 12.1 px: π·12.1² = 460 pixels.
  EXPECT_NEAR(static_cast<double>(count), 460.0, 25.0);

  // The depth camera sees the ball without the offset: u = 418.265·0.1 + 424.158 = 465.985,
  // v = 418.265·(−0.05) + 238.240 = 217.327.
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  size_t depth_count = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) {
      if (f.truth->labels[static_cast<size_t>(v) * f.depth.width + u] == kStaticLabel) continue;
      sum += Eigen::Vector2d(u, v);
      ++depth_count;
    }
  }
  ASSERT_GT(depth_count, 0U);
  EXPECT_NEAR(sum.x() / static_cast<double>(depth_count), 465.985, 0.25);
  EXPECT_NEAR(sum.y() / static_cast<double>(depth_count), 217.327, 0.25);
}

TEST(SimColor, DefaultExtrinsicsAreTheTestD435isAndTheIntrinsicsTheColourCameras) {
  // docs/SIMULATOR.md: rotation identity, translation (15.08, 0.0046, 0.17) mm, the test D435i's.
  const std::array<float, 3> t_m{0.01508F, 0.0000046F, 0.00017F};
  const Eigen::Vector3f defaults_m[] = {SimParams{}.color_translation_m, load_config("", {}).sim.color_translation_m};
  for (const Eigen::Vector3f& default_m : defaults_m) {
    EXPECT_FLOAT_EQ(default_m.x(), t_m[0]);
    EXPECT_FLOAT_EQ(default_m.y(), t_m[1]);
    EXPECT_FLOAT_EQ(default_m.z(), t_m[2]);
  }
  const Simulator sim = ball_scene();  // the default extrinsics
  Frame f;
  sim.render(0, f);
  ASSERT_TRUE(f.color && f.depth_to_color);
  EXPECT_EQ(f.depth_to_color->rotation, (std::array<float, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(f.depth_to_color->translation_m, t_m);
  // The colour camera has its own intrinsics, not the depth camera's (848x480 both).
  EXPECT_NEAR(f.color_intrinsics.fx, 605.393F, 1e-3F);
  EXPECT_NEAR(f.color_intrinsics.ppx, 428.480F, 1e-3F);
  EXPECT_EQ(f.color_intrinsics.model, Distortion::inverse_brown_conrady);
  EXPECT_NEAR(f.intrinsics.fx, 418.265F, 1e-3F);
  EXPECT_NEAR(f.intrinsics.ppx, 424.158F, 1e-3F);
  EXPECT_EQ(f.intrinsics.model, Distortion::brown_conrady);
  // By hand: the ball's centre is (0.11508, −0.0499954, 1.00017) in the colour frame, so at
  // u = 605.3933·0.11508/1.00017 + 428.48 = 498.137, v = 605.6133·(−0.0499954)/1.00017 + 241.10
  // = 210.827; 9.1 px right of where it would be without the 15 mm.
  size_t count = 0;
  const Eigen::Vector2d c = centroid(*f.color, kBallColor, count);
  ASSERT_GT(count, 0U);
  EXPECT_NEAR(c.x(), 498.137, 0.25);
  EXPECT_NEAR(c.y(), 210.827, 0.25);
}

TEST(SimColor, PixelsHaveTheirObjectsFlatColourAndDefaultsComeFromThePalette) {
  Simulator sim = ball_scene();
  Frame f;
  sim.render(0, f);
  ASSERT_TRUE(f.color);
  size_t wall = 0;
  size_t ball_pixels = 0;
  for (size_t i = 0; i < f.color->rgb.size() / 3; ++i) {
    const Rgb c = pixel(*f.color, i);
    wall += c == kWallColor ? 1 : 0;
    ball_pixels += c == kBallColor ? 1 : 0;
  }
  EXPECT_EQ(wall + ball_pixels, static_cast<size_t>(848 * 480)) << "flat colours only, nothing else";
  EXPECT_GT(ball_pixels, 400U);

  // Without a colour an object takes the palette's entry for its index; with nothing hit, black.
  sim.scene.objects[0].color_rgb.reset();
  sim.scene.objects[1].color_rgb.reset();
  sim.scene.objects[0].shapes = {Shape::sphere({-0.3F, 0.0F, 1.0F}, 0.05F)};
  sim.render(0, f);
  size_t first = 0;
  size_t second = 0;
  size_t black = 0;
  for (size_t i = 0; i < f.color->rgb.size() / 3; ++i) {
    const Rgb c = pixel(*f.color, i);
    first += c == kSimPalette[0] ? 1 : 0;
    second += c == kSimPalette[1] ? 1 : 0;
    black += c == Rgb{0, 0, 0} ? 1 : 0;
  }
  EXPECT_GT(first, 1000U);
  EXPECT_GT(second, 300U);
  EXPECT_EQ(first + second + black, static_cast<size_t>(848 * 480));
}

TEST(SimColor, SameFrameSameImageAndSwitchable) {
  const Simulator sim = ball_scene();
  Frame a;
  Frame b;
  sim.render(3, a);
  sim.render(3, b);
  ASSERT_TRUE(a.color && b.color);
  EXPECT_EQ(a.color->rgb, b.color->rgb);
  Simulator other = ball_scene();  // a fresh simulator: no state carried between frames
  other.render(3, b);
  EXPECT_EQ(a.color->rgb, b.color->rgb);

  Simulator off = ball_scene();
  off.params.color = false;
  off.render(3, b);
  EXPECT_FALSE(b.color);
  EXPECT_FALSE(b.depth_to_color);
  EXPECT_EQ(b.color_intrinsics.width, 0);
  EXPECT_EQ(b.depth.pixels, a.depth.pixels) << "the colour camera does not change the depth";

  Simulator hd = ball_scene();
  hd.params.color_width = 1280;
  hd.params.color_height = 720;
  hd.render(3, b);
  ASSERT_TRUE(b.color);
  EXPECT_EQ(b.color->width, 1280);
  EXPECT_EQ(b.color->rgb.size(), static_cast<size_t>(1280 * 720 * 3));
  EXPECT_EQ(b.depth.width, 848);
}

std::string error_of(const std::vector<std::string>& sets) {
  try {
    load_config("", sets);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

TEST(SimColor, ConfigKeys) {
  const Config config = load_config("", {"sim.color=false", "sim.color_width=1280", "sim.color_height=720",
                                         "sim.color_translation_m=[0.02, 0, 0.001]",
                                         "scene.objects=[{color: [1, 2, 3], shapes: [{sphere: {center: [0, 0, 1], "
                                         "radius_m: 0.1}}]}]"});
  EXPECT_FALSE(config.sim.color);
  EXPECT_EQ(config.sim.color_width, 1280);
  EXPECT_FLOAT_EQ(config.sim.color_translation_m.x(), 0.02F);
  ASSERT_EQ(config.scene.objects.size(), 1U);
  ASSERT_TRUE(config.scene.objects[0].color_rgb);
  EXPECT_EQ(*config.scene.objects[0].color_rgb, (Rgb{1, 2, 3}));
  EXPECT_NE(config.canonical_yaml.find("color: [1, 2, 3]"), std::string::npos);
  const Config defaults = load_config("", {});
  EXPECT_TRUE(defaults.sim.color);
  EXPECT_NE(error_of({"sim.color_width=1000", "sim.color_height=600"}).find("sim.color_width"), std::string::npos);
  EXPECT_NE(error_of({"scene.objects=[{color: [300, 0, 0], shapes: [{sphere: {center: [0, 0, 1], radius_m: 0.1}}]}]"})
                .find("scene.objects[0].color"),
            std::string::npos);
}

}  // namespace
}  // namespace hrcsense

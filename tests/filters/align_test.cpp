// SPDX-License-Identifier: Apache-2.0
// Depth ↔ colour alignment (specs/deprojection-and-alignment.md §6–§7): hand-computed pixel
// positions on small images whose arithmetic is exact in float32, hand-derived positions under
// a translation and a rotation, and the fast corner-table implementation against the spec's
// per-pixel definition on a realistic D435 geometry with distortion.
#include "hrcsense/align.hpp"

#include "hrcsense/camera.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

namespace hrcsense {
namespace {

// Units of 1/1024 m, focal lengths that are powers of two and principal points at half pixels
// make every step of the deprojection, transform and projection exact in float32, so the
// expected footprints below follow from the spec without rounding doubts.
constexpr float kScale = 1.0F / 1024.0F;

Intrinsics pinhole(int w, int h, float f, float ppx, float ppy) {
  Intrinsics in;
  in.width = w;
  in.height = h;
  in.fx = in.fy = f;
  in.ppx = ppx;
  in.ppy = ppy;
  in.model = Distortion::brown_conrady;  // as a D435 reports, coefficients all zero
  return in;
}

DepthImage depth_image(int w, int h, uint16_t value) {
  DepthImage d;
  d.depth_scale_m = kScale;
  d.resize(w, h);
  std::fill(d.pixels.begin(), d.pixels.end(), value);
  return d;
}

uint16_t at(const DepthImage& d, int x, int y) { return d.pixels[static_cast<size_t>(y) * d.width + x]; }

Extrinsics translation(float tx, float ty, float tz) {
  Extrinsics e;
  e.translation_m = {tx, ty, tz};
  return e;
}

TEST(Align, TransformPointUsesTheColumnMajorRotation) {
  Extrinsics e;
  // R = [[0, -1, 0], [1, 0, 0], [0, 0, 1]] (90° about z), stored column by column.
  e.rotation = {0, 1, 0, -1, 0, 0, 0, 0, 1};
  e.translation_m = {0.5F, 0.25F, 2.0F};
  const Eigen::Vector3f p = transform_point(e, {1.0F, 2.0F, 3.0F});
  EXPECT_EQ(p, Eigen::Vector3f(-2.0F + 0.5F, 1.0F + 0.25F, 3.0F + 2.0F));
}

// Corner (u − ½) lands on colour x = u − ½, so x0 = int(u) = u and x1 = int(u + 1) = u + 1: every
// depth pixel covers the 2×2 colour pixels (u..u+1, v..v+1), as in the SDK. A constant plane is
// therefore unchanged: colour pixel (x, y) is covered by depth pixels x−1..x, y−1..y, and the
// last depth row and column (x1 = W) are rejected without leaving a gap.
TEST(AlignDepthToColor, IdentityLeavesAPlaneUnchanged) {
  const Intrinsics in = pinhole(16, 12, 16.0F, 7.5F, 5.5F);
  const DepthImage depth = depth_image(16, 12, 2048);
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, in, in, Extrinsics{}, out);
  EXPECT_EQ(out.width, 16);
  EXPECT_EQ(out.height, 12);
  EXPECT_EQ(out.depth_scale_m, kScale);
  EXPECT_EQ(out.pixels, depth.pixels);
}

// With identity geometry each colour pixel is the nearest (smallest non-zero) depth of the four
// depth pixels up-left of it — the z-buffer of spec §6 over the 2×2 footprints.
TEST(AlignDepthToColor, IdentityIsTheNearestOfTheUpLeftNeighbours) {
  const Intrinsics in = pinhole(16, 12, 16.0F, 7.5F, 5.5F);
  DepthImage depth = depth_image(16, 12, 0);
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> value(1024, 4095);
  for (uint16_t& p : depth.pixels) p = rng() % 5 == 0 ? 0 : static_cast<uint16_t>(value(rng));
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, in, in, Extrinsics{}, out);
  for (int y = 0; y < 12; ++y) {
    for (int x = 0; x < 16; ++x) {
      uint16_t expected = 0;
      for (int v = std::max(0, y - 1); v <= std::min(y, 10); ++v) {     // depth row 11 is rejected
        for (int u = std::max(0, x - 1); u <= std::min(x, 14); ++u) {  // depth column 15 too
          const uint16_t raw = at(depth, u, v);
          if (raw != 0 && (expected == 0 || raw < expected)) expected = raw;
        }
      }
      EXPECT_EQ(at(out, x, y), expected) << x << "," << y;
    }
  }
}

// A pure x-translation moves a fronto-parallel plane by fx·tx/Z pixels: fx 16, tx 0.25 m,
// Z 2 m (raw 2048) give 2 pixels. Depth pixel u covers colour u+2..u+3; colour columns 0–1
// receive nothing; depth columns 14–15 fall off the right edge (x1 ≥ 16).
TEST(AlignDepthToColor, TranslationShiftsAPlaneByFxTxOverZ) {
  const Intrinsics in = pinhole(16, 12, 16.0F, 7.5F, 5.5F);
  DepthImage depth = depth_image(16, 12, 2048);
  for (int v = 0; v < 12; ++v) depth.pixels[static_cast<size_t>(v) * 16 + 5] = 1024;  // a nearer column
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, in, in, translation(0.25F, 0.0F, 0.0F), out);
  for (int y = 0; y < 12; ++y) {
    EXPECT_EQ(at(out, 0, y), 0);
    EXPECT_EQ(at(out, 1, y), 0);
    for (int x = 2; x < 16; ++x) {
      // Depth column 5 is at Z = 1 m: its shift is 4 pixels, covering colour 9..10; the z-buffer
      // keeps it over the farther plane there. (Its own column at 2 m would be 7..8.)
      const uint16_t expected = (x == 9 || x == 10) ? 1024 : 2048;
      EXPECT_EQ(at(out, x, y), expected) << x << "," << y;
    }
  }
}

// A colour camera with twice the focal length and twice the resolution: corner A of depth pixel
// u lands on 2u − ½ (x0 = 2u), corner B on 2u + 1.5 (x1 = 2u + 2), so footprints are 3×3 and
// overlap by one column and row, where the nearer depth wins.
TEST(AlignDepthToColor, HigherResolutionColourGetsOverlappingFootprints) {
  const Intrinsics depth_in = pinhole(16, 12, 16.0F, 7.5F, 5.5F);
  const Intrinsics color_in = pinhole(32, 24, 32.0F, 15.5F, 11.5F);
  DepthImage depth = depth_image(16, 12, 3072);
  for (int v = 0; v < 12; ++v)
    for (int u = 8; u < 16; ++u) depth.pixels[static_cast<size_t>(v) * 16 + u] = 2048;  // right half nearer
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, depth_in, color_in, Extrinsics{}, out);
  ASSERT_EQ(out.width, 32);
  ASSERT_EQ(out.height, 24);
  for (int y = 0; y < 24; ++y) {
    for (int x = 0; x < 32; ++x) {
      // Colour x is covered by depth u with 2u <= x <= 2u + 2 and u <= 14 (u = 15: x1 = 32);
      // likewise rows (v <= 10). Column 16 is shared by u = 7 (far) and u = 8 (near).
      const bool covered = x <= 30 && y <= 22;
      const uint16_t expected = !covered ? 0 : x >= 16 ? 2048 : 3072;
      EXPECT_EQ(at(out, x, y), expected) << x << "," << y;
    }
  }
}

// Positions derived by hand (in double) from the spec for a D435-like geometry: 848x480 depth,
// a 1280x720 colour camera rotated 2° about its optical axis and shifted 15 mm. Pixels whose
// corners land within 1e-3 px of a rounding boundary are left out (float32 could go either way).
TEST(AlignDepthToColor, RotatedColourCameraAgreesWithHandDerivedPositions) {
  const Intrinsics depth_in = *d435_depth_intrinsics(848, 480);
  Intrinsics color_in = pinhole(1280, 720, 910.0F, 641.5F, 360.25F);
  const double angle = 2.0 * std::acos(-1.0) / 180.0, c = std::cos(angle), s = std::sin(angle);
  const double R[3][3] = {{c, -s, 0}, {s, c, 0}, {0, 0, 1}};  // row-major, as written by hand
  const double t[3] = {0.015, 0.0, 0.0};
  Extrinsics e;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) e.rotation[3 * j + i] = static_cast<float>(R[i][j]);
  e.translation_m = {0.015F, 0.0F, 0.0F};

  DepthImage depth;
  depth.resize(848, 480);
  std::fill(depth.pixels.begin(), depth.pixels.end(), uint16_t{0});
  struct Probe {
    int u, v;
    uint16_t raw;
  };
  // (10, 10) lies outside the colour camera's narrower view; the others inside.
  const Probe probes[] = {{10, 10, 900}, {423, 239, 1500}, {600, 300, 2000}, {250, 180, 3000}, {500, 120, 1200}};
  for (const Probe& p : probes) depth.pixels[static_cast<size_t>(p.v) * 848 + p.u] = p.raw;
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, depth_in, color_in, e, out);

  size_t expected_pixels = 0;
  for (const Probe& p : probes) {
    const double z = p.raw * 0.001;
    double corner[2][2];
    bool near_boundary = false;
    for (int k = 0; k < 2; ++k) {
      const double du = p.u + (k == 0 ? -0.5 : 0.5), dv = p.v + (k == 0 ? -0.5 : 0.5);
      const double X = (du - depth_in.ppx) / depth_in.fx * z, Y = (dv - depth_in.ppy) / depth_in.fy * z;
      double Q[3];
      for (int i = 0; i < 3; ++i) Q[i] = R[i][0] * X + R[i][1] * Y + R[i][2] * z + t[i];
      corner[k][0] = Q[0] / Q[2] * color_in.fx + color_in.ppx + 0.5;
      corner[k][1] = Q[1] / Q[2] * color_in.fy + color_in.ppy + 0.5;
      for (const double q : corner[k]) near_boundary |= std::abs(q - std::round(q)) < 1e-3;
    }
    ASSERT_FALSE(near_boundary) << "probe " << p.u << "," << p.v << " needs another position";
    const int x0 = static_cast<int>(corner[0][0]), y0 = static_cast<int>(corner[0][1]);
    const int x1 = static_cast<int>(corner[1][0]), y1 = static_cast<int>(corner[1][1]);
    ASSERT_LE(x0, x1);
    ASSERT_LE(y0, y1);
    // Spec §6 step 4: a footprint reaching outside the colour image is skipped entirely.
    if (x0 < 0 || y0 < 0 || x1 >= color_in.width || y1 >= color_in.height) continue;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) EXPECT_EQ(at(out, x, y), p.raw) << p.u << "," << p.v << " → " << x << "," << y;
    expected_pixels += static_cast<size_t>((x1 - x0 + 1) * (y1 - y0 + 1));
  }
  // Colour pixels are 2.2 times smaller than depth pixels: each footprint is at least 3×3.
  EXPECT_GE(expected_pixels, 4U * 9U);
  // Nothing else was written.
  const size_t written = static_cast<size_t>(std::count_if(out.pixels.begin(), out.pixels.end(), [](uint16_t p) { return p != 0; }));
  EXPECT_EQ(written, expected_pixels);
}

// The spec's rule, pixel by pixel, with deproject/project at every corner (no corner table).
DepthImage reference_depth_to_color(const DepthImage& depth, const Intrinsics& depth_in, const Intrinsics& color_in,
                                    const Extrinsics& e) {
  DepthImage out;
  out.depth_scale_m = depth.depth_scale_m;
  out.resize(color_in.width, color_in.height);
  std::fill(out.pixels.begin(), out.pixels.end(), uint16_t{0});
  for (int v = 0; v < depth.height; ++v) {
    for (int u = 0; u < depth.width; ++u) {
      const uint16_t raw = at(depth, u, v);
      if (raw == 0) continue;
      const float z = depth.depth_scale_m * raw;
      const auto corner = [&](float du, float dv) {
        const Eigen::Vector3f p = *deproject(depth_in, {du, dv}, z);
        return *project(color_in, transform_point(e, p));
      };
      const Eigen::Vector2f a = corner(static_cast<float>(u) - 0.5F, static_cast<float>(v) - 0.5F);
      const Eigen::Vector2f b = corner(static_cast<float>(u) + 0.5F, static_cast<float>(v) + 0.5F);
      const int x0 = static_cast<int>(a.x() + 0.5F), y0 = static_cast<int>(a.y() + 0.5F);
      const int x1 = static_cast<int>(b.x() + 0.5F), y1 = static_cast<int>(b.y() + 0.5F);
      if (x0 < 0 || y0 < 0 || x1 >= color_in.width || y1 >= color_in.height) continue;
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          uint16_t& dst = out.pixels[static_cast<size_t>(y) * out.width + x];
          dst = dst == 0 ? raw : std::min(dst, raw);
        }
      }
    }
  }
  return out;
}

// The corner table and the inline pinhole projection must not change a single footprint,
// whatever the distortion models: distorted colour, zero coefficients (the inline path), and
// coefficients too small to matter to is_pinhole() but not zero (the general path).
class AlignDefinition : public ::testing::TestWithParam<std::array<float, 5>> {};

INSTANTIATE_TEST_SUITE_P(ColourCoefficients, AlignDefinition,
                         ::testing::Values(std::array<float, 5>{0.12F, -0.25F, 0.0007F, -0.0003F, 0.1F},
                                           std::array<float, 5>{0.0F, 0.0F, 0.0F, 0.0F, 0.0F},
                                           std::array<float, 5>{1e-9F, 0.0F, 0.0F, 0.0F, 0.0F}));

TEST_P(AlignDefinition, EqualsThePerPixelDefinition) {
  Intrinsics depth_in = *d435_depth_intrinsics(424, 240);
  depth_in.coeffs = {0.02F, -0.01F, 0.001F, -0.0005F, 0.003F};  // a non-rectified depth, for the table
  Intrinsics color_in = pinhole(640, 480, 605.5F, 318.2F, 243.9F);
  color_in.model = Distortion::inverse_brown_conrady;
  color_in.coeffs = GetParam();
  Extrinsics e;
  e.rotation = {0.99998F, 0.0052F, -0.0031F, -0.0052F, 0.99998F, 0.0017F, 0.0031F, -0.0017F, 0.99999F};
  e.translation_m = {0.01508F, 0.0000046F, 0.00017F};
  DepthImage depth;
  depth.resize(424, 240);
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> value(280, 5000);
  for (uint16_t& p : depth.pixels) p = rng() % 7 == 0 ? 0 : static_cast<uint16_t>(value(rng));
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, depth_in, color_in, e, out);
  const DepthImage expected = reference_depth_to_color(depth, depth_in, color_in, e);
  EXPECT_EQ(out.pixels, expected.pixels);
  // The output is mostly written (the colour camera's view covers most of the depth's).
  EXPECT_GT(std::count(out.pixels.begin(), out.pixels.end(), uint16_t{0}), 0);
  EXPECT_LT(std::count(out.pixels.begin(), out.pixels.end(), uint16_t{0}), static_cast<long>(out.pixels.size() / 2));
}

TEST(AlignDepthToColor, ReusesItsBuffersAndFailsSafeOnMismatchedSizes) {
  const Intrinsics in = pinhole(16, 12, 16.0F, 7.5F, 5.5F);
  const DepthImage depth = depth_image(16, 12, 2048);
  AlignDepthToColor align;
  DepthImage out;
  align.apply(depth, in, in, Extrinsics{}, out);
  const uint16_t* buffer = out.pixels.data();
  align.apply(depth, in, in, translation(0.25F, 0, 0), out);
  EXPECT_EQ(out.pixels.data(), buffer);
  const Intrinsics wrong = pinhole(15, 12, 16.0F, 7.5F, 5.5F);
  align.apply(depth, wrong, in, Extrinsics{}, out);
  EXPECT_EQ(std::count(out.pixels.begin(), out.pixels.end(), uint16_t{0}), 16 * 12);
  // A colour camera behind the depth camera's points sees nothing (projection rejects z <= 0).
  align.apply(depth, in, in, translation(0, 0, -3.0F), out);
  EXPECT_EQ(std::count(out.pixels.begin(), out.pixels.end(), uint16_t{0}), 16 * 12);
}

ColorImage gradient_color(int w, int h) {
  ColorImage c;
  c.width = w;
  c.height = h;
  c.rgb.resize(static_cast<size_t>(w) * h * 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      uint8_t* p = &c.rgb[(static_cast<size_t>(y) * w + x) * 3];
      p[0] = static_cast<uint8_t>(x);
      p[1] = static_cast<uint8_t>(y);
      p[2] = static_cast<uint8_t>(x + y * w);
    }
  }
  return c;
}

// Colour → depth: depth pixel (u, v) takes the last colour pixel of its footprint (u+1+s, v+1)
// for a shift s of 0 or 2 pixels (spec §7); empty depth and rejected pixels stay black.
TEST(AlignColorToDepth, TakesTheBottomRightPixelOfTheFootprint) {
  const Intrinsics in = pinhole(16, 12, 16.0F, 7.5F, 5.5F);
  DepthImage depth = depth_image(16, 12, 2048);
  depth.pixels[3 * 16 + 4] = 0;
  const ColorImage color = gradient_color(16, 12);
  AlignColorToDepth align;
  ColorImage out;
  for (const int shift : {0, 2}) {
    align.apply(depth, in, color, in, translation(0.125F * static_cast<float>(shift), 0, 0), out);
    ASSERT_EQ(out.width, 16);
    ASSERT_EQ(out.height, 12);
    for (int v = 0; v < 12; ++v) {
      for (int u = 0; u < 16; ++u) {
        const uint8_t* p = &out.rgb[(static_cast<size_t>(v) * 16 + u) * 3];
        const int x = u + 1 + shift, y = v + 1;
        const bool black = (u == 4 && v == 3) || x >= 16 || y >= 12;
        if (black) {
          EXPECT_EQ(p[0] + p[1] + p[2], 0) << u << "," << v << " shift " << shift;
        } else {
          EXPECT_EQ(p[0], x) << u << "," << v << " shift " << shift;
          EXPECT_EQ(p[1], y) << u << "," << v << " shift " << shift;
        }
      }
    }
  }
  const uint8_t* buffer = out.rgb.data();
  align.apply(depth, in, color, in, Extrinsics{}, out);
  EXPECT_EQ(out.rgb.data(), buffer);
}

}  // namespace
}  // namespace hrcsense

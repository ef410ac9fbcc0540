// SPDX-License-Identifier: Apache-2.0
// Tests of projection/deprojection, D435 intrinsics and the stereo noise model against the spec.

#include "hrcsense/camera.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

namespace hrcsense {
namespace {

constexpr double kPi = 3.14159265358979323846;

Intrinsics simple_intrinsics(Distortion model, std::array<float, 5> coeffs) {
  Intrinsics in;
  in.width = 200;
  in.height = 200;
  in.fx = 100.0F;
  in.fy = 100.0F;
  in.ppx = 0.0F;
  in.ppy = 0.0F;
  in.model = model;
  in.coeffs = coeffs;
  return in;
}

/// A D435i 848x480 depth stream with lens distortion added, to exercise the iterative models
/// over a realistic field of view (±45° horizontally).
Intrinsics distorted_848x480(Distortion model, std::array<float, 5> coeffs) {
  Intrinsics in = *d435_depth_intrinsics(848, 480);
  in.model = model;
  in.coeffs = coeffs;
  return in;
}

TEST(Project, PinholeByHand) {
  // D435i 848x480: fx = fy = 418.265, pp = (424.158, 238.240).
  // (0.1, -0.05, 1) → u = 0.1·418.265 + 424.158 = 465.9845, v = −0.05·418.265 + 238.240 = 217.32675.
  const Intrinsics in = *d435_depth_intrinsics(848, 480);
  const auto px = project(in, {0.1F, -0.05F, 1.0F});
  ASSERT_TRUE(px.has_value());
  EXPECT_NEAR(px->x(), 465.9845, 1e-3);
  EXPECT_NEAR(px->y(), 217.32675, 1e-3);
  // Scaling the point along its ray does not move the pixel.
  const auto far = project(in, {0.3F, -0.15F, 3.0F});
  ASSERT_TRUE(far.has_value());
  EXPECT_NEAR(far->x(), 465.9845, 1e-3);
  EXPECT_NEAR(far->y(), 217.32675, 1e-3);
}

TEST(Project, BrownConradyByHand) {
  // k1 = 0.1, p1 = 0.01, p2 = 0.02; point (0.5, 0.5, 1): x = y = 0.5, r² = 0.5, f = 1.05.
  // xd = 0.5·1.05 + 2·0.01·0.25 + 0.02·(0.5 + 0.5) = 0.525 + 0.005 + 0.02  = 0.55
  // yd = 0.5·1.05 + 2·0.02·0.25 + 0.01·(0.5 + 0.5) = 0.525 + 0.01  + 0.01  = 0.545
  const Intrinsics in = simple_intrinsics(Distortion::brown_conrady, {0.1F, 0.0F, 0.01F, 0.02F, 0.0F});
  const auto px = project(in, {0.5F, 0.5F, 1.0F});
  ASSERT_TRUE(px.has_value());
  EXPECT_NEAR(px->x(), 55.0, 1e-4);
  EXPECT_NEAR(px->y(), 54.5, 1e-4);
}

TEST(Project, InverseAndModifiedBrownConradyByHand) {
  // Same coefficients; tangential terms use the radially distorted x' = y' = 0.525 with r² = 0.5:
  // xd = 0.525 + 2·0.01·0.275625 + 0.02·(0.5 + 2·0.275625) = 0.525 + 0.0055125 + 0.021025  = 0.5515375
  // yd = 0.525 + 2·0.02·0.275625 + 0.01·(0.5 + 2·0.275625) = 0.525 + 0.011025  + 0.0105125 = 0.5465375
  for (const Distortion model : {Distortion::inverse_brown_conrady, Distortion::modified_brown_conrady}) {
    const Intrinsics in = simple_intrinsics(model, {0.1F, 0.0F, 0.01F, 0.02F, 0.0F});
    const auto px = project(in, {0.5F, 0.5F, 1.0F});
    ASSERT_TRUE(px.has_value());
    EXPECT_NEAR(px->x(), 55.15375, 1e-4) << distortion_name(model);
    EXPECT_NEAR(px->y(), 54.65375, 1e-4) << distortion_name(model);
  }
}

TEST(Project, RadialTermsK2K3ByHand) {
  // k2 = 0.2, k3 = 0.4 (coeffs[1], coeffs[4]); point (1, 0, 1): r² = 1, f = 1 + 0.2 + 0.4 = 1.6.
  const Intrinsics in = simple_intrinsics(Distortion::brown_conrady, {0.0F, 0.2F, 0.0F, 0.0F, 0.4F});
  const auto px = project(in, {1.0F, 0.0F, 1.0F});
  ASSERT_TRUE(px.has_value());
  EXPECT_NEAR(px->x(), 160.0, 1e-4);
  EXPECT_NEAR(px->y(), 0.0, 1e-6);
}

TEST(Project, KannalaBrandt4ByHand) {
  // k1 = 0.1; point (1, 0, 1): r = 1, θ = π/4, rd = θ(1 + 0.1θ²) = 0.8338454707.
  const Intrinsics in = simple_intrinsics(Distortion::kannala_brandt4, {0.1F, 0.0F, 0.0F, 0.0F, 0.0F});
  const auto px = project(in, {1.0F, 0.0F, 1.0F});
  ASSERT_TRUE(px.has_value());
  const double theta = kPi / 4.0;
  EXPECT_NEAR(px->x(), 100.0 * theta * (1.0 + 0.1 * theta * theta), 1e-3);
  EXPECT_NEAR(px->x(), 83.38454707, 1e-3);
  EXPECT_NEAR(px->y(), 0.0, 1e-6);
}

TEST(Project, FthetaByHand) {
  // w = 1; point (0.5, 0, 1): r = 0.5, rd = atan(2·0.5·tan(0.5)) / 1 = 0.5 exactly.
  const Intrinsics in = simple_intrinsics(Distortion::ftheta, {1.0F, 0.0F, 0.0F, 0.0F, 0.0F});
  const auto px = project(in, {0.5F, 0.0F, 1.0F});
  ASSERT_TRUE(px.has_value());
  EXPECT_NEAR(px->x(), 50.0, 1e-4);
}

TEST(Project, RefusesPointsNotInFront) {
  const Intrinsics in = *d435_depth_intrinsics(848, 480);
  EXPECT_FALSE(project(in, {0.1F, 0.1F, 0.0F}).has_value());
  EXPECT_FALSE(project(in, {0.1F, 0.1F, -1.0F}).has_value());
  EXPECT_FALSE(project(in, {0.1F, 0.1F, std::numeric_limits<float>::quiet_NaN()}).has_value());
  EXPECT_TRUE(project(in, {0.1F, 0.1F, 1e-3F}).has_value());
}

TEST(Deproject, PinholeByHand) {
  // Inverse of Project.PinholeByHand at 2 m: (465.9845, 217.32675) → (0.2, −0.1, 2).
  const Intrinsics in = *d435_depth_intrinsics(848, 480);
  const auto p = deproject(in, {465.9845F, 217.32675F}, 2.0F);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), 0.2, 1e-5);
  EXPECT_NEAR(p->y(), -0.1, 1e-5);
  EXPECT_FLOAT_EQ(p->z(), 2.0F);
  // The principal point lies on the optical axis.
  const auto axis = deproject(in, {in.ppx, in.ppy}, 1.5F);
  ASSERT_TRUE(axis.has_value());
  EXPECT_FLOAT_EQ(axis->x(), 0.0F);
  EXPECT_FLOAT_EQ(axis->y(), 0.0F);
}

TEST(Deproject, InvertsHandComputedDistortion) {
  // The pixels of the hand-computed projections above lead back to (0.5, 0.5, 1).
  const std::array<float, 5> coeffs{0.1F, 0.0F, 0.01F, 0.02F, 0.0F};
  const auto bc = deproject(simple_intrinsics(Distortion::brown_conrady, coeffs), {55.0F, 54.5F}, 1.0F);
  ASSERT_TRUE(bc.has_value());
  EXPECT_NEAR(bc->x(), 0.5, 1e-4);
  EXPECT_NEAR(bc->y(), 0.5, 1e-4);
  const auto ibc =
      deproject(simple_intrinsics(Distortion::inverse_brown_conrady, coeffs), {55.15375F, 54.65375F}, 1.0F);
  ASSERT_TRUE(ibc.has_value());
  EXPECT_NEAR(ibc->x(), 0.5, 1e-4);
  EXPECT_NEAR(ibc->y(), 0.5, 1e-4);
  const auto kb4 = deproject(simple_intrinsics(Distortion::kannala_brandt4, {0.1F, 0.0F, 0.0F, 0.0F, 0.0F}),
                             {83.38454707F, 0.0F}, 2.0F);
  ASSERT_TRUE(kb4.has_value());
  EXPECT_NEAR(kb4->x(), 2.0, 1e-4);
  EXPECT_NEAR(kb4->y(), 0.0, 1e-6);
}

TEST(Deproject, FthetaKeepsTheSdkDiscrepancy) {
  // The SDK scales by tan(w·rd) / atan(2·tan(w/2)), not by the exact inverse of its projection:
  // pixel 50 (rd = 0.5, w = 1) gives x = tan(0.5) / atan(2·tan(0.5)) = 0.65849..., not 0.5.
  const Intrinsics in = simple_intrinsics(Distortion::ftheta, {1.0F, 0.0F, 0.0F, 0.0F, 0.0F});
  const auto p = deproject(in, {50.0F, 0.0F}, 1.0F);
  ASSERT_TRUE(p.has_value());
  EXPECT_NEAR(p->x(), std::tan(0.5) / std::atan(2.0 * std::tan(0.5)), 1e-5);
  EXPECT_NEAR(p->x(), 0.6584950654, 1e-5);
  // w ≈ 0: the SDK's scale is 0, every ray collapses onto the axis.
  const Intrinsics degenerate = simple_intrinsics(Distortion::ftheta, {0.0F, 0.0F, 0.0F, 0.0F, 0.0F});
  const auto q = deproject(degenerate, {50.0F, 20.0F}, 1.0F);
  ASSERT_TRUE(q.has_value());
  EXPECT_EQ(q->x(), 0.0F);
  EXPECT_EQ(q->y(), 0.0F);
}

TEST(Deproject, RefusesModifiedBrownConrady) {
  EXPECT_FALSE(
      deproject(distorted_848x480(Distortion::modified_brown_conrady, {0.1F, 0.0F, 0.0F, 0.0F, 0.0F}),
                {100.0F, 100.0F}, 1.0F)
          .has_value());
  // Even with zero coefficients: the SDK has no inverse for the model at all.
  EXPECT_FALSE(deproject(distorted_848x480(Distortion::modified_brown_conrady, {}), {100.0F, 100.0F}, 1.0F)
                   .has_value());
}

TEST(Deproject, NegligibleCoefficientsTakeThePinholeShortcut) {
  // All |coeff| < FLT_EPSILON: undistortion is skipped, the result equals the pinhole one exactly.
  const float tiny = FLT_EPSILON / 2.0F;
  const Intrinsics pinhole = distorted_848x480(Distortion::none, {});
  for (const Distortion model : {Distortion::brown_conrady, Distortion::inverse_brown_conrady}) {
    const Intrinsics in = distorted_848x480(model, {tiny, -tiny, tiny, tiny, -tiny});
    EXPECT_TRUE(is_pinhole(in)) << distortion_name(model);
    const Eigen::Vector2f pixel(3.0F, 470.0F);
    EXPECT_EQ(*deproject(in, pixel, 1.7F), *deproject(pinhole, pixel, 1.7F)) << distortion_name(model);
  }
  EXPECT_TRUE(is_pinhole(*d435_depth_intrinsics(848, 480)));
  EXPECT_TRUE(is_pinhole(pinhole));
  EXPECT_FALSE(is_pinhole(distorted_848x480(Distortion::brown_conrady, {0.0F, 0.0F, 0.0F, 0.0F, 1e-4F})));
  EXPECT_FALSE(is_pinhole(distorted_848x480(Distortion::inverse_brown_conrady, {1e-3F, 0, 0, 0, 0})));
  // Not pinhole models even with zero coefficients (KB4 is then an equidistant fisheye).
  EXPECT_FALSE(is_pinhole(distorted_848x480(Distortion::kannala_brandt4, {})));
  EXPECT_FALSE(is_pinhole(distorted_848x480(Distortion::modified_brown_conrady, {})));
}

/// Projecting the deprojection of every pixel of a grid over the image returns that pixel.
void expect_round_trip(const Intrinsics& in, double tolerance_px) {
  double worst_px = 0.0;
  for (int v = 0; v < in.height; v += 16) {
    for (int u = 0; u < in.width; u += 16) {
      const Eigen::Vector2f pixel(static_cast<float>(u), static_cast<float>(v));
      const auto point = deproject(in, pixel, 1.25F);
      ASSERT_TRUE(point.has_value());
      EXPECT_FLOAT_EQ(point->z(), 1.25F);
      const auto back = project(in, *point);
      ASSERT_TRUE(back.has_value());
      worst_px = std::max(worst_px, static_cast<double>((*back - pixel).norm()));
    }
  }
  EXPECT_LT(worst_px, tolerance_px) << distortion_name(in.model);
}

TEST(RoundTrip, EveryInvertibleModelAcross848x480) {
  // Coefficients of the size real colour and fisheye calibrations report.
  expect_round_trip(distorted_848x480(Distortion::none, {}), 1e-3);
  expect_round_trip(distorted_848x480(Distortion::brown_conrady, {0.0F, 0.0F, 0.0F, 0.0F, 0.0F}), 1e-3);
  expect_round_trip(
      distorted_848x480(Distortion::brown_conrady, {-0.055F, 0.062F, 0.0008F, -0.0005F, -0.019F}), 1e-3);
  expect_round_trip(
      distorted_848x480(Distortion::inverse_brown_conrady, {-0.055F, 0.062F, 0.0008F, -0.0005F, -0.019F}),
      1e-3);
  expect_round_trip(
      distorted_848x480(Distortion::kannala_brandt4, {-0.0046F, 0.0395F, -0.0372F, 0.0064F, 0.0F}), 1e-3);
}

TEST(RoundTrip, DeprojectedPointLiesOnTheRay) {
  // Depth is Z along the axis, not the ray length: doubling z doubles x and y.
  const Intrinsics in =
      distorted_848x480(Distortion::inverse_brown_conrady, {-0.055F, 0.062F, 0.0008F, -0.0005F, -0.019F});
  const auto near = deproject(in, {700.0F, 50.0F}, 1.0F);
  const auto far = deproject(in, {700.0F, 50.0F}, 2.0F);
  ASSERT_TRUE(near && far);
  EXPECT_NEAR(far->x(), 2.0F * near->x(), 1e-6);
  EXPECT_NEAR(far->y(), 2.0F * near->y(), 1e-6);
}

TEST(D435, IntrinsicsFromTheSpecTable) {
  const auto in = d435_depth_intrinsics(848, 480);
  ASSERT_TRUE(in.has_value());
  EXPECT_EQ(in->width, 848);
  EXPECT_EQ(in->height, 480);
  EXPECT_FLOAT_EQ(in->fx, 418.265F);
  EXPECT_FLOAT_EQ(in->fy, 418.265F);
  EXPECT_FLOAT_EQ(in->ppx, 424.158F);
  EXPECT_FLOAT_EQ(in->ppy, 238.240F);
  EXPECT_EQ(in->model, Distortion::brown_conrady);
  for (const float c : in->coeffs) {
    EXPECT_EQ(c, 0.0F);
  }
  EXPECT_FLOAT_EQ(d435_depth_intrinsics(1280, 720)->fx, 631.343F);
  EXPECT_FLOAT_EQ(d435_depth_intrinsics(424, 240)->ppy, 119.080F);
}

/// The SDK's field-of-view formula (spec §4), degrees.
double fov_deg(float pp, float f, int size) {
  const double edge = static_cast<double>(pp) + 0.5;
  return (std::atan2(edge, f) + std::atan2(size - edge, f)) * 180.0 / kPi;
}

TEST(D435, EveryOfferedResolutionIsAConsistentPinhole) {
  const int sizes[][2] = {{1280, 720}, {848, 480}, {640, 480}, {640, 360}, {480, 270}, {424, 240}};
  for (const auto& size : sizes) {
    const auto in = d435_depth_intrinsics(size[0], size[1]);
    ASSERT_TRUE(in.has_value()) << size[0] << "x" << size[1];
    EXPECT_EQ(in->width, size[0]);
    EXPECT_EQ(in->height, size[1]);
    EXPECT_EQ(in->fx, in->fy);
    EXPECT_TRUE(is_pinhole(*in));
    // Principal point near the centre (rectified image).
    EXPECT_NEAR(in->ppx, size[0] / 2.0, 0.01 * size[0]);
    EXPECT_NEAR(in->ppy, size[1] / 2.0, 0.01 * size[1]);
    // Spec §2: the 16:9 modes see about 90.8° x 59.5°, 640x480 about 80° x 65°.
    const bool wide = size[0] * 3 != size[1] * 4;  // all but 640x480 are (nearly) 16:9
    EXPECT_NEAR(fov_deg(in->ppx, in->fx, in->width), wide ? 90.8 : 80.0, 0.5);
    EXPECT_NEAR(fov_deg(in->ppy, in->fy, in->height), wide ? 59.5 : 65.0, 0.5);
  }
}

TEST(D435, UnknownResolutionHasNoIntrinsics) {
  EXPECT_FALSE(d435_depth_intrinsics(800, 600).has_value());
  EXPECT_FALSE(d435_depth_intrinsics(480, 848).has_value());   // transposed
  EXPECT_FALSE(d435_depth_intrinsics(1280, 800).has_value());  // infrared only
  EXPECT_FALSE(d435_depth_intrinsics(0, 0).has_value());
}

TEST(NoiseModel, MatchesTheSpecTable) {
  // specs/d435-sensor-model.md §3: 848x480 (fx 418.3, B 49.86 mm, s 0.08).
  const double fx = d435_depth_intrinsics(848, 480)->fx;
  const auto sigma_mm = [&](double z_m, double f) {
    return 1e3 * stereo_depth_sigma_m(z_m, f, kD435BaselineMm, kD435SubpixelRmsPx);
  };
  EXPECT_NEAR(sigma_mm(0.5, fx), 0.96, 0.01);
  EXPECT_NEAR(sigma_mm(1.0, fx), 3.8, 0.05);
  EXPECT_NEAR(sigma_mm(2.0, fx), 15.3, 0.05);
  EXPECT_NEAR(sigma_mm(3.0, fx), 34.5, 0.05);
  const double fx_720p = d435_depth_intrinsics(1280, 720)->fx;
  EXPECT_NEAR(sigma_mm(1.0, fx_720p), 2.5, 0.05);
  EXPECT_NEAR(sigma_mm(2.0, fx_720p), 10.2, 0.05);
  // Quadratic in z, linear in s, inverse in B.
  EXPECT_NEAR(stereo_depth_sigma_m(2.0, fx, 50.0, 0.1), 4.0 * stereo_depth_sigma_m(1.0, fx, 50.0, 0.1),
              1e-12);
  EXPECT_NEAR(stereo_depth_sigma_m(1.0, fx, 25.0, 0.2), 4.0 * stereo_depth_sigma_m(1.0, fx, 50.0, 0.1),
              1e-12);
}

TEST(DistortionNames, RoundTripWithTheSdkStrings) {
  const std::pair<Distortion, const char*> expected[] = {
      {Distortion::none, "None"},
      {Distortion::modified_brown_conrady, "Modified Brown Conrady"},
      {Distortion::inverse_brown_conrady, "Inverse Brown Conrady"},
      {Distortion::ftheta, "Ftheta"},
      {Distortion::brown_conrady, "Brown Conrady"},
      {Distortion::kannala_brandt4, "Kannala Brandt4"},
  };
  int value = 0;
  for (const auto& [model, name] : expected) {
    EXPECT_EQ(static_cast<int>(model), value++);  // the SDK's rs2_distortion numbering
    EXPECT_EQ(distortion_name(model), name);
    const auto back = distortion_from_name(name);
    ASSERT_TRUE(back.has_value()) << name;
    EXPECT_EQ(*back, model);
  }
  EXPECT_FALSE(distortion_from_name("").has_value());
  EXPECT_FALSE(distortion_from_name("Pinhole").has_value());
  EXPECT_FALSE(distortion_from_name("brown conrady").has_value());
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// hrcsense — projection/deprojection as the RealSense SDK defines them, D435 intrinsics, noise.

#include "hrcsense/camera.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

namespace hrcsense {
namespace {

// Every formula below is evaluated in float32 and in the SDK's operation order
// (specs/deprojection-and-alignment.md §3–§4) so that results match the SDK to the bit
// in a build without FMA contraction.

bool coefficients_negligible(const Intrinsics& in) {
  for (const float c : in.coeffs) {
    if (std::fabs(c) >= FLT_EPSILON) {
      return false;
    }
  }
  return true;
}

/// Radial factor 1 + k1·r² + k2·r⁴ + k3·r⁶ of the Brown-Conrady family.
float radial_factor(const Intrinsics& in, float r2) {
  const float k1 = in.coeffs[0];
  const float k2 = in.coeffs[1];
  const float k3 = in.coeffs[4];
  return 1.0F + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
}

/// Inverse radial factor in Horner form, as both iterative undistortions use it.
float inverse_radial_factor(const Intrinsics& in, float r2) {
  const float k1 = in.coeffs[0];
  const float k2 = in.coeffs[1];
  const float k3 = in.coeffs[4];
  return 1.0F / (1.0F + ((k3 * r2 + k2) * r2 + k1) * r2);
}

/// Normalised (x, y) on the image plane → distorted normalised coordinates.
void distort(const Intrinsics& in, float& x, float& y) {
  const float p1 = in.coeffs[2];
  const float p2 = in.coeffs[3];
  switch (in.model) {
    case Distortion::modified_brown_conrady:
    case Distortion::inverse_brown_conrady: {
      // Tangential terms use the radially distorted x', y' but the undistorted r².
      const float r2 = x * x + y * y;
      const float f = radial_factor(in, r2);
      const float xr = x * f;
      const float yr = y * f;
      x = xr + 2.0F * p1 * xr * yr + p2 * (r2 + 2.0F * xr * xr);
      y = yr + 2.0F * p2 * xr * yr + p1 * (r2 + 2.0F * yr * yr);
      break;
    }
    case Distortion::brown_conrady: {
      const float r2 = x * x + y * y;
      const float f = radial_factor(in, r2);
      const float xd = x * f + 2.0F * p1 * x * y + p2 * (r2 + 2.0F * x * x);
      const float yd = y * f + 2.0F * p2 * x * y + p1 * (r2 + 2.0F * y * y);
      x = xd;
      y = yd;
      break;
    }
    case Distortion::ftheta: {
      const float w = in.coeffs[0];
      const float r = std::max(std::sqrt(x * x + y * y), FLT_EPSILON);
      const float rd = std::atan(2.0F * r * std::tan(w / 2.0F)) / w;
      x *= rd / r;
      y *= rd / r;
      break;
    }
    case Distortion::kannala_brandt4: {
      const float r = std::max(std::sqrt(x * x + y * y), FLT_EPSILON);
      const float theta = std::atan(r);
      const float t2 = theta * theta;
      const float series =
          1.0F + t2 * (in.coeffs[0] + t2 * (in.coeffs[1] + t2 * (in.coeffs[2] + t2 * in.coeffs[3])));
      const float rd = theta * series;
      x *= rd / r;
      y *= rd / r;
      break;
    }
    case Distortion::none:
      break;
  }
}

/// Fixed 10 iterations (the SDK's count, chosen empirically there); no convergence test so
/// the result is bit-identical to the SDK's.
constexpr int kBrownConradyIterations = 10;

void undistort_inverse_brown_conrady(const Intrinsics& in, float& x, float& y) {
  const float p1 = in.coeffs[2];
  const float p2 = in.coeffs[3];
  const float x0 = x;
  const float y0 = y;
  for (int i = 0; i < kBrownConradyIterations; ++i) {
    const float r2 = x * x + y * y;
    const float icd = inverse_radial_factor(in, r2);
    const float xq = x / icd;
    const float yq = y / icd;
    const float dx = 2.0F * p1 * xq * yq + p2 * (r2 + 2.0F * xq * xq);
    const float dy = 2.0F * p2 * xq * yq + p1 * (r2 + 2.0F * yq * yq);
    x = (x0 - dx) * icd;
    y = (y0 - dy) * icd;
  }
}

void undistort_brown_conrady(const Intrinsics& in, float& x, float& y) {
  const float p1 = in.coeffs[2];
  const float p2 = in.coeffs[3];
  const float x0 = x;
  const float y0 = y;
  for (int i = 0; i < kBrownConradyIterations; ++i) {
    const float r2 = x * x + y * y;
    const float icd = inverse_radial_factor(in, r2);
    const float dx = 2.0F * p1 * x * y + p2 * (r2 + 2.0F * x * x);
    const float dy = 2.0F * p2 * x * y + p1 * (r2 + 2.0F * y * y);
    x = (x0 - dx) * icd;
    y = (y0 - dy) * icd;
  }
}

/// Newton's method on θ·(1 + k1θ² + k2θ⁴ + k3θ⁶ + k4θ⁸) = rd, at most 4 steps as the SDK.
/// Outside the model's monotonic range this need not converge; the SDK accepts that too.
void undistort_kannala_brandt4(const Intrinsics& in, float& x, float& y) {
  const float k1 = in.coeffs[0];
  const float k2 = in.coeffs[1];
  const float k3 = in.coeffs[2];
  const float k4 = in.coeffs[3];
  const float rd = std::max(std::sqrt(x * x + y * y), FLT_EPSILON);
  float theta = rd;
  float t2 = rd * rd;
  for (int i = 0; i < 4; ++i) {
    const float residual = theta * (1.0F + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4)))) - rd;
    if (std::fabs(residual) < FLT_EPSILON) {
      break;
    }
    const float slope = 1.0F + t2 * (3.0F * k1 + t2 * (5.0F * k2 + t2 * (7.0F * k3 + 9.0F * t2 * k4)));
    theta -= residual / slope;
    t2 = theta * theta;
  }
  const float r = std::tan(theta);
  x *= r / rd;
  y *= r / rd;
}

/// The SDK divides by atan(2·tan(w/2)) where the exact inverse of its projection would divide
/// by 2·tan(w/2); we keep the SDK's form so that points agree with recordings (fisheye only).
void undistort_ftheta(const Intrinsics& in, float& x, float& y) {
  const float w = in.coeffs[0];
  const float rd = std::max(std::sqrt(x * x + y * y), FLT_EPSILON);
  float r = 0.0F;
  if (std::fabs(w) >= FLT_EPSILON) {
    r = std::tan(w * rd) / std::atan(2.0F * std::tan(w / 2.0F));
  }
  x *= r / rd;
  y *= r / rd;
}

Intrinsics d435_pinhole(int width, int height, float f_px, float ppx, float ppy) {
  Intrinsics in;
  in.width = width;
  in.height = height;
  in.fx = f_px;
  in.fy = f_px;
  in.ppx = ppx;
  in.ppy = ppy;
  in.model = Distortion::brown_conrady;  // what the camera reports; coefficients all zero
  return in;
}

}  // namespace

std::optional<Eigen::Vector2f> project(const Intrinsics& intrinsics, const Eigen::Vector3f& point_camera) {
  // `!(z > 0)` also refuses NaN.
  if (!(point_camera.z() > 0.0F)) {
    return std::nullopt;
  }
  float x = point_camera.x() / point_camera.z();
  float y = point_camera.y() / point_camera.z();
  distort(intrinsics, x, y);
  return Eigen::Vector2f(x * intrinsics.fx + intrinsics.ppx, y * intrinsics.fy + intrinsics.ppy);
}

std::optional<Eigen::Vector3f> deproject(const Intrinsics& intrinsics, const Eigen::Vector2f& pixel,
                                         float z_m) {
  if (intrinsics.model == Distortion::modified_brown_conrady) {
    return std::nullopt;  // the SDK asserts: no inverse is defined for this model
  }
  float x = (pixel.x() - intrinsics.ppx) / intrinsics.fx;
  float y = (pixel.y() - intrinsics.ppy) / intrinsics.fy;
  if (!is_pinhole(intrinsics)) {
    switch (intrinsics.model) {
      case Distortion::inverse_brown_conrady:
        undistort_inverse_brown_conrady(intrinsics, x, y);
        break;
      case Distortion::brown_conrady:
        undistort_brown_conrady(intrinsics, x, y);
        break;
      case Distortion::kannala_brandt4:
        undistort_kannala_brandt4(intrinsics, x, y);
        break;
      case Distortion::ftheta:
        undistort_ftheta(intrinsics, x, y);
        break;
      case Distortion::modified_brown_conrady:
      case Distortion::none:
        break;
    }
  }
  return Eigen::Vector3f(z_m * x, z_m * y, z_m);
}

bool is_pinhole(const Intrinsics& intrinsics) {
  if (intrinsics.model == Distortion::none) {
    return true;
  }
  // Modified Brown-Conrady is excluded although its projection would be pinhole: deproject()
  // refuses it, and callers use this to pick a fast path that must agree with deproject().
  return (intrinsics.model == Distortion::inverse_brown_conrady ||
          intrinsics.model == Distortion::brown_conrady) &&
         coefficients_negligible(intrinsics);
}

std::string_view distortion_name(Distortion model) {
  switch (model) {
    case Distortion::none:
      return "None";
    case Distortion::modified_brown_conrady:
      return "Modified Brown Conrady";
    case Distortion::inverse_brown_conrady:
      return "Inverse Brown Conrady";
    case Distortion::ftheta:
      return "Ftheta";
    case Distortion::brown_conrady:
      return "Brown Conrady";
    case Distortion::kannala_brandt4:
      return "Kannala Brandt4";
  }
  return "Unknown";  // an out-of-range enum value, e.g. read from a damaged file
}

std::optional<Distortion> distortion_from_name(std::string_view name) {
  for (const Distortion model :
       {Distortion::none, Distortion::modified_brown_conrady, Distortion::inverse_brown_conrady,
        Distortion::ftheta, Distortion::brown_conrady, Distortion::kannala_brandt4}) {
    if (distortion_name(model) == name) {
      return model;
    }
  }
  return std::nullopt;
}

std::optional<Intrinsics> d435_depth_intrinsics(int width, int height) {
  // D435i rows of specs/d435-sensor-model.md §2 (librealsense unit-tests/dds/d435i.py).
  struct Row {
    int width, height;
    float f_px, ppx, ppy;
  };
  static constexpr Row kRows[] = {
      {1280, 720, 631.343F, 640.238F, 357.343F}, {848, 480, 418.265F, 424.158F, 238.240F},
      {640, 480, 378.806F, 320.143F, 238.406F},  {640, 360, 315.671F, 320.119F, 178.672F},
      {480, 270, 236.754F, 240.089F, 134.004F},  {424, 240, 209.132F, 212.079F, 119.080F},
  };
  for (const Row& row : kRows) {
    if (row.width == width && row.height == height) {
      return d435_pinhole(row.width, row.height, row.f_px, row.ppx, row.ppy);
    }
  }
  return std::nullopt;
}

double stereo_depth_sigma_m(double z_m, double fx_px, double baseline_mm, double subpixel_rms_px) {
  const double baseline_m = baseline_mm * 1e-3;
  return z_m * z_m * subpixel_rms_px / (fx_px * baseline_m);
}

}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// hrcsense — camera geometry: projection and deprojection as the RealSense SDK defines them
// (specs/deprojection-and-alignment.md), the D435's intrinsics and its depth noise model.
#pragma once

#include "hrcsense/types.hpp"

#include <optional>
#include <string_view>

namespace hrcsense {

/// Projects a camera-frame point (metres) to a continuous pixel position.
/// Returns nullopt when z <= 0 (the SDK does not check; we must).
std::optional<Eigen::Vector2f> project(const Intrinsics& intrinsics, const Eigen::Vector3f& point_camera);

/// Deprojects pixel (u, v) with depth z_m (Z along the optical axis) to a camera-frame point.
/// Returns nullopt for MODIFIED_BROWN_CONRADY, which the SDK cannot invert.
std::optional<Eigen::Vector3f> deproject(const Intrinsics& intrinsics, const Eigen::Vector2f& pixel, float z_m);

/// Whether deproject() reduces to the pinhole formula (no model, or all |coeff| < FLT_EPSILON).
bool is_pinhole(const Intrinsics& intrinsics);

/// The SDK's distortion name ("Brown Conrady", ...) and back; nullopt for an unknown name.
std::string_view distortion_name(Distortion model);
std::optional<Distortion> distortion_from_name(std::string_view name);

/// A D435i's rectified depth intrinsics for a depth resolution it offers
/// (specs/d435-sensor-model.md §2: 1280x720, 848x480, 640x480, 640x360, 480x270, 424x240).
/// Brown-Conrady with zero coefficients, as the camera reports. nullopt for other sizes.
std::optional<Intrinsics> d435_depth_intrinsics(int width, int height);

/// The D435i's stereo baseline in millimetres (specs/d435-sensor-model.md §2).
inline constexpr float kD435BaselineMm = 49.864F;
/// Subpixel disparity noise of a well-textured target, pixels (specs/d435-sensor-model.md §3).
inline constexpr float kD435SubpixelRmsPx = 0.08F;

/// RMS depth noise at depth z_m for a stereo camera: z² · s / (fx · B), metres.
double stereo_depth_sigma_m(double z_m, double fx_px, double baseline_mm, double subpixel_rms_px);

}  // namespace hrcsense

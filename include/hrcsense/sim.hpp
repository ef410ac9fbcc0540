// SPDX-License-Identifier: Apache-2.0
// hrcsense — a plain simulated depth camera: a scene of planes, boxes, spheres and capsules,
// ray-cast into a 16-bit depth image with stereo-like disparity noise, plus ground truth.
#pragma once

#include "hrcsense/camera.hpp"
#include "hrcsense/types.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense {

/// Geometry of one scene object, in the robot base (world) frame, metres.
struct Shape {
  enum class Type { plane, box, sphere, capsule };
  Type type = Type::plane;
  Eigen::Vector3f point = Eigen::Vector3f::Zero();   ///< plane: a point on it; sphere: centre
  Eigen::Vector3f normal = -Eigen::Vector3f::UnitZ(); ///< plane: unit normal (either side)
  Eigen::Vector3f min = Eigen::Vector3f::Zero();     ///< box: axis-aligned lower corner
  Eigen::Vector3f max = Eigen::Vector3f::Zero();     ///< box: axis-aligned upper corner
  Eigen::Vector3f a = Eigen::Vector3f::Zero();       ///< capsule: segment start
  Eigen::Vector3f b = Eigen::Vector3f::Zero();       ///< capsule: segment end
  float radius_m = 0.0F;                             ///< sphere and capsule
};

/// Where a moving object is at a time: its shape is translated by `offset_m`.
struct Waypoint {
  double t_s = 0.0;                                  ///< source time (frame index / fps)
  Eigen::Vector3f offset_m = Eigen::Vector3f::Zero(); ///< translation of the whole object
};

/// One scene object. Several shapes may form one object (a person made of capsules).
struct SceneObject {
  std::string name;
  std::vector<Shape> shapes;
  /// Static objects belong to the background (label 0); others are people and objects that
  /// enter the cell and get label = 1 + their index among the non-static objects.
  bool is_static = true;
  int64_t first_frame = 0;        ///< first frame in which the object exists
  int64_t last_frame = -1;        ///< last frame in which it exists; -1: until the end
  std::vector<Waypoint> path;     ///< empty: never moves; else linear interpolation, held at the ends
};

/// The simulated camera and its noise.
struct SimParams {
  int width = 848;                   ///< 640x480, 848x480 or 1280x720 (D435 intrinsics)
  int height = 480;
  double fps = 30.0;                 ///< nominal frame rate; timestamps are index / fps
  int64_t frames = 600;              ///< length of the simulated sequence
  uint64_t seed = 1;                 ///< noise seed; same seed, same frames
  bool noise = true;                 ///< false: exact depth (still quantised to 1 mm)
  float disparity_noise_px = kD435SubpixelRmsPx;  ///< σ of the Gaussian noise on disparity
  float baseline_mm = kD435BaselineMm;            ///< stereo baseline used for the noise model
  float depth_scale_m = 0.001F;      ///< metres per raw unit (quantisation step)
};

/// A scene: objects plus the camera's pose in the base frame.
struct Scene {
  std::vector<SceneObject> objects;
};

/// Buffers a Simulator reuses between frames so that rendering does not allocate after the
/// first frame. Derived data only: never part of the scene, safe to copy or to leave empty.
struct SimScratch {
  int width = 0;                   ///< size the rays were computed for; 0: not yet
  int height = 0;
  std::vector<float> ray_x;        ///< per pixel: x/z of the pixel's ray, camera frame
  std::vector<float> ray_y;        ///< per pixel: y/z of the pixel's ray, camera frame
  std::vector<Shape> shapes_base;  ///< this frame's existing shapes, moved along their paths
  std::vector<uint16_t> shape_labels;  ///< label of each entry of shapes_base
  PointCloud points_base;          ///< noise-free non-static pixels, base frame (truth contact)
  PointCloud points_camera;        ///< the same points, camera frame
};

/// Renders frames of a scene. Deterministic: frame i depends only on (params, scene, i).
struct Simulator {
  SimParams params;
  Scene scene;
  Pose T_base_camera = Pose::Identity();
  RobotModel robot;  ///< for the ground-truth contact
  /// Reused buffers; because render() writes them, one Simulator must not render from two
  /// threads at once (copy it instead).
  mutable SimScratch scratch;

  /// The depth intrinsics used (D435i for the configured resolution).
  /// Throws std::invalid_argument for a resolution the D435 does not offer.
  Intrinsics intrinsics() const;
  /// Renders frame `index` into `out` (depth, intrinsics, timestamp, baseline, ground truth).
  /// Reuses out's buffers, so rendering into the same Frame does not allocate.
  void render(int64_t index, Frame& out) const;
};

}  // namespace hrcsense

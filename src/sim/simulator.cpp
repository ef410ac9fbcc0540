// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulated D435: places the scene's objects for a frame, casts the depth and
// colour cameras' rays, applies the sensor model and computes the ground truth.

#include "hrcsense/sim/sim.hpp"
#include "sim_color.hpp"
#include "sim_geometry.hpp"
#include "sim_raycast.hpp"
#include "sim_sensor.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace hrcsense {
namespace {

using sim_detail::kNoHit;
using sim_detail::PoseF;

bool exists_at(const SceneObject& object, int64_t index) {
  return object.first_frame <= index && (object.last_frame == -1 || index <= object.last_frame);
}

/// Linear interpolation between waypoints (sorted by t_s), held at both ends.
Eigen::Vector3f path_offset(const std::vector<Waypoint>& path, double t_s) {
  if (path.empty()) return Eigen::Vector3f::Zero();
  if (t_s <= path.front().t_s) return path.front().offset_m;
  for (size_t k = 1; k < path.size(); ++k) {
    if (t_s < path[k].t_s) {
      const Waypoint& w0 = path[k - 1];
      const Waypoint& w1 = path[k];
      const auto f = static_cast<float>((t_s - w0.t_s) / (w1.t_s - w0.t_s));
      return w0.offset_m + f * (w1.offset_m - w0.offset_m);
    }
  }
  return path.back().offset_m;
}

Shape translated(Shape s, const Eigen::Vector3f& offset_m) {
  s.point += offset_m;
  s.min += offset_m;
  s.max += offset_m;
  s.a += offset_m;
  s.b += offset_m;
  return s;
}

/// The moving arm's capsules at frame `index`: the visual ones to render, the searched ones
/// for the truth contact. Both reuse their buffers.
void place_arm(const Simulator& sim, int64_t index, SimScratch& scratch) {
  if (!sim.arm) return;
  const SimArm& arm = *sim.arm;
  const JointAngles q_rad = sim.arm_joints(index).q_rad;
  robot_render_capsules(*arm.robot.arm, q_rad, arm.robot.base_frame, scratch.arm_render);
  robot_model_at(arm.robot, q_rad, scratch.arm_searched);
}

/// The shapes that exist in frame `index`, moved along their paths, with their labels; the
/// moving arm last, as object id objects.size() + 1.
void place_shapes(const Simulator& sim, int64_t index, SimScratch& scratch) {
  place_arm(sim, index, scratch);
  const size_t arm_shapes = sim.arm ? scratch.arm_render.capsules.size() : 0;
  size_t total = arm_shapes;
  for (const SceneObject& object : sim.scene.objects) total += object.shapes.size();
  scratch.shapes_base.reserve(total);  // the first frame sizes for all, so later ones never grow
  scratch.shape_labels.reserve(total);
  scratch.shape_ids.reserve(total);
  scratch.shapes_base.clear();
  scratch.shape_labels.clear();
  scratch.shape_ids.clear();
  // Per object id (0: nothing hit): its label and its material bits. Same size every frame.
  const size_t ids = sim.scene.objects.size() + 1 + (sim.arm ? 1 : 0);
  scratch.label_of_id.assign(ids, kStaticLabel);
  scratch.material_of_id.assign(ids, 0);
  scratch.color_of_id.assign(ids, std::array<uint8_t, 3>{0, 0, 0});
  const double t_s = static_cast<double>(index) / sim.params.fps;
  uint16_t next_label = 1;
  for (size_t k = 0; k < sim.scene.objects.size(); ++k) {
    const SceneObject& object = sim.scene.objects[k];
    const uint16_t label = object.is_static ? kStaticLabel : next_label++;
    const auto id = static_cast<uint16_t>(k + 1);
    scratch.label_of_id[id] = label;
    scratch.color_of_id[id] = object.color_rgb.value_or(kSimPalette[k % kSimPalette.size()]);
    const Material& m = object.material;
    scratch.material_of_id[id] = static_cast<uint8_t>((m.dark ? sim_detail::kDarkBit : 0) |
                                                      (m.shiny ? sim_detail::kShinyBit : 0) |
                                                      (m.low_texture ? sim_detail::kLowTextureBit : 0));
    if (!exists_at(object, index)) continue;
    const Eigen::Vector3f offset_m = path_offset(object.path, t_s);
    for (const Shape& shape : object.shapes) {
      scratch.shapes_base.push_back(translated(shape, offset_m));
      scratch.shape_labels.push_back(label);
      scratch.shape_ids.push_back(id);
    }
  }
  if (!sim.arm) return;
  const size_t k = sim.scene.objects.size();
  const auto id = static_cast<uint16_t>(k + 1);
  scratch.label_of_id[id] = kRobotLabel;
  scratch.color_of_id[id] = sim.arm->color_rgb.value_or(kSimPalette[k % kSimPalette.size()]);
  for (const Capsule& capsule : scratch.arm_render.capsules) {
    if (capsule.radius_m <= 0.0F) continue;  // a bare segment has no surface to see
    scratch.shapes_base.push_back(Shape::capsule(capsule.a, capsule.b, capsule.radius_m));
    scratch.shape_labels.push_back(kRobotLabel);
    scratch.shape_ids.push_back(id);
  }
}

/// What the truth contact measures against: the moving arm's searched capsules this frame, or
/// the fixed robot.
const RobotModel& truth_robot(const Simulator& sim) { return sim.arm ? sim.scratch.arm_searched : sim.robot; }

bool is_foreground_label(uint16_t label) { return label != kStaticLabel && label != kRobotLabel; }

/// Closest robot contact over the analytic surfaces of the existing non-static shapes.
Contact analytic_contact(const SimScratch& scratch, const RobotModel& robot, const PoseF& T_camera_base) {
  Contact best;
  for (size_t k = 0; k < scratch.shapes_base.size(); ++k) {
    if (!is_foreground_label(scratch.shape_labels[k])) continue;
    for (const Capsule& capsule : robot.capsules) {
      const sim_detail::ClosestPair pair = sim_detail::closest_shape_capsule(scratch.shapes_base[k], capsule);
      if (best.valid && !(pair.distance_m < best.distance_m)) continue;
      best.valid = true;
      best.distance_m = pair.distance_m;
      best.closest_base = pair.on_shape;
      best.closest_camera = T_camera_base.apply(pair.on_shape);
      best.closest_robot_base = pair.on_robot;
      best.robot_link = capsule.link;
    }
  }
  return best;
}

/// Labels from the cast's object ids; the z-buffer's misses (+inf) become the truth's 0.
void fill_truth_labels(const SimScratch& scratch, GroundTruth& truth) {
  const size_t n = truth.labels.size();
  const uint16_t* ids = scratch.object_ids.data();
  const uint16_t* label_of_id = scratch.label_of_id.data();
  uint16_t* labels = truth.labels.data();
  float* depth_m = truth.depth_m.data();
  for (size_t i = 0; i < n; ++i) labels[i] = label_of_id[ids[i]];
  // On the bits, because GCC keeps a float select as a branch (trapping math); this way the
  // loop vectorises. Hits are finite and positive and stay as they are.
  constexpr uint32_t kInfBits = 0x7F800000U;
  for (size_t i = 0; i < n; ++i) {
    uint32_t bits = 0;
    std::memcpy(&bits, &depth_m[i], sizeof bits);
    bits &= -static_cast<uint32_t>(bits != kInfBits);
    std::memcpy(&depth_m[i], &bits, sizeof bits);
  }
}

// The distance from `p` to the surface of the nearest of `link`'s capsules, in double.
double link_distance_m(const RobotModel& link, const Eigen::Vector3f& p_f) {
  const Eigen::Vector3d p = p_f.cast<double>();
  double best = std::numeric_limits<double>::infinity();
  for (const Capsule& capsule : link.capsules) {
    const Eigen::Vector3d a = capsule.a.cast<double>();
    const Eigen::Vector3d ab = capsule.b.cast<double>() - a;
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    best = std::min(best, std::max(0.0, (p - (a + t * ab)).norm() - static_cast<double>(capsule.radius_m)));
  }
  return best;
}

// The link's capsules (index `i` of the split) `dt_s` after frame `index`'s time.
const RobotModel& link_at(const Simulator& sim, int64_t index, double dt_s, size_t i) {
  SimScratch& scratch = sim.scratch;
  // The arm's pose dt_s later at the rate in force from the frame on: the speed it moves at.
  const TrajectoryClock::Reading time = sim.arm_time(index);
  const double t_s = time.trajectory_s + dt_s * time.rate;
  robot_model_at(sim.arm->robot, joints_at(sim.arm->trajectory, t_s).q_rad, scratch.arm_nearby);
  split_by_link(scratch.arm_nearby, scratch.nearby_links);
  return scratch.nearby_links[i];
}

/// GroundTruth::links: per link of the truth's capsules, the nearest noise-free moving-object
/// pixel and the link's speed towards it. The speed is the rate at which that pixel's distance
/// to the link's surface shrinks, by central differences of the trajectory's poses around the
/// frame's time: the surface point's velocity along the surface normal, which is the
/// separation direction, without the kinematics' Jacobian (point_velocity) or the search.
void fill_truth_links(const Simulator& sim, int64_t index, GroundTruth& truth) {
  SimScratch& scratch = sim.scratch;
  truth.links.clear();
  if (scratch.points_base.empty()) return;
  split_by_link(truth_robot(sim), scratch.truth_links);
  constexpr double kHalfStepS = 1e-4;
  for (size_t i = 0; i < scratch.truth_links.size(); ++i) {
    const RobotModel& link = scratch.truth_links[i];
    const Contact c = sim_detail::rendered_truth_contact(scratch.points_base, scratch.points_camera, link);
    if (!c.valid) continue;
    LinkTruth out;
    out.link = link.capsules.front().link;
    out.distance_m = c.distance_m;
    if (sim.arm) {
      const double before_m = link_distance_m(link_at(sim, index, -kHalfStepS, i), c.closest_base);
      const double after_m = link_distance_m(link_at(sim, index, kHalfStepS, i), c.closest_base);
      out.speed_towards_mps = static_cast<float>((before_m - after_m) / (2.0 * kHalfStepS));
    }
    truth.links.push_back(out);
  }
}

void fill_truth_contacts(const Simulator& sim, const PoseF& T_base_camera, GroundTruth& truth) {
  SimScratch& scratch = sim.scratch;
  scratch.points_base.clear();
  scratch.points_camera.clear();
  // Plain pointers: push_back below may write any memory as far as the compiler knows, which
  // would reload the vectors' sizes and data for every pixel.
  const size_t n = truth.labels.size();
  const uint16_t* labels = truth.labels.data();
  const float* depth_m = truth.depth_m.data();
  static_assert(kStaticLabel == 0, "the scan below skips four static labels as one zero word");
  for (size_t i = 0; i < n; ++i) {
    // Most pixels are static: skip them four at a time.
    for (uint64_t word = 0; i + 4 <= n; i += 4) {
      std::memcpy(&word, labels + i, sizeof word);
      if (word != 0) break;
    }
    if (i == n) break;
    if (!is_foreground_label(labels[i])) continue;
    const float z = depth_m[i];
    const Eigen::Vector3f p_camera(z * scratch.rays.x[i], z * scratch.rays.y[i], z);
    const Eigen::Vector3f p_base = T_base_camera.apply(p_camera);
    scratch.points_camera.push_back(p_camera.x(), p_camera.y(), p_camera.z(), static_cast<uint32_t>(i));
    scratch.points_base.push_back(p_base.x(), p_base.y(), p_base.z(), static_cast<uint32_t>(i));
  }
  // Both contacts exist only while a non-static object is in view, as a camera would see it.
  if (scratch.points_base.empty()) {
    truth.contact = Contact{};
    truth.analytic_contact = Contact{};
    return;
  }
  const RobotModel& robot = truth_robot(sim);
  truth.contact = sim_detail::rendered_truth_contact(scratch.points_base, scratch.points_camera, robot);
  truth.analytic_contact = analytic_contact(scratch, robot, T_base_camera.inverse());
}

PoseF pose_f(const Pose& pose) {
  PoseF out;
  out.R = pose.linear().cast<float>();
  out.t = pose.translation().cast<float>();
  return out;
}

/// The colour camera's frame: the same placed shapes cast from the colour camera's pose, flat
/// colours per object, nothing hit black.
void render_color(const Simulator& sim, const PoseF& T_base_camera_f, Frame& out) {
  const SimParams& params = sim.params;
  SimScratch& scratch = sim.scratch;
  if (!params.color) {
    out.color.reset();
    out.color_intrinsics = Intrinsics{};
    out.depth_to_color.reset();
    return;
  }
  const Intrinsics in = sim.color_intrinsics();
  const Extrinsics e = sim.depth_to_color();
  // The colour camera's pose: T_base_color = T_base_depth · T_depth_color, where T_depth_color
  // inverts depth_to_color (P_color = R·P_depth + t, R the identity here).
  PoseF T_base_color = T_base_camera_f;
  T_base_color.t = T_base_camera_f.t - T_base_camera_f.R * params.color_translation_m;
  sim_detail::ensure_rays(scratch.color_rays, in);
  const size_t n = static_cast<size_t>(in.width) * in.height;
  scratch.color_z_m.resize(n);
  scratch.color_ids.resize(n);
  sim_detail::cast_shapes(scratch.shapes_base, scratch.shape_ids, scratch.color_rays, T_base_color,
                          scratch.color_z_m.data(), scratch.color_ids.data());
  if (!out.color) out.color.emplace();
  sim_detail::write_color(scratch.color_ids, scratch.color_of_id, in.width, in.height, *out.color);
  out.color_intrinsics = in;
  out.depth_to_color = e;
}

}  // namespace

Intrinsics Simulator::intrinsics() const {
  const bool structured = params.sensor == SimSensor::structured_light;
  const std::optional<Intrinsics> in = structured ? structured_light_intrinsics(params.width, params.height)
                                                  : d435_depth_intrinsics(params.width, params.height);
  if (!in) {
    throw std::invalid_argument(std::string("simulator: the ") + (structured ? "structured-light sensor" : "D435") +
                                " has no " + std::to_string(params.width) + "x" + std::to_string(params.height) +
                                " depth mode");
  }
  return *in;
}

Intrinsics Simulator::color_intrinsics() const {
  const int width = params.color_width > 0 ? params.color_width : params.width;
  const int height = params.color_height > 0 ? params.color_height : params.height;
  const std::optional<Intrinsics> in = d435_color_intrinsics(width, height);
  if (!in) {
    throw std::invalid_argument("simulator: the D435 has no " + std::to_string(width) + "x" + std::to_string(height) +
                                " colour mode");
  }
  return *in;
}

Extrinsics Simulator::depth_to_color() const {
  Extrinsics e;  // identity rotation
  e.translation_m = {params.color_translation_m.x(), params.color_translation_m.y(), params.color_translation_m.z()};
  return e;
}

void Simulator::render(int64_t index, Frame& out) const {
  const Intrinsics in = intrinsics();
  sim_detail::ensure_rays(scratch.rays, in);
  place_shapes(*this, index, scratch);
  // The true pose: the depth and colour casts and every truth (labels, the camera-frame points
  // of the contacts) follow where the camera really is; base-frame distances need no pose.
  const PoseF T_base_camera_f = pose_f(T_base_camera_at(index));

  out.index = index;
  out.timestamp_ns = std::llround(static_cast<double>(index) * 1e9 / params.fps);
  out.intrinsics = in;
  out.stereo_baseline_mm = params.baseline_mm;
  out.depth.resize(in.width, in.height);
  out.depth.depth_scale_m = params.depth_scale_m;
  if (!out.truth) out.truth.emplace();
  GroundTruth& truth = *out.truth;
  const size_t n = static_cast<size_t>(in.width) * in.height;
  truth.depth_m.resize(n);
  truth.labels.resize(n);
  scratch.object_ids.resize(n);

  sim_detail::cast_shapes(scratch.shapes_base, scratch.shape_ids, scratch.rays, T_base_camera_f, truth.depth_m.data(),
                          scratch.object_ids.data());
  scratch.label_index = -1;  // the cast above wrote object_ids but not hit_at()'s z-buffer
  sim_detail::write_sensor_depth(params, in.fx, index, truth.depth_m.data(), scratch, out.depth);
  fill_truth_labels(scratch, truth);
  fill_truth_contacts(*this, T_base_camera_f, truth);
  fill_truth_links(*this, index, truth);
  render_color(*this, T_base_camera_f, out);
}

Simulator::Hit Simulator::hit_at(int64_t index, int pixel) const {
  const Intrinsics in = intrinsics();
  const size_t n = static_cast<size_t>(in.width) * in.height;
  if (pixel < 0 || static_cast<size_t>(pixel) >= n) return Hit{};
  if (scratch.label_index != index) {
    sim_detail::ensure_rays(scratch.rays, in);
    place_shapes(*this, index, scratch);
    const PoseF T_base_camera_f = pose_f(T_base_camera_at(index));  // as render() casts it
    scratch.label_z_m.resize(n);
    scratch.object_ids.resize(n);
    sim_detail::cast_shapes(scratch.shapes_base, scratch.shape_ids, scratch.rays, T_base_camera_f,
                            scratch.label_z_m.data(), scratch.object_ids.data());
    scratch.label_index = index;
  }
  const size_t i = static_cast<size_t>(pixel);
  const float z_m = scratch.label_z_m[i];
  return Hit{scratch.label_of_id[scratch.object_ids[i]], std::isfinite(z_m) ? z_m : 0.0F};  // a miss is +inf
}

const std::string& Simulator::label_name(uint16_t label) const {
  static const std::string static_name = "static";
  static const std::string robot_name = "robot";
  static const std::string none;
  if (label == kStaticLabel) return static_name;
  if (label == kRobotLabel) return robot_name;
  uint16_t next_label = 1;  // as place_shapes numbers them
  for (const SceneObject& object : scene.objects) {
    if (object.is_static) continue;
    if (next_label++ == label) return object.name;
  }
  return none;
}

TrajectoryClock::Reading Simulator::arm_time(int64_t index) const {
  const double t_s = static_cast<double>(index) / params.fps;
  if (!arm->clock) return {t_s, 1.0};
  return arm->clock->advance_to(std::llround(static_cast<double>(index) * 1e9 / params.fps));  // the frame's timestamp_ns
}

TrajectorySample Simulator::arm_joints(int64_t index) const {
  const TrajectoryClock::Reading time = arm_time(index);
  TrajectorySample sample = joints_at(arm->trajectory, time.trajectory_s);
  for (double& qd : sample.qd_rad_s) qd *= time.rate;
  return sample;
}

}  // namespace hrcsense

namespace hrcsense {

double sim_fill_rate(const Simulator& sim, int64_t first, int64_t count) {
  Simulator depth_only = sim;  // the colour image does not count
  depth_only.params.color = false;
  Frame frame;
  size_t valid = 0;
  size_t total = 0;
  for (int64_t i = first; i < first + std::max<int64_t>(count, 1); ++i) {
    depth_only.render(i, frame);
    for (const uint16_t raw : frame.depth.pixels) valid += raw != 0 ? 1U : 0U;
    total += frame.depth.pixels.size();
  }
  return total == 0 ? 0.0 : static_cast<double>(valid) / static_cast<double>(total);
}

}  // namespace hrcsense

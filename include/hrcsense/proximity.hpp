// SPDX-License-Identifier: Apache-2.0
// hrcsense — proximity: the foreground point closest to the robot's capsules (docs/PROXIMITY.md).
#pragma once

#include "hrcsense/types.hpp"

#include <memory>
#include <optional>
#include <string_view>

namespace hrcsense {

/// Distance from point p to a capsule's surface (0 when inside); `closest_on_capsule`
/// receives the nearest point of the capsule's surface (p itself when inside).
float point_capsule_distance(const Eigen::Vector3f& p, const Capsule& capsule,
                             Eigen::Vector3f* closest_on_capsule = nullptr);

/// Closest points of segments p1q1 and p2q2 (either may be a point): their parameters s and t
/// in [0, 1], the points p1 + s·(q1 − p1) and p2 + t·(q2 − p2). The simulator's analytic truth
/// and the viewer's robot silhouette use it.
void closest_segment_params(const Eigen::Vector3f& p1, const Eigen::Vector3f& q1, const Eigen::Vector3f& p2,
                            const Eigen::Vector3f& q2, float& s, float& t);

/// Exact closest contact by brute force over every point and capsule, single-threaded, with
/// no state kept between calls. `points_base` in the base frame; `points_camera` (same order)
/// fills Contact::closest_camera and may be empty. Ties: the smallest float distance, then the
/// lowest point index, then the lowest capsule index (the rule every backend follows).
/// Returns an invalid contact when the cloud or the robot is empty or no point is finite.
Contact closest_contact_brute(const PointCloud& points_base, const PointCloud& points_camera,
                              const RobotModel& robot);

/// The search structures; all are exact and give the same contact (docs/PROXIMITY.md).
enum class ProximityBackend {
  brute,      ///< vectorised scan in blocks, pruned by block boxes; optionally two threads
  kdtree,     ///< nanoflann's kd-tree, rebuilt per frame, with an exact capsule traversal
  octree,     ///< hrcsense's own octree, rebuilt per frame into reused buffers
  automatic,  ///< picks one by cloud size (config name "auto")
};

/// Every backend, in the order the configuration lists them.
inline constexpr ProximityBackend kProximityBackends[] = {ProximityBackend::brute, ProximityBackend::kdtree,
                                                         ProximityBackend::octree, ProximityBackend::automatic};
/// The configuration name of a backend (static string): "brute", "kdtree", "octree" or "auto".
/// The name is parsed in src/config (proximity.backend), nowhere else.
const char* proximity_backend_name(ProximityBackend backend);

/// Tuning of the search; which backend is chosen separately (ProximitySearch's constructor).
struct ProximityParams {
  int octree_height = 4;  ///< octree depth, 1-10 (`proximity.octree.height`); leaves hold >= 1 point
  int threads = 1;        ///< brute only: 1, or 2 for a second worker thread on large clouds
};

/// One backend with its reusable state: after the first frame of a given size no backend but
/// kdtree allocates (nanoflann frees and re-allocates its tree nodes at every build).
/// Not thread-safe; one instance per pipeline.
class ProximitySearch {
 public:
  /// Throws std::invalid_argument for an octree height outside 1-10 or threads outside 1-2.
  explicit ProximitySearch(ProximityBackend backend = ProximityBackend::brute, ProximityParams params = {});
  ~ProximitySearch();
  ProximitySearch(ProximitySearch&&) noexcept;
  ProximitySearch& operator=(ProximitySearch&&) noexcept;
  ProximitySearch(const ProximitySearch&) = delete;
  ProximitySearch& operator=(const ProximitySearch&) = delete;

  /// The exact closest contact; arguments and result as closest_contact_brute. The cloud is
  /// new every frame: trees are rebuilt at every call.
  Contact closest(const PointCloud& points_base, const PointCloud& points_camera, const RobotModel& robot);

  /// The backend the last call used (for `auto`, the one it picked); the configured one before.
  ProximityBackend last_backend() const { return last_backend_; }
  ProximityBackend backend() const { return backend_; }

 private:
  struct State;
  ProximityBackend backend_;
  ProximityBackend last_backend_;
  ProximityParams params_;
  std::unique_ptr<State> state_;
};

}  // namespace hrcsense

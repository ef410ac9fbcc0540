// SPDX-License-Identifier: Apache-2.0
// hrcsense — ProximitySearch: one backend and its reusable state behind one entry point.

#include "brute.hpp"
#include "kdtree.hpp"
#include "octree.hpp"

#include "hrcsense/proximity.hpp"

#include <stdexcept>

namespace hrcsense {
namespace proximity_detail {

Contact make_contact(const Best& best, const PointCloud& points_base, const PointCloud& points_camera,
                     const RobotModel& robot) {
  Contact contact;
  if (!best.found()) return contact;
  const Capsule& capsule = robot.capsules[best.capsule];
  const size_t n = points_base.size();
  contact.valid = true;
  contact.distance_m = best.distance_m;
  contact.inside = best.distance_m == 0.0F;
  contact.closest_base = points_base.point(best.point);
  point_capsule_distance(contact.closest_base, capsule, &contact.closest_robot_base);
  contact.robot_link = capsule.link;
  if (points_camera.size() == n) contact.closest_camera = points_camera.point(best.point);
  if (points_base.pixel.size() == n) contact.pixel = static_cast<int>(points_base.pixel[best.point]);
  return contact;
}

}  // namespace proximity_detail

namespace {

// `auto`: the cloud changes every frame, so a tree pays its whole build for one query; measured
// (docs/PROXIMITY.md, the crossover table) that never pays off at any cloud size, so `auto` is
// brute force until a measurement says otherwise. The size is kept for that rule.
ProximityBackend pick_automatic(size_t /*points*/) { return ProximityBackend::brute; }

}  // namespace

const char* proximity_backend_name(ProximityBackend backend) {
  switch (backend) {
    case ProximityBackend::brute: return "brute";
    case ProximityBackend::kdtree: return "kdtree";
    case ProximityBackend::octree: return "octree";
    case ProximityBackend::automatic: return "auto";
  }
  return "unknown";
}

struct ProximitySearch::State {
  std::vector<proximity_detail::CapsuleBound> capsules;
  std::unique_ptr<proximity_detail::Worker> worker;  ///< brute's second thread, when asked for
  proximity_detail::Octree octree;
  std::unique_ptr<proximity_detail::KdTree> kdtree;  ///< created on first use
};

ProximitySearch::ProximitySearch(ProximityBackend backend, ProximityParams params)
    : backend_(backend), last_backend_(backend), params_(params), state_(std::make_unique<State>()) {
  if (params_.octree_height < 1 || params_.octree_height > 10) {
    throw std::invalid_argument("proximity.octree.height must be 1-10, got " + std::to_string(params_.octree_height));
  }
  if (params_.threads < 1 || params_.threads > 2) {
    throw std::invalid_argument("proximity.threads must be 1 or 2, got " + std::to_string(params_.threads));
  }
  if (params_.threads == 2) state_->worker = std::make_unique<proximity_detail::Worker>();
}

ProximitySearch::~ProximitySearch() = default;
ProximitySearch::ProximitySearch(ProximitySearch&&) noexcept = default;
ProximitySearch& ProximitySearch::operator=(ProximitySearch&&) noexcept = default;

Contact ProximitySearch::closest(const PointCloud& points_base, const PointCloud& points_camera,
                                 const RobotModel& robot) {
  using namespace proximity_detail;
  State& s = *state_;
  prepare_bounds(robot, s.capsules);
  last_backend_ = backend_ == ProximityBackend::automatic ? pick_automatic(points_base.size()) : backend_;
  Best best;
  switch (last_backend_) {
    case ProximityBackend::kdtree:
      if (!s.kdtree) s.kdtree = std::make_unique<KdTree>();
      s.kdtree->build(points_base);
      best = s.kdtree->closest(s.capsules);
      break;
    case ProximityBackend::octree:
      s.octree.build(points_base.x.data(), points_base.y.data(), points_base.z.data(), points_base.size(),
                     params_.octree_height);
      best = s.octree.closest(s.capsules);
      break;
    case ProximityBackend::brute:
    case ProximityBackend::automatic:
      best = brute_search(points_base, s.capsules, s.worker.get());
      break;
  }
  return make_contact(best, points_base, points_camera, robot);
}

}  // namespace hrcsense

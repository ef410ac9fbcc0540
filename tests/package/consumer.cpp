// SPDX-License-Identifier: Apache-2.0
// A consumer of the installed package: two points against one capsule, worked by hand.
// Capsule from (0,0,0) to (1,0,0), radius 0.1. Point 0 at (0.5, 0.5, 0) is 0.5 from the axis,
// so 0.4 from the surface, nearest surface point (0.5, 0.1, 0). Point 1 at (2, 0, 0.3) is
// sqrt(1 + 0.09) - 0.1 = 0.944 from it. The closest contact is point 0 at 0.4 m.
#include "hrcsense/pipeline.hpp"
#include "hrcsense/proximity.hpp"
#include "hrcsense/sim/sim.hpp"
#ifdef CONSUMER_WITH_APPS
#include "hrcsense/config/config.hpp"
#include "hrcsense/recordings/recordings.hpp"
#include "hrcsense/sinks/sinks.hpp"
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace {

bool near(float a, float b) { return std::fabs(a - b) <= 1e-6F; }

bool contact_is_point_0(const hrcsense::Contact& c, const char* what) {
  const bool ok = c.valid && !c.inside && near(c.distance_m, 0.4F) && c.pixel == 7 &&
                  near(c.closest_base.x(), 0.5F) && near(c.closest_base.y(), 0.5F) &&
                  near(c.closest_robot_base.x(), 0.5F) && near(c.closest_robot_base.y(), 0.1F) &&
                  near(c.closest_robot_base.z(), 0.0F);
  std::printf("%s: valid %d distance %.7f m pixel %d -> %s\n", what, static_cast<int>(c.valid),
              static_cast<double>(c.distance_m), c.pixel, ok ? "ok" : "WRONG");
  return ok;
}

}  // namespace

int main() {
  hrcsense::PointCloud cloud;
  cloud.push_back(0.5F, 0.5F, 0.0F, 7);
  cloud.push_back(2.0F, 0.0F, 0.3F, 9);
  hrcsense::RobotModel robot;
  hrcsense::Capsule capsule;
  capsule.a = Eigen::Vector3f(0.0F, 0.0F, 0.0F);
  capsule.b = Eigen::Vector3f(1.0F, 0.0F, 0.0F);
  capsule.radius_m = 0.1F;
  robot.capsules.push_back(capsule);

  bool ok = contact_is_point_0(hrcsense::closest_contact_brute(cloud, {}, robot), "brute");
  // The kd-tree backend: nanoflann is compiled into the library, not needed by a consumer.
  hrcsense::ProximitySearch kdtree(hrcsense::ProximityBackend::kdtree);
  ok = contact_is_point_0(kdtree.closest(cloud, {}, robot), "kdtree") && ok;

  // The simulator is its own library (hrcsense::sim), built with the core alone too. An empty
  // scene at 424x240 seen from the origin: every ray misses, so no pixel has depth.
  hrcsense::Simulator simulator;
  simulator.params.width = 424;
  simulator.params.height = 240;
  simulator.params.noise = false;
  hrcsense::Frame frame;
  simulator.render(0, frame);
  const bool empty_scene = frame.depth.width == 424 && frame.depth.height == 240 &&
                           std::all_of(frame.depth.pixels.begin(), frame.depth.pixels.end(),
                                       [](uint16_t d) { return d == 0; });
  std::printf("simulator: %dx%d, empty scene without depth -> %s\n", frame.depth.width, frame.depth.height,
              empty_scene ? "ok" : "WRONG");
  ok = empty_scene && ok;

#ifdef CONSUMER_WITH_APPS
  // The recordings link lz4 and bz2 privately: this resolves only if the package config found
  // them. A missing file is an error naming it.
  try {
    hrcsense::BagSource bag(hrcsense::RecordingParams{"/nonexistent/hrcsense-consumer.bag"});
    std::printf("BagSource: no error for a missing file -> WRONG\n");
    ok = false;
  } catch (const std::exception& e) {
    std::printf("BagSource: error (%s) -> ok\n", e.what());
  }
  // The configuration reader links yaml-cpp privately.
  try {
    (void)hrcsense::load_config("/nonexistent/hrcsense-consumer.yaml", {});
    std::printf("load_config: no error for a missing file -> WRONG\n");
    ok = false;
  } catch (const hrcsense::ConfigError& e) {
    std::printf("load_config: ConfigError (%s) -> ok\n", e.what());
  }
#endif
  return ok ? 0 : 1;
}

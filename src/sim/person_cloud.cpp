// SPDX-License-Identifier: Apache-2.0
// hrcsense — the synthetic person-shaped cloud and the robots beside it (person_cloud.hpp).

#include "hrcsense/sim/person_cloud.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace hrcsense {
namespace {

struct Part {
  Eigen::Vector3f a, b;  // axis; a == b for a sphere
  float radius_m;
};

// Standing at x = 0, z = 2 m, y down (camera frame): head, torso, arms, legs.
const Part kPerson[] = {
    {{0.0F, -0.75F, 2.0F}, {0.0F, -0.75F, 2.0F}, 0.11F},   // head
    {{0.0F, -0.5F, 2.0F}, {0.0F, 0.1F, 2.0F}, 0.17F},      // torso
    {{-0.25F, -0.45F, 2.0F}, {-0.3F, 0.1F, 1.85F}, 0.05F}, // left arm, a little forward
    {{0.25F, -0.45F, 2.0F}, {0.3F, 0.1F, 2.0F}, 0.05F},    // right arm
    {{-0.1F, 0.2F, 2.0F}, {-0.12F, 1.0F, 2.0F}, 0.07F},    // left leg
    {{0.1F, 0.2F, 2.0F}, {0.12F, 1.0F, 2.0F}, 0.07F},      // right leg
};

}  // namespace

PointCloud person_cloud(size_t n) {
  std::mt19937 rng(2020);
  std::uniform_real_distribution<float> unit(0.0F, 1.0F);
  std::normal_distribution<float> normal(0.0F, 1.0F);
  struct Sample {
    float x, y, z;
    uint32_t pixel;
  };
  std::vector<Sample> samples;
  samples.reserve(n);
  // Part chosen by its (approximate) visible area; surface points facing the camera only.
  float weights[std::size(kPerson)];
  for (size_t k = 0; k < std::size(kPerson); ++k) {
    weights[k] = kPerson[k].radius_m * ((kPerson[k].b - kPerson[k].a).norm() + kPerson[k].radius_m);
  }
  std::discrete_distribution<size_t> pick(std::begin(weights), std::end(weights));
  while (samples.size() < n) {
    const Part& part = kPerson[pick(rng)];
    const Eigen::Vector3f on_axis = part.a + unit(rng) * (part.b - part.a);
    Eigen::Vector3f dir(normal(rng), normal(rng), normal(rng));
    dir.normalize();
    const Eigen::Vector3f p = on_axis + part.radius_m * dir;
    if (dir.dot(p) >= 0.0F) continue;  // faces away from the camera at the origin
    // Pixel of a 848x480 D435 (fx = fy = 420) for depth-image order.
    const int u = std::clamp(static_cast<int>(424.0F + 420.0F * p.x() / p.z()), 0, 847);
    const int v = std::clamp(static_cast<int>(240.0F + 420.0F * p.y() / p.z()), 0, 479);
    samples.push_back({p.x(), p.y(), p.z(), static_cast<uint32_t>(v * 848 + u)});
  }
  std::stable_sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.pixel < b.pixel; });
  PointCloud cloud;
  cloud.reserve(n);
  for (const Sample& s : samples) cloud.push_back(s.x, s.y, s.z, s.pixel);
  return cloud;
}

RobotModel person_cloud_robot_point() {
  RobotModel robot;
  robot.capsules.push_back({{-0.3F, 0.3F, 1.6F}, {-0.3F, 0.3F, 1.6F}, 0.0F, 0});
  return robot;
}

RobotModel person_cloud_robot_arm8() {
  // A chain from a base on the floor left of the person up and toward them.
  const Eigen::Vector3f joints[] = {{-1.0F, 1.0F, 1.5F},  {-1.0F, 0.9F, 1.5F},  {-1.0F, 0.8F, 1.5F},
                                    {-0.9F, 0.4F, 1.55F}, {-0.85F, 0.0F, 1.6F}, {-0.7F, -0.1F, 1.6F},
                                    {-0.6F, -0.1F, 1.65F}, {-0.55F, -0.05F, 1.65F}, {-0.5F, 0.0F, 1.7F}};
  const float radii[] = {0.08F, 0.08F, 0.06F, 0.06F, 0.05F, 0.05F, 0.04F, 0.04F};
  RobotModel robot;
  for (int k = 0; k < 8; ++k) robot.capsules.push_back({joints[k], joints[k + 1], radii[k], k});
  return robot;
}

}  // namespace hrcsense

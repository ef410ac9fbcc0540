// SPDX-License-Identifier: Apache-2.0
// The camera pose check's pieces on values worked by hand: the depth at which a ray enters a
// capsule, one frame's disagreement on a small rendered image, and the window's decision.

#include "hrcsense/pose_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace hrcsense {
namespace {

// A capsule along camera x from (-1, 0, 2) to (1, 0, 2), radius 0.5 m.
const Eigen::Vector3f kA(-1.0F, 0.0F, 2.0F);
const Eigen::Vector3f kB(1.0F, 0.0F, 2.0F);

TEST(PoseCheck, RayEntersTheCylinderAtTheDepthWorkedByHand) {
  CapsuleHit hit;
  // Straight at the axis: the near surface at z = 2 − 0.5.
  ASSERT_TRUE(ray_capsule_depth(Eigen::Vector3f(0, 0, 1), kA, kB, 0.5F, hit));
  EXPECT_NEAR(hit.depth_m, 1.5F, 1e-5F);
  EXPECT_NEAR(hit.axis_share, 0.0F, 1e-3F);
  // (0, 0.125 t, t): (0.125 t)² + (t − 2)² = 0.25 gives 1.015625 t² − 4 t + 3.75 = 0, t = 3.125 / 2.03125;
  // the ray passes the axis at 0.25 / √1.015625 m, 0.49614 of the radius.
  ASSERT_TRUE(ray_capsule_depth(Eigen::Vector3f(0, 0.125F, 1), kA, kB, 0.5F, hit));
  EXPECT_NEAR(hit.depth_m, 3.125F / 2.03125F, 1e-5F);
  EXPECT_NEAR(hit.axis_share, 0.49614F, 1e-4F);
}

TEST(PoseCheck, RayBeyondTheSegmentEntersTheCap) {
  // (0.7 t, 0, t) would enter the cylinder at t = 1.5, x = 1.05 > 1: the cap about b instead,
  // (0.7 t − 1)² + (t − 2)² = 0.25, 1.49 t² − 5.4 t + 4.75 = 0, t = (5.4 − √0.85) / 2.98.
  CapsuleHit hit;
  ASSERT_TRUE(ray_capsule_depth(Eigen::Vector3f(0.7F, 0, 1), kA, kB, 0.5F, hit));
  EXPECT_NEAR(hit.depth_m, (5.4F - std::sqrt(0.85F)) / 2.98F, 1e-5F);
  // The ray's distance to b = (1, 0, 2): |b × ray| / |ray| = |(0, 0.4, 0)| / √1.49 = 0.32769 m,
  // 0.65538 of the radius.
  EXPECT_NEAR(hit.axis_share, 0.65538F, 1e-4F);
}

TEST(PoseCheck, RayMissesOrTheCapsuleIsBehindTheCamera) {
  CapsuleHit hit;
  // (0, t, t) passes the axis at √2 m at best.
  EXPECT_FALSE(ray_capsule_depth(Eigen::Vector3f(0, 1, 1), kA, kB, 0.5F, hit));
  const Eigen::Vector3f behind_a(-1, 0, -2);
  const Eigen::Vector3f behind_b(1, 0, -2);
  EXPECT_FALSE(ray_capsule_depth(Eigen::Vector3f(0, 0, 1), behind_a, behind_b, 0.5F, hit));
  // A sphere (a = b) at (0, 0, 2): entered at 1.5.
  ASSERT_TRUE(ray_capsule_depth(Eigen::Vector3f(0, 0, 1), Eigen::Vector3f(0, 0, 2), Eigen::Vector3f(0, 0, 2), 0.5F, hit));
  EXPECT_NEAR(hit.depth_m, 1.5F, 1e-5F);
}

// A 64×48 image, fx = fy = 50, the principal point at its centre: a wall at 3 m and, in front
// of it, a capsule along camera x at 1.5 m of radius 0.1 m, each pixel's depth from the same
// ray cast (1 mm units).
struct SmallScene {
  Intrinsics intrinsics;
  DepthImage depth;
  RobotModel arm_base;  ///< the capsule in the base frame, which is the camera frame here
  SmallScene() {
    intrinsics.width = 64;
    intrinsics.height = 48;
    intrinsics.fx = intrinsics.fy = 50.0F;
    intrinsics.ppx = 32.0F;
    intrinsics.ppy = 24.0F;
    depth.width = 64;
    depth.height = 48;
    depth.depth_scale_m = 0.001F;
    depth.pixels.assign(64 * 48, 3000);
    Capsule c;
    c.a = Eigen::Vector3f(-0.3F, 0, 1.5F);
    c.b = Eigen::Vector3f(0.3F, 0, 1.5F);
    c.radius_m = 0.1F;
    arm_base.capsules.push_back(c);
    for (int v = 0; v < 48; ++v) {
      for (int u = 0; u < 64; ++u) {
        const Eigen::Vector3f ray((u - 32.0F) / 50.0F, (v - 24.0F) / 50.0F, 1.0F);
        CapsuleHit hit;
        if (ray_capsule_depth(ray, c.a, c.b, c.radius_m, hit)) {
          depth.pixels[static_cast<size_t>(v * 64 + u)] = static_cast<uint16_t>(std::lround(hit.depth_m * 1000.0F));
        }
      }
    }
  }
};

TEST(PoseCheck, TheRightPoseAgreesWithinTheDepthUnit) {
  const SmallScene scene;
  PoseCheckParams params;
  params.grid_px = 1;
  params.patch_px = 0;  // each sample its own pixel, as the depth was rendered
  std::vector<ShapeInCamera> shapes;
  const PoseDisagreement d =
      pose_disagreement(params, scene.depth, scene.intrinsics, Pose::Identity(), scene.arm_base, shapes);
  // The capsule spans about 20 × 7 px; its core (0.6 of the radius) about 4 rows of it.
  EXPECT_GT(d.samples, 40U);
  EXPECT_LE(d.mean_m, 0.0005F);  // rounding to the 1 mm unit only
}

TEST(PoseCheck, APoseOffByTwoCentimetresDisagrees) {
  const SmallScene scene;
  PoseCheckParams params;
  params.grid_px = 1;
  params.patch_px = 0;  // each sample its own pixel, as the depth was rendered
  std::vector<ShapeInCamera> shapes;
  // Told: the camera 2 cm further along y (down in the image) than it is: the capsule is
  // predicted 2 cm up, 0.67 px; its lower core rows then predict the surface nearer than the
  // rows above, and the edge rows of the prediction see the wall.
  Pose told = Pose::Identity();
  told.translation() = Eigen::Vector3d(0, 0.02, 0);
  const PoseDisagreement moved = pose_disagreement(params, scene.depth, scene.intrinsics, told, scene.arm_base, shapes);
  const PoseDisagreement right =
      pose_disagreement(params, scene.depth, scene.intrinsics, Pose::Identity(), scene.arm_base, shapes);
  EXPECT_GT(moved.mean_m, right.mean_m + 0.003F);
  // Told 5 cm nearer along z than it is: every sample 5 cm off.
  told.translation() = Eigen::Vector3d(0, 0, 0.05);
  const PoseDisagreement nearer = pose_disagreement(params, scene.depth, scene.intrinsics, told, scene.arm_base, shapes);
  EXPECT_GT(nearer.samples, 40U);
  EXPECT_NEAR(nearer.mean_m, 0.05F, 0.002F);
}

TEST(PoseCheck, SomethingInFrontOfTheArmIsNoSample) {
  SmallScene scene;
  // A plate at 1 m over the left half of the image hides that half of the capsule.
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 32; ++u) scene.depth.pixels[static_cast<size_t>(v * 64 + u)] = 1000;
  }
  PoseCheckParams params;
  params.grid_px = 1;
  params.patch_px = 0;  // each sample its own pixel, as the depth was rendered
  std::vector<ShapeInCamera> shapes;
  const PoseDisagreement all = pose_disagreement(params, SmallScene().depth, scene.intrinsics, Pose::Identity(),
                                                 scene.arm_base, shapes);
  const PoseDisagreement half =
      pose_disagreement(params, scene.depth, scene.intrinsics, Pose::Identity(), scene.arm_base, shapes);
  EXPECT_LT(half.samples, all.samples * 6 / 10);
  EXPECT_LE(half.mean_m, 0.0005F);
}

TEST(PoseCheck, TheWindowFiresOnItsMeanAndClearsWhenEveryFrameAgrees) {
  PoseCheck check;
  check.params.window_frames = 3;
  check.params.threshold_m = 0.03F;
  check.params.min_arm_pixels = 10;
  const PoseDisagreement off{100, 0.05F};
  const PoseDisagreement right{100, 0.01F};
  const PoseDisagreement unseen{9, 0.5F};  // too few samples: says nothing
  EXPECT_FALSE(check.add(off));
  EXPECT_FALSE(check.add(unseen));
  EXPECT_FALSE(check.add(off));
  EXPECT_TRUE(check.add(off));  // the window is full: mean 0.05
  EXPECT_NEAR(check.window_mean_m(), 0.05F, 1e-6F);
  EXPECT_TRUE(check.add(right));  // mean 0.037 and a frame above: stays
  EXPECT_TRUE(check.add(right));  // mean 0.023, still one frame above
  EXPECT_TRUE(check.add(unseen));
  EXPECT_FALSE(check.add(right));  // every frame of the window at 0.01
  // One frame does not fire it again: the mean of (0.01, 0.01, 0.06) is 0.027.
  EXPECT_FALSE(check.add(PoseDisagreement{100, 0.06F}));
  check.reset();
  EXPECT_FALSE(check.mismatch());
}

}  // namespace
}  // namespace hrcsense

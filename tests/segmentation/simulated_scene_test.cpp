// SPDX-License-Identifier: Apache-2.0
// Segmentation statistics on the simulator's noisy 848x480 frames against its ground truth.

#include "hrcsense/segmentation.hpp"
#include "hrcsense/sim/sim.hpp"

#include <gtest/gtest.h>

#include <cstdint>

namespace hrcsense {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr int64_t kSceneLearnFrames = 50;  // sanitizers: the same checks on fewer frames
constexpr int64_t kEmptyFrames = 60;
#else
constexpr int64_t kSceneLearnFrames = 100;
constexpr int64_t kEmptyFrames = 500;
#endif

/// A cell seen from 2 m above the floor, looking straight down: floor, a back wall, a table
/// 0.75 m high, and (from frame `box_frame`) a 0.3 m box on the table whose top is 1 m from the
/// camera. The box sits on the optical axis, so only its top is visible.
Simulator cell(uint64_t seed, int64_t box_frame) {
  Simulator sim;
  sim.params.seed = seed;
  sim.T_base_camera = Pose::Identity();
  sim.T_base_camera.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;  // camera x = base x, z = base −z
  sim.T_base_camera.translation() = Eigen::Vector3d(0.0, 0.0, 2.0);
  SceneObject statics;
  statics.name = "cell";
  statics.shapes.push_back(Shape::plane({0, 0, 0}, {0, 0, 1}));     // floor
  statics.shapes.push_back(Shape::plane({0, 0.9F, 0}, {0, 1, 0}));  // back wall
  statics.shapes.push_back(Shape::box({-0.6F, -0.5F, 0.0F}, {0.6F, 0.5F, 0.75F}));
  sim.scene.objects.push_back(statics);
  SceneObject parcel;
  parcel.name = "box";
  parcel.shapes.push_back(Shape::box({-0.15F, -0.15F, 0.75F}, {0.15F, 0.15F, 1.0F}));
  parcel.is_static = false;
  parcel.first_frame = box_frame;
  sim.scene.objects.push_back(parcel);
  return sim;
}

/// Learns the background from the first kSceneLearnFrames frames; the batch must be still.
BackgroundModel learn(const Simulator& sim, Frame& frame) {
  BackgroundLearner learner;
  learner.params.frames = static_cast<int>(kSceneLearnFrames);
  for (int64_t i = 0; i < kSceneLearnFrames; ++i) {
    sim.render(i, frame);
    const BackgroundLearner::Status status = learner.add(frame);
    EXPECT_NE(status, BackgroundLearner::Status::restarted) << learner.message();
  }
  EXPECT_TRUE(learner.ready());
  return learner.model();
}

// Hundreds of empty noisy frames after learning: not a single foreground pixel survives.
TEST(SimulatedScene, EmptyCellHasNoForeground) {
  const Simulator sim = cell(7, 1'000'000);  // the box never appears
  Frame frame;
  const BackgroundModel background = learn(sim, frame);
  ForegroundExtractor extractor;
  extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
  Foreground fg;
  size_t worst = 0;
  for (int64_t i = kSceneLearnFrames; i < kSceneLearnFrames + kEmptyFrames; ++i) {
    sim.render(i, frame);
    ASSERT_TRUE(extractor.extract(frame, sim.T_base_camera, fg));
    worst = std::max(worst, fg.points_base.size());
  }
  EXPECT_EQ(worst, 0U);
}

// A box appears after learning: its mask matches the truth labels (on pixels with valid depth)
// with IoU >= 0.95 in every frame, for two noise seeds.
TEST(SimulatedScene, AppearingBoxMatchesTruth) {
  for (const uint64_t seed : {3U, 11U}) {
    const Simulator sim = cell(seed, kSceneLearnFrames);
    Frame frame;
    const BackgroundModel background = learn(sim, frame);
    ForegroundExtractor extractor;
    extractor.set_background(background, frame.intrinsics.fx, frame.stereo_baseline_mm, frame.depth.depth_scale_m);
    Foreground fg;
    for (int64_t i = kSceneLearnFrames; i < kSceneLearnFrames + 10; ++i) {
      sim.render(i, frame);
      ASSERT_TRUE(extractor.extract(frame, sim.T_base_camera, fg));
      size_t both = 0;
      size_t either = 0;
      for (size_t p = 0; p < fg.mask.size(); ++p) {
        if (frame.depth.pixels[p] == 0) continue;
        const bool truth = frame.truth->labels[p] != kStaticLabel;
        both += (truth && fg.mask[p] != 0) ? 1U : 0U;
        either += (truth || fg.mask[p] != 0) ? 1U : 0U;
      }
      ASSERT_GT(either, 10000U) << "the box top should cover ~15k pixels";
      EXPECT_GE(static_cast<double>(both) / static_cast<double>(either), 0.95) << "seed " << seed << " frame " << i;
    }
  }
}

}  // namespace
}  // namespace hrcsense

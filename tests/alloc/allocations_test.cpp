// SPDX-License-Identifier: Apache-2.0
// After a warm-up at the largest cloud, Pipeline::process allocates nothing (STYLE.md, "Real
// time"), for every filter preset and for the brute and octree backends. The kd-tree is the
// documented exception: nanoflann 1.4 frees and re-allocates its node pool at every build
// (docs/PROXIMITY.md) with malloc itself, which a counting operator new cannot see, so it is
// not held to this test.
//
// This binary replaces the global operator new to count allocations, so it holds no other
// tests: a replacement in a family binary would count (and could disturb) all of them.
#include "../support/scenes.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/safety.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <vector>

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// malloc-based, so the sanitizers still see every allocation; GCC cannot see that the replaced
// new and delete match.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace hrcsense {
namespace {

constexpr int kLearnFrames = 20;

// walk.yaml: the empty room for learning, then the person from entering the view to standing
// at the robot (frames 100-200), rendered before any counting.
std::vector<Frame> walk_frames(const Config& config) {
  const Simulator sim = make_simulator(config);
  std::vector<Frame> frames;
  for (int i = 0; i < kLearnFrames; ++i) sim.render(i, frames.emplace_back());
  for (int i = 100; i <= 200; i += 4) sim.render(i, frames.emplace_back());
  return frames;
}

// Allocations during the last of three passes over the person frames, after the first two
// have grown every buffer to the largest cloud.
long allocations_after_warm_up(const std::string& preset, const std::string& backend) {
  const Config config = load_config(test::scene_path("walk.yaml"),
                                    {"filters.preset=" + preset, "proximity.backend=" + backend,
                                     "background.frames=" + std::to_string(kLearnFrames), "sim.color=false"});
  const std::vector<Frame> frames = walk_frames(config);
  Pipeline pipeline(config.pipeline);
  SafetyMonitor monitor(config.pipeline.safety);  // the output thread's decision, measured too
  FrameResult result;
  size_t largest_cloud = 0;
  const RobotState state = fixed_robot_state(config.robot_state.joints_rad);
  for (const Frame& frame : frames) {
    pipeline.process(frame, state, result);
    monitor.decide(result, 0);
    largest_cloud = std::max(largest_cloud, result.foreground_points);
  }
  EXPECT_GT(largest_cloud, 1000U) << preset << "/" << backend << ": the person was not found";
  // The person frames once more before counting: the jump from frame 200 back to frame 100
  // leaves the temporal filter's memory of frame 200 in the first frames of a replay (sdk,
  // thesis), so the counted pass must follow a pass that began the same way; otherwise those
  // frames' filter remnants (small blobs the speckle rule keeps) give the octree a new shape.
  const auto person_pass = [&] {
    for (size_t i = kLearnFrames; i < frames.size(); ++i) {
      pipeline.process(frames[i], state, result);
      monitor.decide(result, 0);
    }
  };
  person_pass();
  const long before = g_allocations.load();
  person_pass();
  const long allocations = g_allocations.load() - before;
  EXPECT_TRUE(result.valid) << result.verdict.reason;
  return allocations;
}

TEST(PipelineAllocations, NoneAfterWarmUpForEveryPresetWithBruteAndOctree) {
  for (const char* preset : {"none", "sdk", "thesis"}) {
    for (const char* backend : {"brute", "octree"}) {
      EXPECT_EQ(allocations_after_warm_up(preset, backend), 0) << preset << "/" << backend;
    }
  }
}

// A UR5 whose joints change every frame (cell-ur5.yaml, the person at the table): the pipeline
// rebuilds the arm's capsules from each robot state into its own buffer, so a moving arm
// allocates nothing either once warmed up; nor does the per-link measurement and its ssm
// decision.
TEST(PipelineAllocations, NoneWithAnArmMovingEveryFrame) {
  const Config config = load_config(test::scene_path("cell-ur5.yaml"),
                                    {"background.frames=" + std::to_string(kLearnFrames), "sim.color=false",
                                     "sim.width=424", "sim.height=240", "safety.mode=ssm"});
  const Simulator sim = make_simulator(config);
  std::vector<Frame> frames;
  for (int i = 0; i < kLearnFrames; ++i) sim.render(i, frames.emplace_back());
  for (int i = 200; i <= 300; i += 10) sim.render(i, frames.emplace_back());
  Pipeline pipeline(config.pipeline);
  FrameResult result;
  // The pan joint swings by up to 0.1 rad about the configured pose, a new pose each frame.
  auto state_for = [&](size_t i) {
    RobotState state = fixed_robot_state(config.robot_state.joints_rad);
    state.q_rad[0] += 0.01 * static_cast<double>(i % 11);
    return state;
  };
  SafetyMonitor monitor(config.pipeline.safety);
  for (size_t i = 0; i < frames.size(); ++i) {
    pipeline.process(frames[i], state_for(i), result);
    monitor.decide(result, 0);
  }
  const long before = g_allocations.load();
  for (size_t i = kLearnFrames; i < frames.size(); ++i) {
    pipeline.process(frames[i], state_for(i + 3), result);
    monitor.decide(result, 0);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_FALSE(result.links.empty()) << "every link near the person is measured";
  EXPECT_TRUE(result.valid) << result.verdict.reason;
  EXPECT_TRUE(result.contact.valid) << "the person at the table must be found";
}

// The search alone, frame after frame on clouds of two sizes: after each size has been seen
// once, neither the octree nor the brute force allocates (both keep their buffers).
TEST(ProximityAllocations, RepeatedFramesAllocateNothing) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> coordinate(-1.0F, 1.0F);
  auto cloud_of = [&](size_t n) {
    PointCloud cloud;
    for (size_t i = 0; i < n; ++i) cloud.push_back(coordinate(rng), coordinate(rng), 1.5F + coordinate(rng), 0);
    return cloud;
  };
  const PointCloud small = cloud_of(3000), large = cloud_of(120000);
  RobotModel robot;
  Capsule capsule;
  capsule.a = {0.5F, -0.5F, 0.5F};
  capsule.b = {1.0F, 0.0F, 0.7F};
  capsule.radius_m = 0.05F;
  robot.capsules.push_back(capsule);
  for (const ProximityBackend backend : {ProximityBackend::brute, ProximityBackend::octree}) {
    ProximityParams params;
    params.octree_height = 7;
    ProximitySearch search(backend, params);
    search.closest(small, PointCloud{}, robot);
    search.closest(large, PointCloud{}, robot);
    const long before = g_allocations.load();
    const Contact a = search.closest(small, PointCloud{}, robot);
    const Contact b = search.closest(large, PointCloud{}, robot);
    EXPECT_EQ(g_allocations.load() - before, 0) << proximity_backend_name(backend);
    EXPECT_TRUE(a.valid && b.valid);
  }
}

// The simulator renders a frame into the buffers of the previous one (docs/SIMULATOR.md):
// depth, colour and truth without allocating once sized.
TEST(SimulatorAllocations, NoneWhenRenderingAgain) {
  const Config config = load_config(test::scene_path("walk.yaml"), {});
  const Simulator sim = make_simulator(config);
  Frame frame;
  for (int i = 150; i < 160; ++i) sim.render(i, frame);  // the person in view: truth points too
  const long before = g_allocations.load();
  for (int i = 160; i < 170; ++i) sim.render(i, frame);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// The moving arm (robot.trajectory) is placed anew every frame into the simulator's buffers:
// still no allocation once sized, with the person in view.
TEST(SimulatorAllocations, NoneWhenRenderingTheMovingArm) {
  const Config config = load_config(test::scene_path("cell-ur5-moving.yaml"), {});
  const Simulator sim = make_simulator(config);
  ASSERT_TRUE(sim.arm.has_value());
  Frame frame;
  for (int i = 250; i < 260; ++i) sim.render(i, frame);
  const long before = g_allocations.load();
  for (int i = 260; i < 270; ++i) sim.render(i, frame);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// Every proximity backend against a double-precision brute-force reference on random clouds,
// and against the brute backend on simulated scenes.

#include "../support/decide.hpp"
#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/proximity.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <optional>
#include <random>
#include <string>

namespace hrcsense {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr double kMaxCloudPoints = 1e4;  // ASan runs ~10x slower: keep the suite fast
constexpr int kSceneFrames = 15;
#else
constexpr double kMaxCloudPoints = 1e5;
constexpr int kSceneFrames = 60;
#endif
constexpr int kCases = 2000;

struct BackendCase {
  const char* name;
  ProximityBackend backend;
  ProximityParams params;
};

std::ostream& operator<<(std::ostream& out, const BackendCase& c) { return out << c.name; }

// Straightforward double-precision reference: every point against every capsule, the first
// pair (lowest point, then lowest capsule) reaching the minimum wins.
struct Reference {
  double distance = std::numeric_limits<double>::infinity();
  size_t point = 0;
  size_t capsule = 0;
  /// A pair within 1e-5 m of the minimum but not exactly at it: float rounding may then order
  /// the two differently, so only the distance is compared. Exact ties (duplicates, points
  /// inside, exactly equidistant points) keep the winner unambiguous: lowest index.
  bool ambiguous = false;
};

double reference_distance(const Eigen::Vector3f& pf, const Capsule& capsule) {
  const Eigen::Vector3d p = pf.cast<double>();
  const Eigen::Vector3d a = capsule.a.cast<double>();
  const Eigen::Vector3d ab = capsule.b.cast<double>() - a;
  double t = ab.squaredNorm() > 0 ? (p - a).dot(ab) / ab.squaredNorm() : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::max(0.0, (p - (a + t * ab)).norm() - capsule.radius_m);
}

Reference reference_contact(const PointCloud& cloud, const RobotModel& robot) {
  Reference best;
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (size_t c = 0; c < robot.capsules.size(); ++c) {
      const double d = reference_distance(cloud.point(i), robot.capsules[c]);
      if (d < best.distance) best = {d, i, c, false};
    }
  }
  for (size_t i = 0; i < cloud.size(); ++i) {
    for (size_t c = 0; c < robot.capsules.size(); ++c) {
      const double d = reference_distance(cloud.point(i), robot.capsules[c]);
      if (d != best.distance && d <= best.distance + 1e-5) best.ambiguous = true;
    }
  }
  return best;
}

// One random case: a cloud and a robot.
struct Case {
  PointCloud cloud;
  RobotModel robot;
  std::string kind;
};

Capsule random_capsule(std::mt19937& rng, bool degenerate, int link) {
  std::uniform_real_distribution<float> coord(-0.8F, 0.8F);
  std::uniform_real_distribution<float> length(-0.4F, 0.4F);
  std::uniform_real_distribution<float> radius(0.0F, 0.12F);
  Capsule c;
  c.a = {coord(rng), coord(rng), coord(rng) + 0.5F};
  c.b = degenerate ? c.a : c.a + Eigen::Vector3f(length(rng), length(rng), length(rng));
  c.radius_m = rng() % 4 == 0 ? 0.0F : radius(rng);
  c.link = link;
  return c;
}

Case make_case(int index) {
  std::mt19937 rng(1000 + index);
  Case out;
  // Log-uniform size in [1, max]; every 50th case empty.
  std::uniform_real_distribution<double> log_size(0.0, std::log(kMaxCloudPoints));
  const size_t n = index % 50 == 0 ? 0 : static_cast<size_t>(std::exp(log_size(rng)));
  const int kind = index % 5;
  // Robot: the thesis's point, one capsule, or eight (some degenerate, some of radius 0).
  const int robot_kind = (index / 5) % 3;
  if (robot_kind == 0) {
    out.robot.capsules.push_back(random_capsule(rng, true, 7));
    out.robot.capsules[0].radius_m = 0.0F;
  } else {
    const int count = robot_kind == 1 ? 1 : 8;
    for (int c = 0; c < count; ++c) out.robot.capsules.push_back(random_capsule(rng, c % 3 == 2, 10 + c));
  }
  std::uniform_real_distribution<float> coord(-1.0F, 1.0F);
  std::uniform_real_distribution<float> depth(0.5F, 2.5F);
  out.cloud.reserve(n);
  auto add = [&](float x, float y, float z) {
    out.cloud.push_back(x, y, z, static_cast<uint32_t>(out.cloud.size() + 1000));
  };
  switch (kind) {
    case 0:  // scattered like a person in front of the robot
      out.kind = "scattered";
      for (size_t i = 0; i < n; ++i) add(coord(rng), coord(rng), depth(rng));
      break;
    case 1: {  // few distinct points, each repeated: exact ties between duplicates
      out.kind = "duplicates";
      const size_t distinct = 1 + n / 50;
      std::vector<Eigen::Vector3f> pool;
      for (size_t k = 0; k < distinct; ++k) pool.emplace_back(coord(rng), coord(rng), depth(rng));
      std::uniform_int_distribution<size_t> pick(0, distinct - 1);
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector3f& p = pool[pick(rng)];
        add(p.x(), p.y(), p.z());
      }
      break;
    }
    case 2: {  // every point at exactly 0.5 m from a robot point (exact in float)
      out.kind = "equidistant";
      out.robot.capsules.assign(1, Capsule{{0.25F, -0.5F, 1.0F}, {0.25F, -0.5F, 1.0F}, 0.0F, 3});
      const Eigen::Vector3f offsets[] = {{0.5F, 0, 0}, {-0.5F, 0, 0}, {0, 0.5F, 0},
                                         {0, -0.5F, 0}, {0, 0, 0.5F}, {0, 0, -0.5F}};
      for (size_t i = 0; i < n; ++i) {
        const Eigen::Vector3f p = out.robot.capsules[0].a + offsets[rng() % 6];
        add(p.x(), p.y(), p.z());
      }
      break;
    }
    case 3: {  // some points well inside capsules: distance 0, lowest index wins
      out.kind = "inside";
      for (Capsule& c : out.robot.capsules) c.radius_m = std::max(c.radius_m, 0.05F);
      std::uniform_real_distribution<float> unit(0.0F, 1.0F);
      for (size_t i = 0; i < n; ++i) {
        if (rng() % 4 != 0) {
          add(coord(rng), coord(rng), depth(rng) + 1.0F);
          continue;
        }
        const Capsule& c = out.robot.capsules[rng() % out.robot.capsules.size()];
        const Eigen::Vector3f on_axis = c.a + unit(rng) * (c.b - c.a);
        const Eigen::Vector3f offset = 0.5F * c.radius_m * Eigen::Vector3f(unit(rng), unit(rng), unit(rng)) / std::sqrt(3.0F);
        const Eigen::Vector3f p = on_axis + offset;
        add(p.x(), p.y(), p.z());
      }
      break;
    }
    default:  // a thin, dense cluster (one surface seen by the camera), far and near
      out.kind = "surface";
      for (size_t i = 0; i < n; ++i) add(coord(rng) * 0.3F, coord(rng) * 0.3F, 1.2F + 0.01F * coord(rng));
      break;
  }
  return out;
}

// The reference of a case, computed once and shared by every backend's run of the suite.
const Reference& cached_reference(int index, const Case& c) {
  static std::vector<std::optional<Reference>> cache(kCases);
  std::optional<Reference>& slot = cache[static_cast<size_t>(index)];
  if (!slot) slot = reference_contact(c.cloud, c.robot);
  return *slot;
}

class Backends : public ::testing::TestWithParam<BackendCase> {};

TEST_P(Backends, MatchDoublePrecisionReferenceOnRandomClouds) {
  ProximitySearch search(GetParam().backend, GetParam().params);
  for (int index = 0; index < kCases; ++index) {
    const Case c = make_case(index);
    const std::string where = "case " + std::to_string(index) + " (" + c.kind + ", " +
                              std::to_string(c.cloud.size()) + " points, " +
                              std::to_string(c.robot.capsules.size()) + " capsules)";
    const Contact got = search.closest(c.cloud, c.cloud, c.robot);
    if (c.cloud.empty()) {
      EXPECT_FALSE(got.valid) << where;
      continue;
    }
    const Reference& ref = cached_reference(index, c);
    ASSERT_TRUE(got.valid) << where;
    ASSERT_NEAR(got.distance_m, ref.distance, 1e-5) << where;
    EXPECT_EQ(got.inside, got.distance_m == 0.0F) << where;
    ASSERT_GE(got.pixel, 1000) << where;
    const size_t point = static_cast<size_t>(got.pixel) - 1000;
    // The reported pair really is a closest pair, seen from the reference.
    const auto capsule = std::find_if(c.robot.capsules.begin(), c.robot.capsules.end(),
                                      [&](const Capsule& k) { return k.link == got.robot_link; });
    ASSERT_NE(capsule, c.robot.capsules.end()) << where;
    EXPECT_TRUE(got.closest_base.isApprox(c.cloud.point(point))) << where;
    if (!ref.ambiguous) {
      EXPECT_EQ(point, ref.point) << where;
      EXPECT_EQ(got.robot_link, c.robot.capsules[ref.capsule].link) << where;
    } else {
      EXPECT_LE(reference_distance(c.cloud.point(point), *capsule), ref.distance + 1e-5) << where;
    }
    // The same tie rule as plain brute force, bit for bit.
    const Contact brute = closest_contact_brute(c.cloud, c.cloud, c.robot);
    EXPECT_EQ(got.distance_m, brute.distance_m) << where;
    EXPECT_EQ(got.pixel, brute.pixel) << where;
    EXPECT_EQ(got.robot_link, brute.robot_link) << where;
    EXPECT_EQ(got.closest_robot_base, brute.closest_robot_base) << where;
    if (HasFailure()) return;  // one case's report is enough
  }
}

TEST_P(Backends, EmptyRobotIsInvalid) {
  ProximitySearch search(GetParam().backend, GetParam().params);
  PointCloud cloud;
  cloud.push_back(1, 2, 3, 0);
  EXPECT_FALSE(search.closest(cloud, cloud, RobotModel{}).valid);
}

TEST_P(Backends, PointsWithNanCoordinatesNeverWin) {
  // A NaN coordinate (never produced by the foreground stage, but possible from a broken
  // source) must neither win nor hide the finite points.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  RobotModel robot;
  robot.capsules.push_back(Capsule{{0, 0, 0}, {0, 0, 0}, 0.1F, 4});
  robot.capsules.push_back(Capsule{{0, 0, 1}, {0, 1, 1}, 0.0F, 5});
  ProximitySearch search(GetParam().backend, GetParam().params);
  for (size_t n : {size_t{3}, size_t{40000}}) {
    PointCloud cloud;
    for (size_t i = 0; i < n; ++i) {
      const float f = static_cast<float>(i % 100) * 0.01F;
      if (i % 7 == 0) {
        cloud.push_back(nan, f, 1.0F, static_cast<uint32_t>(i));
      } else {
        cloud.push_back(2.0F + f, f, 3.0F, static_cast<uint32_t>(i));
      }
    }
    const Contact got = search.closest(cloud, cloud, robot);
    const Contact brute = closest_contact_brute(cloud, cloud, robot);
    ASSERT_TRUE(got.valid) << n;
    EXPECT_FALSE(got.inside) << n;
    EXPECT_NE(got.pixel % 7, 0) << n;
    EXPECT_EQ(got.pixel, brute.pixel) << n;
    EXPECT_EQ(got.distance_m, brute.distance_m) << n;
  }
}

TEST_P(Backends, BuffersAreReusedAcrossClouds) {
  // The same search object over clouds that grow and shrink gives the same answers as new ones.
  ProximitySearch reused(GetParam().backend, GetParam().params);
  for (int index : {7, 13, 1, 401, 2, 6, 13}) {
    const Case c = make_case(index);
    ProximitySearch fresh(GetParam().backend, GetParam().params);
    const Contact a = reused.closest(c.cloud, PointCloud{}, c.robot);
    const Contact b = fresh.closest(c.cloud, PointCloud{}, c.robot);
    EXPECT_EQ(a.valid, b.valid) << index;
    EXPECT_EQ(a.distance_m, b.distance_m) << index;
    EXPECT_EQ(a.pixel, b.pixel) << index;
  }
}

const BackendCase kBackends[] = {
    {"brute", ProximityBackend::brute, {}},
    {"brute_two_threads", ProximityBackend::brute, {8, 2}},
    {"kdtree", ProximityBackend::kdtree, {}},
    {"octree_h1", ProximityBackend::octree, {1, 1}},
    {"octree_h4", ProximityBackend::octree, {4, 1}},
    {"octree_h8", ProximityBackend::octree, {8, 1}},
    {"octree_h10", ProximityBackend::octree, {10, 1}},
    {"auto", ProximityBackend::automatic, {}},
};

INSTANTIATE_TEST_SUITE_P(Proximity, Backends, ::testing::ValuesIn(kBackends),
                         [](const ::testing::TestParamInfo<BackendCase>& info) { return std::string(info.param.name); });

// The second thread takes the upper half of clouds from 2^18 points on (src/proximity/brute.cpp),
// sizes the random suite above never reaches. The same contact as one thread, bit for bit: a
// minimum in either half, and an exact tie across the halves (the lower index wins).
TEST(ProximitySearch, TwoThreadsSplitLargeCloudsWithTheSameContact) {
  constexpr size_t kPoints = 300000;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(-1.0F, 1.0F);
  RobotModel robot;
  for (int link = 0; link < 8; ++link) robot.capsules.push_back(random_capsule(rng, link % 4 == 0, link));
  const Eigen::Vector3f near_point = robot.capsules[3].a + Eigen::Vector3f(0.0F, 0.0F, robot.capsules[3].radius_m + 0.01F);
  ProximitySearch one(ProximityBackend::brute, {8, 1});
  ProximitySearch two(ProximityBackend::brute, {8, 2});
  for (const char* layout : {"random", "nearest in the lower half", "nearest in the upper half", "tie across the halves"}) {
    PointCloud cloud;
    for (size_t i = 0; i < kPoints; ++i) cloud.push_back(coord(rng), coord(rng), coord(rng) + 2.5F, static_cast<uint32_t>(i));
    const std::string kind = layout;
    auto place = [&](size_t i) {
      cloud.x[i] = near_point.x();
      cloud.y[i] = near_point.y();
      cloud.z[i] = near_point.z();
    };
    if (kind == "nearest in the lower half" || kind == "tie across the halves") place(1000);
    if (kind == "nearest in the upper half" || kind == "tie across the halves") place(kPoints - 1000);
    const Contact a = one.closest(cloud, PointCloud{}, robot);
    const Contact b = two.closest(cloud, PointCloud{}, robot);
    ASSERT_TRUE(a.valid && b.valid) << kind;
    EXPECT_EQ(a.distance_m, b.distance_m) << kind;
    EXPECT_EQ(a.pixel, b.pixel) << kind;
    EXPECT_EQ(a.robot_link, b.robot_link) << kind;
    EXPECT_NEAR(b.distance_m, reference_contact(cloud, robot).distance, 1e-5) << kind;
    const bool lower_wins = kind == "nearest in the lower half" || kind == "tie across the halves";
    if (kind != "random") {
      EXPECT_EQ(b.pixel, lower_wins ? 1000U : kPoints - 1000) << kind;
    }
  }
}

TEST(ProximitySearch, EveryBackendHasItsConfigurationName) {
  // proximity.backend's names (docs/CONFIG.md); the configuration parses them (tests/config).
  const std::pair<ProximityBackend, const char*> named[] = {{ProximityBackend::brute, "brute"},
                                                            {ProximityBackend::kdtree, "kdtree"},
                                                            {ProximityBackend::octree, "octree"},
                                                            {ProximityBackend::automatic, "auto"}};
  ASSERT_EQ(std::size(kProximityBackends), std::size(named));
  for (size_t i = 0; i < std::size(named); ++i) {
    EXPECT_EQ(kProximityBackends[i], named[i].first);
    EXPECT_STREQ(proximity_backend_name(named[i].first), named[i].second);
  }
}

TEST(ProximitySearch, RejectsBadParameters) {
  EXPECT_THROW(ProximitySearch(ProximityBackend::octree, {0, 1}), std::invalid_argument);
  EXPECT_THROW(ProximitySearch(ProximityBackend::octree, {11, 1}), std::invalid_argument);
  EXPECT_THROW(ProximitySearch(ProximityBackend::brute, {8, 3}), std::invalid_argument);
}

// The simulated scenes with their robot point: the pipeline's foreground of every frame, searched
// by every backend, gives the brute pipeline's distance. Reduced resolution keeps it fast.
void expect_backends_agree_on_scene(const char* config_name, int first_frame, int frames) {
  const std::filesystem::path path = std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config" / config_name;
  const Config config = load_config(path.string(), {"sim.width=424", "sim.height=240", "background.frames=20",
                                                    "sim.frames=" + std::to_string(first_frame + frames)});
  std::unique_ptr<Source> source = make_source(config);
  Pipeline pipeline(config.pipeline);
  std::vector<std::pair<std::string, ProximitySearch>> searches;
  for (const BackendCase& b : kBackends) searches.emplace_back(b.name, ProximitySearch(b.backend, b.params));
  Frame frame;
  FrameResult result;
  int compared = 0;
  while (source->next(frame) == Source::Status::frame) {
    test::process_and_decide(pipeline, frame, fixed_robot_state(config.robot_state.joints_rad), result);
    if (frame.index < first_frame || !result.valid || !result.contact.valid) continue;
    ASSERT_STREQ(result.backend, "brute");
    const PointCloud& base = pipeline.foreground().points_base;
    for (auto& [name, search] : searches) {
      const Contact c = search.closest(base, pipeline.foreground().points_camera, pipeline.robot());
      ASSERT_TRUE(c.valid) << name << " frame " << frame.index;
      EXPECT_EQ(c.distance_m, result.contact.distance_m) << name << " frame " << frame.index;
      EXPECT_EQ(c.pixel, result.contact.pixel) << name << " frame " << frame.index;
    }
    ++compared;
  }
  EXPECT_GE(compared, frames / 2) << config_name << ": too few frames with foreground";
}

TEST(ProximityScenes, ThesisBoxEveryBackendMatchesBrute) { expect_backends_agree_on_scene("thesis-box.yaml", 100, kSceneFrames); }

TEST(ProximityScenes, WalkEveryBackendMatchesBrute) { expect_backends_agree_on_scene("walk.yaml", 150, kSceneFrames); }

TEST(ProximityScenes, PipelineReportsTheBackendItUsed) {
  const std::filesystem::path path = std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config" / "thesis-box.yaml";
  for (const char* backend : {"octree", "kdtree", "auto"}) {
    const Config config = load_config(path.string(), {"sim.width=424", "sim.height=240", "background.frames=5",
                                                      "sim.frames=110", std::string("proximity.backend=") + backend});
    std::unique_ptr<Source> source = make_source(config);
    Pipeline pipeline(config.pipeline);
    Frame frame;
    FrameResult result;
    while (source->next(frame) == Source::Status::frame) test::process_and_decide(pipeline, frame, fixed_robot_state(config.robot_state.joints_rad), result);
    ASSERT_TRUE(result.valid) << backend;
    ASSERT_TRUE(result.contact.valid) << backend;
    // auto names its pick, never "auto".
    EXPECT_STREQ(result.backend, std::string(backend) == "auto" ? "brute" : backend);
  }
}

}  // namespace
}  // namespace hrcsense

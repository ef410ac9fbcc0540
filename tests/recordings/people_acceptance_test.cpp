// SPDX-License-Identifier: Apache-2.0
// Acceptance (issue C1): the whole pipeline on a real depth camera's recording of people
// walking through a room (../shared/data/ist_piv_lab_people, frames seconds apart), without
// depth filters and with the default (SDK) preset.
#include "../support/decide.hpp"
#include "recordings_test_util.hpp"

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/robot_state.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kEdgePx = 8;  // source pixels: a sliver of a person entering or leaving the view

struct FrameStats {
  double foreground_share = 0.0;  ///< foreground pixels / all pixels
  bool contact = false;
  bool valid = false;             ///< processed with a ready background
  std::string reason;             ///< the verdict's reason
  double closest_depth_m = kNaN;
  double closest_blob_share = 0.0;  ///< size of the foreground blob holding the closest pixel
  bool closest_at_edge = false;     ///< the closest pixel lies within kEdgePx source pixels of the border
  /// How far the closest point is in front of the empty room: the nearest valid depth of the
  /// recording's frames 0-2 (unfiltered) at its pixel or, where they have none (about 20 % of
  /// the room: windows, dark screens), within the first of 8, 16, 32 source pixels around it
  /// that has one, minus its depth; NaN when there is none.
  double closest_gap_m = kNaN;
};

/// The empty room of frames 0-2: per source pixel the nearest valid depth (m), 0 where none.
struct EmptyRoom {
  int width = 0;
  std::vector<float> nearest_m;
  void add(const DepthImage& depth) {
    width = depth.width;
    nearest_m.resize(depth.pixels.size(), 0.0F);
    for (size_t i = 0; i < depth.pixels.size(); ++i) {
      const float z_m = depth.pixels[i] * depth.depth_scale_m;
      if (depth.pixels[i] != 0 && (nearest_m[i] == 0.0F || z_m < nearest_m[i])) nearest_m[i] = z_m;
    }
  }
  /// The nearest depth over the source pixels that pixel `i` of an image `image_width` wide
  /// covers (decimation: a block of source pixels), widened by `margin_px` source pixels.
  float nearest_at(int i, int image_width, int margin_px) const {
    const int scale = width / image_width;
    const int height = static_cast<int>(nearest_m.size()) / width;
    const int u0 = (i % image_width) * scale, v0 = (i / image_width) * scale;
    float nearest = 0.0F;
    for (int v = std::max(v0 - margin_px, 0); v < std::min(v0 + scale + margin_px, height); ++v) {
      for (int u = std::max(u0 - margin_px, 0); u < std::min(u0 + scale + margin_px, width); ++u) {
        const float z_m = nearest_m[static_cast<size_t>(v) * width + u];
        if (z_m > 0.0F && (nearest == 0.0F || z_m < nearest)) nearest = z_m;
      }
    }
    return nearest;
  }
};

/// Pixels of the 4-connected foreground region containing `seed` (0 when seed is not in it).
size_t blob_size(const std::vector<uint8_t>& mask, int width, int height, int seed) {
  if (seed < 0 || static_cast<size_t>(seed) >= mask.size() || mask[static_cast<size_t>(seed)] == 0) return 0;
  std::vector<uint8_t> seen(mask.size(), 0);
  std::vector<int> stack{seed};
  seen[static_cast<size_t>(seed)] = 1;
  size_t count = 0;
  while (!stack.empty()) {
    const int p = stack.back();
    stack.pop_back();
    ++count;
    const int u = p % width, v = p / width;
    const int neighbours[4] = {u > 0 ? p - 1 : -1, u + 1 < width ? p + 1 : -1, v > 0 ? p - width : -1,
                               v + 1 < height ? p + width : -1};
    for (int q : neighbours) {
      if (q < 0 || mask[static_cast<size_t>(q)] == 0 || seen[static_cast<size_t>(q)] != 0) continue;
      seen[static_cast<size_t>(q)] = 1;
      stack.push_back(q);
    }
  }
  return count;
}

FrameStats frame_stats(const Pipeline& pipeline, const Frame& processed, const FrameResult& result,
                       const EmptyRoom& room) {
  const std::vector<uint8_t>& mask = pipeline.foreground().mask;
  FrameStats s;
  s.foreground_share = mask.empty() ? 0.0
                                    : static_cast<double>(std::count(mask.begin(), mask.end(), uint8_t{1})) /
                                          static_cast<double>(mask.size());
  s.contact = result.contact.valid;
  s.valid = result.valid;
  s.reason = result.verdict.reason;
  if (!s.contact) return s;
  const int pixel = result.contact.pixel;
  s.closest_depth_m = result.contact.closest_camera.z();
  s.closest_blob_share = static_cast<double>(blob_size(mask, processed.depth.width, processed.depth.height, pixel)) /
                         static_cast<double>(mask.size());
  const int scale = room.width / processed.depth.width;  // decimation: source pixels per filtered pixel
  const int u = pixel % processed.depth.width * scale, v = pixel / processed.depth.width * scale;
  const int source_height = static_cast<int>(room.nearest_m.size()) / room.width;
  s.closest_at_edge = u < kEdgePx || v < kEdgePx || u + scale > room.width - kEdgePx ||
                      v + scale > source_height - kEdgePx;
  float room_m = 0.0F;
  for (int margin_px = 0; margin_px <= 32 && room_m == 0.0F; margin_px = std::max(2 * margin_px, 8)) {
    room_m = room.nearest_at(pixel, processed.depth.width, margin_px);
  }
  if (room_m > 0.0F) s.closest_gap_m = room_m - s.closest_depth_m;
  return s;
}

/// Runs the pipeline over the recording; calls `visit(frame_index, pipeline, depth, result)` for
/// every frame with the depth image the foreground was computed from (after the filters).
template <typename Visit>
std::vector<FrameStats> run_people(const std::string& path, const std::vector<std::string>& extra, Visit visit) {
  std::vector<std::string> sets{"source.type=folder", "source.path=" + path, "background.frames=3"};
  sets.insert(sets.end(), extra.begin(), extra.end());
  const Config config = load_config("", sets);
  std::unique_ptr<Source> source = make_source(config);
  Pipeline pipeline(config.pipeline);
  // The filters' output is not exposed by the pipeline: a second chain with the same
  // parameters (deterministic) gives the image the foreground was computed from.
  FilterChain chain;
  chain.params = config.pipeline.filters;
  Frame frame;
  Frame filtered;
  FrameResult result;
  EmptyRoom room;
  std::vector<FrameStats> stats;
  while (source->next(frame) == Source::Status::frame) {
    if (stats.size() < 3) room.add(frame.depth);
    test::process_and_decide(pipeline, frame, fixed_robot_state(config.robot_state.joints_rad), result);
    const Frame* processed = &frame;
    if (!chain.params.order.empty()) {
      chain.start(frame, filtered);
      for (size_t i = 0; i < chain.block_count(); ++i) chain.run_block(i, filtered);
      processed = &filtered;
    }
    stats.push_back(frame_stats(pipeline, *processed, result, room));
    visit(stats.size() - 1, pipeline, processed->depth, result);
  }
  return stats;
}

std::vector<FrameStats> run_people(const std::string& path, const std::vector<std::string>& extra) {
  return run_people(path, extra, [](size_t, const Pipeline&, const DepthImage&, const FrameResult&) {});
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? kNaN : values[values.size() / 2];
}

/// One line per frame range for docs/RECORDINGS.md: min / median / max foreground share, and the
/// closest point's depth (min / median) where there is one.
void print_summary(const std::vector<FrameStats>& stats, const char* label) {
  const size_t ranges[][2] = {{3, 7}, {8, 25}, {26, 29}, {30, 99}, {100, 107}};
  for (const auto& range : ranges) {
    std::vector<double> share, depth;
    for (size_t i = range[0]; i <= range[1] && i < stats.size(); ++i) {
      share.push_back(100.0 * stats[i].foreground_share);
      if (stats[i].contact) depth.push_back(stats[i].closest_depth_m);
    }
    std::printf("[people %s] frames %zu-%zu: foreground min %.2f %% median %.2f %% max %.2f %%; closest z min %.2f m "
                "median %.2f m (%zu frames with contact)\n",
                label, range[0], range[1], *std::min_element(share.begin(), share.end()), median(share),
                *std::max_element(share.begin(), share.end()),
                depth.empty() ? kNaN : *std::min_element(depth.begin(), depth.end()), median(depth), depth.size());
  }
  double min_gap_m = kNaN, min_blob = kNaN;
  for (size_t i = 30; i <= 99 && i < stats.size(); ++i) {
    min_gap_m = std::fmin(min_gap_m, stats[i].closest_gap_m);
    min_blob = std::fmin(min_blob, 100.0 * stats[i].closest_blob_share);
  }
  std::printf("[people %s] frames 30-99: the closest point stands >= %.2f m in front of the empty room, in blobs of "
              ">= %.2f %%\n",
              label, min_gap_m, min_blob);
}

void check_acceptance(const std::vector<FrameStats>& stats, const char* label) {
  ASSERT_EQ(stats.size(), 108U);
  // Three learning frames (the empty room), then every frame is processed.
  for (size_t i = 0; i < stats.size(); ++i) EXPECT_EQ(stats[i].valid, i >= 3) << label << ": frame " << i;
  // Empty: at most 1 % of the image. The speckle threshold, 32 mm = 0.8 of the detection
  // capability d (a 40 mm test piece measures 35-45 mm, docs/SAFETY.md), keeps some of this
  // structured-light camera's noise blobs 2.7-3.5 m away: up to 0.69 % without filters (0.41 %
  // with the old rule, a square of side 40 mm); their closest point stays at least 2.7 m from
  // the camera and every empty frame says run.
  for (size_t i = 8; i <= 25; ++i) {
    EXPECT_LE(stats[i].foreground_share, 0.01) << label << ": empty frame " << i;
  }
  for (size_t i = 30; i <= 99; ++i) {
    EXPECT_GE(stats[i].foreground_share, 0.02) << label << ": frame " << i << " with people";
    EXPECT_TRUE(stats[i].contact) << label << ": frame " << i;
    // On a person: the closest point lies in a foreground blob of at least 0.25 % of the image
    // (noise blobs in the empty frames stayed below 0.15 % with the old speckle rule; a person
    // half out of the image, as in frame 83, is 0.46 %) or, at the image's edge, in a sliver of
    // a person entering or leaving the view (frame 42: an arm at the left edge 0.97 m away, 0.10 %; with `sdk` also frames
    // 83-85, the left edge of frame 83's person, held by the temporal filter's persistence; the
    // 32 mm speckle threshold keeps such slivers, the old 40 mm square rule removed them and
    // took a farther person's point), stands at least 0.25 m in front of everything the
    // recording showed there in the empty frames 0-2 (the dataset README's criterion for
    // people, checked on the unfiltered data, independently of the learnt model), and at a
    // depth where the README finds people (0.8-2.6 m, with some slack).
    EXPECT_TRUE(stats[i].closest_blob_share >= 0.0025 || stats[i].closest_at_edge)
        << label << ": frame " << i << ": closest point in a blob of " << 100.0 * stats[i].closest_blob_share
        << " % away from the image's edge";
    EXPECT_GE(stats[i].closest_gap_m, 0.25) << label << ": frame " << i;  // NaN (no data) fails
    EXPECT_GT(stats[i].closest_depth_m, 0.6) << label << ": frame " << i;
    EXPECT_LT(stats[i].closest_depth_m, 4.0) << label << ": frame " << i;
  }
  print_summary(stats, label);
  if (::testing::Test::HasFailure()) {
    for (size_t i = 0; i < stats.size(); ++i) {
      std::printf("%s frame %zu: valid %d, foreground %.2f %%, closest z %.3f m (%.3f m before the empty room) in a "
                  "blob of %.2f %% (%s)\n",
                  label, i, stats[i].valid ? 1 : 0, 100.0 * stats[i].foreground_share, stats[i].closest_depth_m,
                  stats[i].closest_gap_m, 100.0 * stats[i].closest_blob_share, stats[i].reason.c_str());
    }
  }
}

TEST(PeopleAcceptance, NoFiltersForegroundIsPeopleAndEmptyFramesStayEmpty) {
  const std::string path = test::shared_data("ist_piv_lab_people");
  if (path.empty()) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  check_acceptance(run_people(path, {"filters.preset=none"}), "none");
}

// Issue 32's rule on this camera (a structured-light camera hrcsense was not tuned for): five
// learning frames, no filters. The head entering at frames 4-5 (dataset README) refuses the two
// batches that hold it; the room is static from frame 6, so learning must finish within
// 2 x 5 frames of it, by frame 15. Then the empty frames up to 25 stay at most 0.5 % foreground
// and the frames with people (26-101, 8-37 % by the README's crude check) at least 1 %.
TEST(PeopleAcceptance, FiveLearningFramesFinishWithinTwoBatchesAndEmptyFramesStayQuiet) {
  const std::string path = test::shared_data("ist_piv_lab_people");
  if (path.empty()) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  const std::vector<FrameStats> stats = run_people(path, {"filters.preset=none", "background.frames=5"});
  ASSERT_EQ(stats.size(), 108U);
  size_t first_valid = stats.size();
  for (size_t i = 0; i < stats.size() && first_valid == stats.size(); ++i) first_valid = stats[i].valid ? i : first_valid;
  ASSERT_LE(first_valid, 6U + 2U * 5U) << "learning did not finish within two batches of the static room";
  double worst_empty = 0.0, weakest_people = 1.0;
  for (size_t i = first_valid; i <= 25; ++i) {
    EXPECT_LE(stats[i].foreground_share, 0.005) << "empty frame " << i;
    worst_empty = std::max(worst_empty, stats[i].foreground_share);
  }
  for (size_t i = 26; i <= 101; ++i) {
    EXPECT_GE(stats[i].foreground_share, 0.01) << "frame " << i << " with people";
    weakest_people = std::min(weakest_people, stats[i].foreground_share);
  }
  std::printf("[people 5 frames] learnt by frame %zu; empty frames at most %.2f %% foreground, frames with people at "
              "least %.2f %%\n",
              first_valid, 100.0 * worst_empty, 100.0 * weakest_people);
}

// The default preset: without a stereo baseline the chain runs in the depth domain, and its
// decimation halves the resolution (320x240).
TEST(PeopleAcceptance, SdkFiltersForegroundIsPeopleAndEmptyFramesStayEmpty) {
  const std::string path = test::shared_data("ist_piv_lab_people");
  if (path.empty()) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  check_acceptance(run_people(path, {"filters.preset=sdk"}), "sdk");
}

/// The picture for docs/RECORDINGS.md: depth in grey (near is bright, no data black), the
/// foreground tinted orange, the closest point as a red disc with a white ring. Images smaller
/// than 640 px wide (decimated) are enlarged by pixel repetition.
ColorImage people_picture(const DepthImage& depth, const std::vector<uint8_t>& mask, int closest_pixel) {
  const int scale = std::max(1, 640 / depth.width);
  ColorImage image;
  image.width = depth.width * scale;
  image.height = depth.height * scale;
  image.rgb.assign(static_cast<size_t>(image.width) * image.height * 3, 0);
  const int cu = closest_pixel >= 0 ? closest_pixel % depth.width : -100;
  const int cv = closest_pixel >= 0 ? closest_pixel / depth.width : -100;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const size_t i = static_cast<size_t>(y / scale) * depth.width + static_cast<size_t>(x / scale);
      const double z_m = depth.pixels[i] * static_cast<double>(depth.depth_scale_m);
      // 0.5 m -> 255, 9 m -> 40.
      const double grey = depth.pixels[i] == 0 ? 0.0 : std::clamp(255.0 - (z_m - 0.5) * (215.0 / 8.5), 40.0, 255.0);
      double rgb[3] = {grey, grey, grey};
      if (mask[i] != 0) {
        const double tint[3] = {255.0, 140.0, 0.0};
        for (int c = 0; c < 3; ++c) rgb[c] = 0.35 * grey + 0.65 * tint[c];
      }
      const double d = std::hypot((x + 0.5) / scale - (cu + 0.5), (y + 0.5) / scale - (cv + 0.5)) * scale;
      if (d <= 7.0) rgb[0] = 255.0, rgb[1] = 0.0, rgb[2] = 0.0;
      else if (d <= 10.0) rgb[0] = rgb[1] = rgb[2] = 255.0;
      uint8_t* out = &image.rgb[(static_cast<size_t>(y) * image.width + x) * 3];
      for (int c = 0; c < 3; ++c) out[c] = static_cast<uint8_t>(std::lround(rgb[c]));
    }
  }
  return image;
}

// Writes docs/images/people_frame_<N>_<preset>.png; run on purpose only:
//   test_recordings --gtest_also_run_disabled_tests --gtest_filter=PeopleAcceptance.DISABLED_WritePictures
TEST(PeopleAcceptance, DISABLED_WritePictures) {
  const std::string path = test::shared_data("ist_piv_lab_people");
  if (path.empty()) GTEST_SKIP() << "../shared/data/ist_piv_lab_people is absent";
  constexpr size_t kFrame = 61;
  for (const char* preset : {"none", "sdk"}) {
    bool written = false;
    run_people(path, {std::string("filters.preset=") + preset},
               [&](size_t index, const Pipeline& pipeline, const DepthImage& depth, const FrameResult& result) {
                 if (index != kFrame) return;
                 char name[96];
                 std::snprintf(name, sizeof name, "/docs/images/people_frame_%zu_%s.png", kFrame, preset);
                 write_color_png(std::string(HRCSENSE_SOURCE_DIR) + name,
                                 people_picture(depth, pipeline.foreground().mask, result.contact.pixel));
                 written = true;
               });
    EXPECT_TRUE(written) << preset;
  }
}

}  // namespace
}  // namespace hrcsense

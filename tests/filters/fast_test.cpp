// SPDX-License-Identifier: Apache-2.0
// The fast (strip-interleaved, SIMD) filters against the plain references of reference.hpp,
// bit for bit, on random images of many sizes (every width modulo the SIMD and strip widths)
// and every option set; and the properties of issue 4: no filter but threshold turns a valid
// pixel invalid, the result does not depend on where the data sits in memory (rows shifted
// across the lanes here; every block with the buffer's base address moved: the binary of its
// own in tests/filters_alignment/), and a filter run twice on the same input with reset state
// gives the same output.
#include "hrcsense/filters.hpp"
#include "random_images.hpp"
#include "reference.hpp"

#include <gtest/gtest.h>

#include <random>
#include <string>
#include <utility>
#include <vector>

namespace hrcsense {
namespace {

using test::kFactor;
using test::random_depth;
using test::random_disparity;
using test::same_bits;

// Sizes around the widths of SSE2 and AVX2 vectors (4/8 floats, 8/16 uint16), of the row
// strips and of hole filling's 64-pixel words and 2048-pixel segments (150, 2200 wide).
const std::vector<std::pair<int, int>> kSizes{{1, 1},   {2, 1},   {1, 9},   {3, 2},   {5, 8},   {8, 8},
                                              {9, 16},  {15, 17}, {16, 7},  {17, 24}, {31, 33}, {64, 40},
                                              {83, 19}, {150, 6}, {2200, 3}};

// Every test here runs twice: forced onto the portable (SSE2) loops, and with the best the CPU
// has (AVX2 where present), so both paths are checked against the same references.
class IsaTest : public ::testing::TestWithParam<FilterIsa> {
 protected:
  void SetUp() override { set_filter_isa(GetParam()); }
  void TearDown() override { set_filter_isa(FilterIsa::best); }
};
using SpatialFast = IsaTest;
using TemporalFast = IsaTest;
using BlocksFast = IsaTest;
using Properties = IsaTest;

std::string isa_label(const ::testing::TestParamInfo<FilterIsa>& info) {
  return info.param == FilterIsa::portable ? "portable" : "best";
}

const auto kBothIsas = ::testing::Values(FilterIsa::portable, FilterIsa::best);
INSTANTIATE_TEST_SUITE_P(Isa, SpatialFast, kBothIsas, isa_label);
INSTANTIATE_TEST_SUITE_P(Isa, TemporalFast, kBothIsas, isa_label);
INSTANTIATE_TEST_SUITE_P(Isa, BlocksFast, kBothIsas, isa_label);
INSTANTIATE_TEST_SUITE_P(Isa, Properties, kBothIsas, isa_label);

// The hook really switches paths (else "both" would test one path twice).
TEST(FilterIsaHook, PortableForcesTheBaselineAndBestTakesAvx2WhereTheCpuHasIt) {
  set_filter_isa(FilterIsa::portable);
  const std::string portable = filter_isa_name();
  set_filter_isa(FilterIsa::best);
  const std::string best = filter_isa_name();
#if defined(__x86_64__)
  EXPECT_EQ(portable, "sse2");
  EXPECT_EQ(best, __builtin_cpu_supports("avx2") ? "avx2" : "sse2");
#else
  EXPECT_EQ(portable, "scalar");
  EXPECT_EQ(best, "scalar");
#endif
}

std::string describe(const SpatialParams& q, int w, int h) {
  return std::to_string(w) + "x" + std::to_string(h) + " alpha " + std::to_string(q.alpha) + " delta " +
         std::to_string(q.delta) + " magnitude " + std::to_string(q.magnitude) + " holes_fill " +
         std::to_string(q.holes_fill);
}

const SpatialParams kSpatialOptions[] = {{0.5F, 20, 2, 0}, {0.25F, 1, 1, 0}, {0.4F, 50, 5, 0}, {0.77F, 8, 3, 1},
                                         {0.5F, 20, 2, 2}, {0.33F, 30, 2, 3}, {0.6F, 20, 1, 4}, {0.5F, 45, 4, 5},
                                         {1.0F, 20, 2, 0}, {1.0F, 20, 2, 3}};

TEST_P(SpatialFast, DepthEqualsTheReferenceOnEverySizeAndOption) {
  std::mt19937 rng(101);
  for (const auto& [w, h] : kSizes) {
    for (const SpatialParams& q : kSpatialOptions) {
      const DepthImage in = random_depth(rng, w, h);
      DepthImage fast = in, plain = in;
      spatial_filter(q, fast);
      reference::spatial_depth(q, plain);
      ASSERT_EQ(fast.pixels, plain.pixels) << describe(q, w, h);
    }
  }
}

TEST_P(SpatialFast, DisparityEqualsTheReferenceOnEverySizeAndOption) {
  std::mt19937 rng(103);
  for (const auto& [w, h] : kSizes) {
    for (const SpatialParams& q : kSpatialOptions) {
      for (const bool special : {false, true}) {
        const DisparityImage in = random_disparity(rng, w, h, special);
        DisparityImage fast = in, plain = in;
        spatial_filter(q, fast);
        reference::spatial_disparity(q, plain);
        ASSERT_TRUE(same_bits(fast.pixels, plain.pixels)) << describe(q, w, h) << (special ? " special" : "");
      }
    }
  }
}

TEST_P(SpatialFast, AlphaOneWithoutHoleFillLeavesEverySizeUnchanged) {
  std::mt19937 rng(107);
  for (const auto& [w, h] : kSizes) {
    const DepthImage depth_in = random_depth(rng, w, h);
    DepthImage depth = depth_in;
    spatial_filter(SpatialParams{1.0F, 50, 5, 0}, depth);
    EXPECT_EQ(depth.pixels, depth_in.pixels) << w << "x" << h;
    const DisparityImage disparity_in = random_disparity(rng, w, h, false);
    DisparityImage disparity = disparity_in;
    spatial_filter(SpatialParams{1.0F, 50, 5, 0}, disparity);
    EXPECT_TRUE(same_bits(disparity.pixels, disparity_in.pixels)) << w << "x" << h;
  }
}

TEST_P(TemporalFast, EqualsTheReferenceOnEverySizePersistenceAndAlpha) {
  std::mt19937 rng(109);
  std::bernoulli_distribution burst(0.3);
  for (const auto& [w, h] : kSizes) {
    for (int persistence = 0; persistence <= 8; ++persistence) {
      for (const float alpha : {0.0F, 0.4F, 1.0F}) {
        const TemporalParams q{alpha, persistence % 2 == 0 ? 20 : 60, persistence};
        TemporalFilter depth_fast, disparity_fast;
        depth_fast.params = disparity_fast.params = q;
        reference::Temporal<uint16_t> depth_plain{q, {}, {}};
        reference::Temporal<float> disparity_plain{q, {}, {}};
        DepthImage frame = random_depth(rng, w, h);
        for (int t = 0; t < 20; ++t) {
          // Each pixel keeps or drops out in bursts, and its depth drifts (sometimes past δ).
          DepthImage next = random_depth(rng, w, h);
          for (size_t i = 0; i < frame.pixels.size(); ++i) {
            if (burst(rng)) frame.pixels[i] = next.pixels[i];
          }
          DisparityImage disparity;
          depth_to_disparity(frame, kFactor, disparity);
          DepthImage depth = frame;
          std::vector<uint16_t> depth_expected = frame.pixels;
          std::vector<float> disparity_expected = disparity.pixels;
          depth_fast.apply(depth);
          disparity_fast.apply(disparity);
          depth_plain.apply(depth_expected);
          disparity_plain.apply(disparity_expected);
          ASSERT_EQ(depth.pixels, depth_expected) << w << "x" << h << " persistence " << persistence << " t " << t;
          ASSERT_TRUE(same_bits(disparity.pixels, disparity_expected))
              << w << "x" << h << " persistence " << persistence << " t " << t;
        }
      }
    }
  }
}

// The plain references of the stateless blocks.
TEST_P(BlocksFast, ThresholdTransformsDecimationAndHoleFillingEqualTheReferences) {
  std::mt19937 rng(113);
  const ThresholdParams thresholds[] = {{0.1F, 4.0F}, {0.15F, 1.5F}, {0.0F, 16.0F}, {1.0F, 0.5F}, {0.8F, 0.8F}};
  for (const auto& [w, h] : kSizes) {
    const DepthImage in = random_depth(rng, w, h);
    for (const ThresholdParams& q : thresholds) {
      DepthImage fast = in;
      apply_threshold(q, fast);
      EXPECT_EQ(fast.pixels, reference::threshold(q, in).pixels) << w << "x" << h << " " << q.min_m << "-" << q.max_m;
    }
    DisparityImage disparity;
    depth_to_disparity(in, kFactor, disparity);
    EXPECT_TRUE(same_bits(disparity.pixels, reference::to_disparity(in, kFactor).pixels)) << w << "x" << h;
    const DisparityImage special = random_disparity(rng, w, h, true);
    DepthImage depth;
    disparity_to_depth(special, kFactor, depth);
    EXPECT_EQ(depth.pixels, reference::to_depth(special, kFactor).pixels) << w << "x" << h;
    for (int magnitude = 1; magnitude <= 8; ++magnitude) {
      DepthImage out;
      Intrinsics intrinsics, out_intrinsics;
      decimate(DecimationParams{magnitude}, in, intrinsics, out, out_intrinsics);
      const DepthImage expected = reference::decimate(magnitude, in);
      EXPECT_EQ(out.width, expected.width);
      EXPECT_EQ(out.pixels, expected.pixels) << w << "x" << h << " magnitude " << magnitude;
    }
    for (int mode = 0; mode <= 2; ++mode) {
      DepthImage fast = in;
      fill_holes(HoleFillingParams{mode}, fast);
      EXPECT_EQ(fast.pixels, reference::fill_holes(mode, in).pixels) << w << "x" << h << " mode " << mode;
      DisparityImage fast_disparity = special;
      fill_holes(HoleFillingParams{mode}, fast_disparity);
      EXPECT_TRUE(same_bits(fast_disparity.pixels, reference::fill_holes(mode, special).pixels))
          << w << "x" << h << " mode " << mode;
    }
  }
}

// Every block but threshold keeps valid pixels valid, except where the spec says otherwise
// (spatial on depth, below). Decimation: an output pixel is valid when its block holds a valid
// pixel; to_depth: on disparities that came from depth, where rounding gives the depth back.
TEST_P(Properties, NoFilterButThresholdInvalidatesAValidPixel) {
  std::mt19937 rng(127);
  for (const auto& [w, h] : kSizes) {
    const DepthImage in = random_depth(rng, w, h);
    const auto kept = [&](const std::vector<uint16_t>& out, const std::string& what, int min_raw = 1) {
      for (size_t i = 0; i < in.pixels.size(); ++i) {
        if (in.pixels[i] >= min_raw) {
          ASSERT_NE(out[i], 0) << what << " " << w << "x" << h << " pixel " << i;
        }
      }
    };
    DisparityImage disparity;
    depth_to_disparity(in, kFactor, disparity);
    DepthImage back;
    disparity_to_depth(disparity, kFactor, back);
    kept(back.pixels, "to_disparity, to_depth");
    for (int mode = 0; mode <= 2; ++mode) {
      DepthImage filled = in;
      fill_holes(HoleFillingParams{mode}, filled);
      kept(filled.pixels, "hole_filling");
      DisparityImage filled_disparity = disparity;
      fill_holes(HoleFillingParams{mode}, filled_disparity);
      disparity_to_depth(filled_disparity, kFactor, back);
      kept(back.pixels, "hole_filling (disparity)");
    }
    for (const SpatialParams& q : kSpatialOptions) {
      DepthImage depth = in;
      spatial_filter(q, depth);
      // Spec §5b: the depth path's top→bottom pass has no validity check, so a raw value below
      // δ next to a hole is blended with 0 and may round to 0 (never in D435 data: < 20 mm).
      kept(depth.pixels, "spatial " + describe(q, w, h), q.delta);
      DisparityImage smoothed = disparity;
      spatial_filter(q, smoothed);
      disparity_to_depth(smoothed, kFactor, back);
      kept(back.pixels, "spatial (disparity) " + describe(q, w, h));
    }
    for (int persistence = 0; persistence <= 8; ++persistence) {
      TemporalFilter temporal;
      temporal.params.persistence = persistence;
      for (int t = 0; t < 3; ++t) {
        DepthImage depth = in;
        temporal.apply(depth);
        kept(depth.pixels, "temporal");
      }
    }
    for (int magnitude = 1; magnitude <= 8; ++magnitude) {
      DepthImage out;
      Intrinsics intrinsics, out_intrinsics;
      decimate(DecimationParams{magnitude}, in, intrinsics, out, out_intrinsics);
      for (int j = 0; j < h / magnitude; ++j) {
        for (int i = 0; i < w / magnitude; ++i) {
          bool any = false;
          for (int y = j * magnitude; y < (j + 1) * magnitude; ++y)
            for (int x = i * magnitude; x < (i + 1) * magnitude; ++x) any |= in.pixels[static_cast<size_t>(y) * w + x] != 0;
          EXPECT_EQ(out.pixels[static_cast<size_t>(j) * out.width + i] != 0, any) << "decimation " << magnitude;
        }
      }
    }
  }
}

// Each row's data moved by k elements within the image: k empty columns on the left shift every
// row across the SIMD lanes and strip blocks (the base address itself: tests/filters_alignment/).
// Empty columns are inert in every block (without hole filling, which would fill them), so the
// rest of the output must not change.
template <typename Image>
Image shifted(const Image& in, int k) {
  Image out;
  out.resize(in.width + k, in.height);
  std::fill(out.pixels.begin(), out.pixels.end(), typename decltype(out.pixels)::value_type{0});
  for (int v = 0; v < in.height; ++v)
    for (int u = 0; u < in.width; ++u)
      out.pixels[static_cast<size_t>(v) * out.width + u + k] = in.pixels[static_cast<size_t>(v) * in.width + u];
  return out;
}

template <typename Image>
Image unshifted(const Image& in, int k) {
  Image out;
  out.resize(in.width - k, in.height);
  for (int v = 0; v < in.height; ++v)
    for (int u = 0; u < out.width; ++u)
      out.pixels[static_cast<size_t>(v) * out.width + u] = in.pixels[static_cast<size_t>(v) * in.width + u + k];
  return out;
}

TEST_P(Properties, OutputDoesNotDependOnMemoryAlignment) {
  std::mt19937 rng(131);
  const SpatialParams spatial{0.45F, 25, 3, 0};
  for (const auto& [w, h] : {std::pair{29, 18}, std::pair{64, 17}}) {
    const DepthImage in = random_depth(rng, w, h);
    DisparityImage disparity_in;
    depth_to_disparity(in, kFactor, disparity_in);
    DepthImage depth0 = in;
    spatial_filter(spatial, depth0);
    DisparityImage disparity0 = disparity_in;
    spatial_filter(spatial, disparity0);
    DepthImage threshold0 = in;
    apply_threshold(ThresholdParams{0.9F, 2.0F}, threshold0);
    DepthImage back0;
    disparity_to_depth(disparity0, kFactor, back0);
    std::vector<uint16_t> temporal0;
    TemporalFilter temporal;
    for (int t = 0; t < 3; ++t) {
      DepthImage frame = t == 1 ? threshold0 : in;
      temporal.apply(frame);
      temporal0 = frame.pixels;
    }
    for (int k = 1; k <= 9; ++k) {
      const std::string at = std::to_string(w) + "x" + std::to_string(h) + " shifted by " + std::to_string(k);
      DepthImage depth = shifted(in, k);
      spatial_filter(spatial, depth);
      EXPECT_EQ(unshifted(depth, k).pixels, depth0.pixels) << "spatial depth " << at;
      DisparityImage disparity = shifted(disparity_in, k);
      spatial_filter(spatial, disparity);
      EXPECT_TRUE(same_bits(unshifted(disparity, k).pixels, disparity0.pixels)) << "spatial disparity " << at;
      DepthImage threshold = shifted(in, k);
      apply_threshold(ThresholdParams{0.9F, 2.0F}, threshold);
      EXPECT_EQ(unshifted(threshold, k).pixels, threshold0.pixels) << "threshold " << at;
      DisparityImage converted;
      depth_to_disparity(shifted(in, k), kFactor, converted);
      EXPECT_TRUE(same_bits(unshifted(converted, k).pixels, disparity_in.pixels)) << "to_disparity " << at;
      DepthImage back;
      disparity_to_depth(shifted(disparity0, k), kFactor, back);
      EXPECT_EQ(unshifted(back, k).pixels, back0.pixels) << "to_depth " << at;
      TemporalFilter shifted_temporal;
      DepthImage frame;
      for (int t = 0; t < 3; ++t) {
        frame = shifted(t == 1 ? threshold0 : in, k);
        shifted_temporal.apply(frame);
      }
      EXPECT_EQ(unshifted(frame, k).pixels, temporal0) << "temporal " << at;
    }
  }
}

// Scratch buffers are reused between calls and sizes; they must carry nothing over.
TEST_P(Properties, RunningTwiceWithResetStateGivesIdenticalOutput) {
  std::mt19937 rng(137);
  const DepthImage a = random_depth(rng, 83, 41);
  const DepthImage b = random_depth(rng, 120, 9);
  const SpatialParams q{0.5F, 20, 2, 3};
  // One scratch through calls of different sizes, as the chain reuses it; nothing may leak
  // from one call into the next, so the result also equals a fresh scratch's.
  SpatialScratch scratch;
  DepthImage first = a;
  spatial_filter(q, first, scratch);
  DepthImage other = b;
  spatial_filter(q, other, scratch);
  DepthImage second = a;
  spatial_filter(q, second, scratch);
  EXPECT_EQ(first.pixels, second.pixels);
  DepthImage fresh = a;
  spatial_filter(q, fresh);
  EXPECT_EQ(fresh.pixels, second.pixels);
  DisparityImage d_first, d_other, d_second;
  depth_to_disparity(a, kFactor, d_first);
  depth_to_disparity(b, kFactor, d_other);
  d_second = d_first;
  DisparityImage d_fresh = d_first;
  spatial_filter(q, d_first, scratch);
  spatial_filter(q, d_other, scratch);
  spatial_filter(q, d_second, scratch);
  spatial_filter(q, d_fresh);
  EXPECT_TRUE(same_bits(d_first.pixels, d_second.pixels));
  EXPECT_TRUE(same_bits(d_fresh.pixels, d_second.pixels));

  TemporalFilter temporal;
  std::vector<std::vector<uint16_t>> outputs;
  for (int pass = 0; pass < 2; ++pass) {
    temporal.reset();
    std::mt19937 sequence(139);
    for (int t = 0; t < 10; ++t) {
      DepthImage frame = random_depth(sequence, 83, 41);
      temporal.apply(frame);
      if (pass == 0) {
        outputs.push_back(frame.pixels);
      } else {
        EXPECT_EQ(frame.pixels, outputs[static_cast<size_t>(t)]) << "frame " << t;
      }
    }
  }
}

}  // namespace
}  // namespace hrcsense

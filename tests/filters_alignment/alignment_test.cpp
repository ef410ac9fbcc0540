// SPDX-License-Identifier: Apache-2.0
// Every filter block gives the same bits whatever the address its buffers start at: each input
// and output image (and the spatial scratch, and the temporal state) is moved to every offset
// from a 64-byte boundary in steps of its element size, and the result is compared with the
// same block on ordinarily allocated buffers. Runs on the portable and the AVX2 loops.
//
// How the buffers are moved: DepthImage and DisparityImage own their pixels in a std::vector
// with the default allocator, so the API takes no outside or offset buffer, and glibc's malloc
// only ever returns 16-byte aligned blocks. This executable therefore replaces the global
// operator new: while a `Placement` is alive, every allocation starts `offset` bytes past a
// 64-byte boundary and ends where its block ends (so AddressSanitizer still sees an overrun);
// operator delete finds such blocks in a small table. Offsets are multiples of the element
// size, so every uint16_t and float stays naturally aligned; only the vector-width alignment
// varies. Outside a Placement allocation is plain malloc/free.
//
// A replaced operator new holds for the whole executable, so this file is a family of its own
// (test_filters_alignment, as tests/alloc/ is for the counting allocator) and holds no other
// tests: in test_filters it would sit under every filter test. It compares the filters with
// themselves, never with a float reference of its own, so it needs test_filters'
// -ffp-contract=off no more than the filters library gives it.
#include "hrcsense/filters.hpp"
#include "../filters/random_images.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace {

constexpr size_t kBoundary = 64;  // a cache line; covers the 16- and 32-byte vector widths

struct PlacedBlock {
  std::atomic<char*> data{nullptr};  // what operator new returned; nullptr: free entry
  size_t offset = 0;                 // data - offset is the block to free
};
std::array<PlacedBlock, 32> g_placed;  // live placed blocks (a test holds a handful at a time)
std::atomic<int> g_placed_live{0};
std::atomic<long> g_offset{-1};  // the offset of new allocations; -1: plain malloc

}  // namespace

#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  const long offset = g_offset.load(std::memory_order_relaxed);
  if (offset < 0) {
    if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
    throw std::bad_alloc();
  }
  void* block = nullptr;
  if (posix_memalign(&block, kBoundary, static_cast<size_t>(offset) + std::max<size_t>(size, 1)) != 0) {
    throw std::bad_alloc();
  }
  char* data = static_cast<char*>(block) + offset;
  for (PlacedBlock& entry : g_placed) {
    char* free_entry = nullptr;
    if (entry.data.compare_exchange_strong(free_entry, data)) {
      entry.offset = static_cast<size_t>(offset);
      ++g_placed_live;
      return data;
    }
  }
  std::free(block);
  throw std::bad_alloc();  // more live placed blocks than the table holds: a bug in this test
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* p) noexcept {
  if (p != nullptr && g_placed_live.load() > 0) {
    for (PlacedBlock& entry : g_placed) {
      if (entry.data.load() == p) {
        std::free(static_cast<char*>(p) - entry.offset);
        entry.data.store(nullptr);
        --g_placed_live;
        return;
      }
    }
  }
  std::free(p);
}
void operator delete[](void* p) noexcept { operator delete(p); }
void operator delete(void* p, std::size_t) noexcept { operator delete(p); }
void operator delete[](void* p, std::size_t) noexcept { operator delete(p); }

namespace hrcsense {
namespace {

using test::kFactor;
using test::random_depth;
using test::random_disparity;
using test::same_bits;

// Allocations made while one is alive start `offset` bytes past a 64-byte boundary.
class Placement {
 public:
  explicit Placement(size_t offset) { g_offset.store(static_cast<long>(offset)); }
  ~Placement() { g_offset.store(-1); }
  Placement(const Placement&) = delete;
  Placement& operator=(const Placement&) = delete;
};

size_t offset_of(const void* p) { return reinterpret_cast<uintptr_t>(p) % kBoundary; }

// Replaces `buffer` by one of `size` elements (zeros) whose data starts at `offset`.
template <typename T>
void place(std::vector<T>& buffer, size_t size, size_t offset) {
  std::vector<T> placed;
  {
    const Placement at(offset);
    placed.reserve(size);  // the one allocation
  }
  placed.resize(size);  // within the capacity: no reallocation
  buffer.swap(placed);
}

// A copy of `in` whose pixels start at `offset`.
template <typename Image>
Image placed_copy(const Image& in, size_t offset) {
  Image out = in;
  place(out.pixels, in.pixels.size(), offset);
  std::copy(in.pixels.begin(), in.pixels.end(), out.pixels.begin());
  return out;
}

// An output image of `width` x `height` whose pixels start at `offset`; the block's resize()
// keeps the buffer (same size), which the tests check.
template <typename Image>
Image placed_output(int width, int height, size_t offset) {
  Image out;
  place(out.pixels, static_cast<size_t>(width) * height, offset);
  out.width = width;
  out.height = height;
  return out;
}

// A spatial scratch at `offset`. The sizes are above what spatial_filter asks for (a strip of
// 16 rows, one line); it keeps buffers that are large enough, which the tests check, so if it
// ever needs more the check says to make these bigger.
SpatialScratch placed_scratch(int width, size_t offset) {
  const size_t w = static_cast<size_t>(width);
  SpatialScratch s;
  place(s.depth_strip, 64 * w + 64, offset);
  place(s.depth_fill, w + 64, offset);
  place(s.disparity_strip, 64 * w + 64, offset / 4 * 4);
  place(s.disparity_line, w + 64, offset / 4 * 4);
  return s;
}

bool same_scratch(const SpatialScratch& a, const std::array<const void*, 4>& data) {
  return a.depth_strip.data() == data[0] && a.depth_fill.data() == data[1] && a.disparity_strip.data() == data[2] &&
         a.disparity_line.data() == data[3];
}

std::array<const void*, 4> scratch_data(const SpatialScratch& s) {
  return {s.depth_strip.data(), s.depth_fill.data(), s.disparity_strip.data(), s.disparity_line.data()};
}

class BaseAddress : public ::testing::TestWithParam<FilterIsa> {
 protected:
  void SetUp() override { set_filter_isa(GetParam()); }
  void TearDown() override { set_filter_isa(FilterIsa::best); }
};
INSTANTIATE_TEST_SUITE_P(Isa, BaseAddress, ::testing::Values(FilterIsa::portable, FilterIsa::best),
                         [](const ::testing::TestParamInfo<FilterIsa>& info) {
                           return info.param == FilterIsa::portable ? "portable" : "best";
                         });

// Widths that end rows inside a vector (29, 83), on a vector boundary (64) and past hole
// filling's 64-pixel words (150); heights below, at and above the 16-row strip.
const std::pair<int, int> kSizes[] = {{29, 18}, {64, 17}, {83, 5}, {150, 33}};

// Offsets of a buffer of `element`-byte values: 0, element, ..., kBoundary − element.
std::vector<size_t> offsets(size_t element) {
  std::vector<size_t> all;
  for (size_t offset = 0; offset < kBoundary; offset += element) all.push_back(offset);
  return all;
}

TEST(BaseAddressHook, PlacesBuffersAtTheAskedOffset) {
  for (const size_t offset : offsets(2)) {
    DepthImage d;
    d.resize(7, 3);
    const DepthImage placed = placed_copy(d, offset);
    EXPECT_EQ(offset_of(placed.pixels.data()), offset);
  }
  std::vector<float> plain(100);  // outside a Placement: malloc's usual 16-byte alignment
  EXPECT_EQ(offset_of(plain.data()) % 16, 0U);
}

TEST_P(BaseAddress, PointwiseBlocksAndDecimation) {
  std::mt19937 rng(151);
  for (const auto& [w, h] : kSizes) {
    const DepthImage in = random_depth(rng, w, h);
    const DisparityImage disparity_in = random_disparity(rng, w, h, true);
    const ThresholdParams threshold{0.9F, 2.0F};
    DepthImage threshold0 = in;
    apply_threshold(threshold, threshold0);
    DisparityImage disparity0;
    depth_to_disparity(in, kFactor, disparity0);
    DepthImage depth0;
    disparity_to_depth(disparity_in, kFactor, depth0);
    std::vector<DepthImage> decimated0(9);
    const Intrinsics intrinsics{};
    for (int magnitude = 1; magnitude <= 8; ++magnitude) {
      Intrinsics unused;
      decimate(DecimationParams{magnitude}, in, intrinsics, decimated0[static_cast<size_t>(magnitude)], unused);
    }
    for (const size_t offset : offsets(2)) {
      const std::string at = std::to_string(w) + "x" + std::to_string(h) + " at offset " + std::to_string(offset);
      DepthImage thresholded = placed_copy(in, offset);
      apply_threshold(threshold, thresholded);
      EXPECT_EQ(thresholded.pixels, threshold0.pixels) << "threshold " << at;

      const DepthImage source = placed_copy(in, offset);
      for (int magnitude = 1; magnitude <= 8; ++magnitude) {
        const DepthImage& expected = decimated0[static_cast<size_t>(magnitude)];
        DepthImage out = placed_output<DepthImage>(expected.width, expected.height, (offset * 7) % kBoundary);
        const uint16_t* data = out.pixels.data();
        Intrinsics unused;
        decimate(DecimationParams{magnitude}, source, intrinsics, out, unused);
        ASSERT_EQ(out.pixels.data(), data) << "decimation reallocated its output, " << at;
        EXPECT_EQ(out.pixels, expected.pixels) << "decimation " << magnitude << " " << at;
      }
      if (offset % 4 != 0) continue;  // float buffers: 4-byte steps
      DisparityImage converted = placed_output<DisparityImage>(w, h, offset);
      const float* converted_data = converted.pixels.data();
      depth_to_disparity(source, kFactor, converted);
      ASSERT_EQ(converted.pixels.data(), converted_data) << at;
      EXPECT_TRUE(same_bits(converted.pixels, disparity0.pixels)) << "to_disparity " << at;
      DepthImage back = placed_output<DepthImage>(w, h, (offset + 2) % kBoundary);
      const uint16_t* back_data = back.pixels.data();
      disparity_to_depth(placed_copy(disparity_in, offset), kFactor, back);
      ASSERT_EQ(back.pixels.data(), back_data) << at;
      EXPECT_EQ(back.pixels, depth0.pixels) << "to_depth " << at;
    }
  }
}

TEST_P(BaseAddress, HoleFilling) {
  std::mt19937 rng(157);
  for (const auto& [w, h] : kSizes) {
    const DepthImage in = random_depth(rng, w, h);
    const DisparityImage disparity_in = random_disparity(rng, w, h, true);
    for (int mode = 0; mode <= 2; ++mode) {
      DepthImage depth0 = in;
      fill_holes(HoleFillingParams{mode}, depth0);
      DisparityImage disparity0 = disparity_in;
      fill_holes(HoleFillingParams{mode}, disparity0);
      for (const size_t offset : offsets(2)) {
        const std::string at = std::to_string(w) + "x" + std::to_string(h) + " mode " + std::to_string(mode) +
                               " at offset " + std::to_string(offset);
        DepthImage depth = placed_copy(in, offset);
        fill_holes(HoleFillingParams{mode}, depth);
        EXPECT_EQ(depth.pixels, depth0.pixels) << "depth " << at;
        if (offset % 4 != 0) continue;
        DisparityImage disparity = placed_copy(disparity_in, offset);
        fill_holes(HoleFillingParams{mode}, disparity);
        EXPECT_TRUE(same_bits(disparity.pixels, disparity0.pixels)) << "disparity " << at;
      }
    }
  }
}

// Every holes_fill mode, in both domains, with the scratch placed too (at another offset).
TEST_P(BaseAddress, Spatial) {
  std::mt19937 rng(163);
  const SpatialParams options[] = {{0.5F, 20, 2, 0}, {0.25F, 1, 1, 1}, {0.45F, 25, 3, 2},
                                   {0.6F, 20, 1, 3}, {0.5F, 45, 4, 4}, {0.33F, 30, 2, 5}};
  for (const auto& [w, h] : kSizes) {
    const DepthImage in = random_depth(rng, w, h);
    const DisparityImage disparity_in = random_disparity(rng, w, h, true);
    for (const SpatialParams& q : options) {
      DepthImage depth0 = in;
      spatial_filter(q, depth0);
      DisparityImage disparity0 = disparity_in;
      spatial_filter(q, disparity0);
      for (const size_t offset : offsets(2)) {
        const std::string at = std::to_string(w) + "x" + std::to_string(h) + " holes_fill " +
                               std::to_string(q.holes_fill) + " at offset " + std::to_string(offset);
        SpatialScratch scratch = placed_scratch(w, (kBoundary - offset) % kBoundary);
        const std::array<const void*, 4> scratch_at = scratch_data(scratch);
        DepthImage depth = placed_copy(in, offset);
        spatial_filter(q, depth, scratch);
        EXPECT_EQ(depth.pixels, depth0.pixels) << "depth " << at;
        if (offset % 4 == 0) {
          DisparityImage disparity = placed_copy(disparity_in, offset);
          spatial_filter(q, disparity, scratch);
          EXPECT_TRUE(same_bits(disparity.pixels, disparity0.pixels)) << "disparity " << at;
        }
        ASSERT_TRUE(same_scratch(scratch, scratch_at)) << "spatial_filter grew the scratch; place a larger one";
      }
    }
  }
}

// A sequence of frames at one offset; the first apply() allocates the stored values and the
// history, inside a Placement, so they sit at the offset too.
TEST_P(BaseAddress, Temporal) {
  std::mt19937 rng(167);
  for (const auto& [w, h] : kSizes) {
    std::vector<DepthImage> frames;
    for (int t = 0; t < 6; ++t) frames.push_back(random_depth(rng, w, h));
    std::fill(frames[3].pixels.begin(), frames[3].pixels.end(), uint16_t{0});  // an all-hole frame: persistence fills
    std::vector<DisparityImage> disparities(frames.size());
    for (size_t t = 0; t < frames.size(); ++t) depth_to_disparity(frames[t], kFactor, disparities[t]);
    for (const int persistence : {3, 8}) {
      const TemporalParams q{0.4F, 20, persistence};
      TemporalFilter depth_filter, disparity_filter;
      depth_filter.params = disparity_filter.params = q;
      std::vector<std::vector<uint16_t>> depth0;
      std::vector<std::vector<float>> disparity0;
      for (size_t t = 0; t < frames.size(); ++t) {
        DepthImage depth = frames[t];
        depth_filter.apply(depth);
        depth0.push_back(depth.pixels);
        DisparityImage disparity = disparities[t];
        disparity_filter.apply(disparity);
        disparity0.push_back(disparity.pixels);
      }
      for (const size_t offset : offsets(2)) {
        const std::string at = std::to_string(w) + "x" + std::to_string(h) + " persistence " +
                               std::to_string(persistence) + " at offset " + std::to_string(offset);
        TemporalFilter depth_placed, disparity_placed;
        depth_placed.params = disparity_placed.params = q;
        for (size_t t = 0; t < frames.size(); ++t) {
          DepthImage depth = placed_copy(frames[t], offset);
          if (t == 0) {
            const int live = g_placed_live.load();
            const Placement state_at((offset + 6) % kBoundary);
            depth_placed.apply(depth);
            ASSERT_GT(g_placed_live.load(), live) << "the first apply() allocated no state to place";
          } else {
            depth_placed.apply(depth);
          }
          EXPECT_EQ(depth.pixels, depth0[t]) << "depth frame " << t << " " << at;
          if (offset % 4 != 0) continue;
          DisparityImage disparity = placed_copy(disparities[t], offset);
          if (t == 0) {
            const int live = g_placed_live.load();
            const Placement state_at((offset + 8) % kBoundary);
            disparity_placed.apply(disparity);
            ASSERT_GT(g_placed_live.load(), live) << "the first apply() allocated no state to place";
          } else {
            disparity_placed.apply(disparity);
          }
          EXPECT_TRUE(same_bits(disparity.pixels, disparity0[t])) << "disparity frame " << t << " " << at;
        }
      }
    }
  }
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// hrcsense — unknown space, one ray segment against the spheres around every capsule at once
// (internal to src/pipeline/unknown_space.cpp; tests/pipeline checks the SSE2 variant against
// the plain one and against the geometry in double).
//
// A ray that comes near the arm was tested against each capsule's sphere in turn, a call and
// a branch per capsule; the spheres are laid out by coordinate (x[], y[], z[], radius[]) so
// that SSE2 tests four of them with the same few instructions and one mask says which are near.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace hrcsense::unknown_space_detail {

inline constexpr int kMaxSpheres = 32;  // one bit each in a uint32_t mask

/// Spheres, their centres relative to the camera's centre (base frame). Lanes from `count` up
/// to the next multiple of four are zero and never reported.
struct SphereLanes {
  alignas(16) std::array<float, kMaxSpheres> x{}, y{}, z{}, radius_m{};
  int count = 0;
};

/// The segment camera + t·direction, t ∈ [z0_m, z1_m] (direction: the pixel's ray scaled so
/// that t is the depth along the camera's z axis); inv_direction_sq = 1 / |direction|².
struct RaySpan {
  float dx = 0.0F, dy = 0.0F, dz = 0.0F;
  float inv_direction_sq = 1.0F;
  float z0_m = 0.0F, z1_m = 0.0F;
};

/// The spheres [0, count) as a bit mask.
inline uint32_t sphere_bits(int count) { return count >= 32 ? ~0U : (1U << count) - 1U; }

/// Of the spheres in `candidates` (bit c: sphere c), those the segment does not stay farther
/// than reach_m from, judged at its point nearest the centre (the projection clamped to
/// [z0, z1], as std::clamp: NaN stays NaN). NaN anywhere keeps the sphere: it is never skipped.
inline uint32_t spheres_within_plain(const SphereLanes& s, const RaySpan& r, float reach_m, uint32_t candidates) {
  uint32_t within = 0;
  for (int c = 0; c < s.count; ++c) {
    if ((candidates >> c & 1U) == 0) continue;
    const size_t i = static_cast<size_t>(c);
    const float along = (s.x[i] * r.dx + s.y[i] * r.dy) + s.z[i] * r.dz;
    float t = along * r.inv_direction_sq;
    t = r.z0_m > t ? r.z0_m : t;  // the operand order of SSE2's max and min, so NaN stays
    t = r.z1_m < t ? r.z1_m : t;
    const float ex = s.x[i] - t * r.dx, ey = s.y[i] - t * r.dy, ez = s.z[i] - t * r.dz;
    const float limit_m = s.radius_m[i] + reach_m;
    if (!((ex * ex + ey * ey) + ez * ez > limit_m * limit_m)) within |= 1U << c;
  }
  return within;
}

#if defined(__SSE2__)
/// The same bits, four spheres per step; a step without a candidate is left out (a ray is
/// tested against the few capsules near its block only).
inline uint32_t spheres_within_sse2(const SphereLanes& s, const RaySpan& r, float reach_m, uint32_t candidates) {
  const __m128 dx = _mm_set1_ps(r.dx), dy = _mm_set1_ps(r.dy), dz = _mm_set1_ps(r.dz);
  const __m128 inv_sq = _mm_set1_ps(r.inv_direction_sq), z0 = _mm_set1_ps(r.z0_m), z1 = _mm_set1_ps(r.z1_m);
  const __m128 reach = _mm_set1_ps(reach_m);
  uint32_t beyond = 0;
  for (int c = 0; c < s.count; c += 4) {
    if ((candidates >> c & 0xFU) == 0) continue;
    const size_t i = static_cast<size_t>(c);
    const __m128 x = _mm_load_ps(&s.x[i]), y = _mm_load_ps(&s.y[i]), z = _mm_load_ps(&s.z[i]);
    const __m128 along = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, dx), _mm_mul_ps(y, dy)), _mm_mul_ps(z, dz));
    const __m128 t = _mm_min_ps(z1, _mm_max_ps(z0, _mm_mul_ps(along, inv_sq)));
    const __m128 ex = _mm_sub_ps(x, _mm_mul_ps(t, dx)), ey = _mm_sub_ps(y, _mm_mul_ps(t, dy));
    const __m128 ez = _mm_sub_ps(z, _mm_mul_ps(t, dz));
    const __m128 sq = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ex), _mm_mul_ps(ey, ey)), _mm_mul_ps(ez, ez));
    const __m128 limit = _mm_add_ps(_mm_load_ps(&s.radius_m[i]), reach);
    beyond |= static_cast<uint32_t>(_mm_movemask_ps(_mm_cmpgt_ps(sq, _mm_mul_ps(limit, limit)))) << c;
  }
  return ~beyond & candidates & sphere_bits(s.count);
}
#endif

/// spheres_within with SSE2 where the compiler targets it.
inline uint32_t spheres_within(const SphereLanes& s, const RaySpan& r, float reach_m, uint32_t candidates) {
#if defined(__SSE2__)
  return spheres_within_sse2(s, r, reach_m, candidates);
#else
  return spheres_within_plain(s, r, reach_m, candidates);
#endif
}

}  // namespace hrcsense::unknown_space_detail

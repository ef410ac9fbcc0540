// SPDX-License-Identifier: Apache-2.0
// hrcsense — exact closest contact by brute force: a vectorised scan over blocks of the SoA
// cloud, skipping (block, capsule) pairs whose box lower bound cannot reach the best so far.

#include "brute.hpp"

#include "hrcsense/proximity.hpp"

#include <algorithm>
#include <cmath>

namespace hrcsense {
namespace proximity_detail {
namespace {

// Points per block: small enough that a block's coordinates stay in L1 across the capsules
// and its box is tight (a block of a depth image's foreground spans one or two image rows),
// large enough that the per-block box and bound cost little per point.
constexpr size_t kBlock = 512;
// Clouds from this size on are split between two threads when params.threads is 2: below it
// the hand-over costs more than the half scan saves (measured: 10^5 points took 76 us on two
// threads against 31 us on one; 10^6 points 269 us against 435 us; docs/PROXIMITY.md).
constexpr size_t kTwoThreadMinPoints = size_t{1} << 18;

struct Cloud {
  const float* x;
  const float* y;
  const float* z;
  size_t n;
};

// A true upper bound on the minimum: the best distance of a sparse sample of actual points.
// Seeding the scan with it lets the box bounds prune from the first block on.
float sampled_upper_bound_m(const Cloud& cloud, const std::vector<CapsuleBound>& capsules) {
  constexpr size_t kSamples = 256;
  const size_t stride = std::max<size_t>(1, cloud.n / kSamples);
  float best = kInf;
  for (size_t i = 0; i < cloud.n; i += stride) {
    for (const CapsuleBound& c : capsules) {
      const float d = surface_distance(c.segment, axis_distance_sq(c.segment, cloud.x[i], cloud.y[i], cloud.z[i]));
      best = d < best ? d : best;
    }
  }
  return best;
}

}  // namespace

BlockResult scan_blocks(const float* x, const float* y, const float* z, size_t n,
                        const std::vector<CapsuleBound>& capsules, size_t first_block, size_t last_block,
                        float upper_bound_m) {
  BlockResult result{upper_bound_m, kNoBlock};
  const bool prune = capsules.size() > 1;
  for (size_t b = first_block; b < last_block; ++b) {
    const size_t begin = b * kBlock;
    const size_t count = std::min(n, begin + kBlock) - begin;
    const float* bx = x + begin;
    const float* by = y + begin;
    const float* bz = z + begin;
    Box box;
    if (prune) box = bounding_box(bx, by, bz, count);
    for (const CapsuleBound& c : capsules) {
      if (prune && prunable(lower_bound_m(c, box), result.distance_m, c.segment.radius_m)) continue;
      const float d2 = min_axis_distance_sq(c.segment, bx, by, bz, count);
      if (!(d2 < kInf)) continue;  // no finite point
      const float m = surface_distance(c.segment, d2);
      // The first block reaching the final minimum holds its lowest point index.
      if (m < result.distance_m || (m == result.distance_m && result.block == kNoBlock)) {
        result = {m, b};
      }
    }
  }
  return result;
}

size_t block_count(size_t n) { return (n + kBlock - 1) / kBlock; }

Best resolve_block(const float* x, const float* y, const float* z, size_t n,
                   const std::vector<CapsuleBound>& capsules, const BlockResult& block) {
  Best best;
  const size_t begin = block.block * kBlock;
  const size_t end = std::min(n, begin + kBlock);
  for (size_t i = begin; i < end && !best.found(); ++i) {
    for (size_t c = 0; c < capsules.size(); ++c) {
      const Segment& s = capsules[c].segment;
      const float d = surface_distance(s, axis_distance_sq(s, x[i], y[i], z[i]));
      if (d == block.distance_m) {
        best = {d, i, c};
        break;
      }
    }
  }
  return best;
}

void prepare_bounds(const RobotModel& robot, std::vector<CapsuleBound>& out) {
  out.clear();
  for (const Capsule& capsule : robot.capsules) out.push_back(make_bound(capsule));
}

Best brute_search(const PointCloud& points_base, const std::vector<CapsuleBound>& capsules, Worker* worker) {
  const Cloud cloud{points_base.x.data(), points_base.y.data(), points_base.z.data(), points_base.size()};
  if (cloud.n == 0 || capsules.empty()) return {};
  const size_t blocks = block_count(cloud.n);
  const float upper_bound_m = capsules.size() > 1 && blocks > 8 ? sampled_upper_bound_m(cloud, capsules) : kInf;
  BlockResult result;
  if (worker != nullptr && cloud.n >= kTwoThreadMinPoints) {
    // The second thread takes the upper half of the blocks; on equal minima the lower half
    // wins, which keeps the lowest-index rule.
    const size_t half = blocks / 2;
    BlockResult upper;
    auto upper_half = [&] { upper = scan_blocks(cloud.x, cloud.y, cloud.z, cloud.n, capsules, half, blocks, upper_bound_m); };
    worker->run(upper_half);
    const BlockResult lower = scan_blocks(cloud.x, cloud.y, cloud.z, cloud.n, capsules, 0, half, upper_bound_m);
    worker->wait();
    const bool lower_wins = lower.block != kNoBlock &&
                            (upper.block == kNoBlock || lower.distance_m <= upper.distance_m);
    result = lower_wins ? lower : upper;
  } else {
    result = scan_blocks(cloud.x, cloud.y, cloud.z, cloud.n, capsules, 0, blocks, upper_bound_m);
  }
  if (result.block == kNoBlock) return {};  // no finite point
  return resolve_block(cloud.x, cloud.y, cloud.z, cloud.n, capsules, result);
}

Worker::Worker() : thread_([this] { loop(); }) {}

Worker::~Worker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quit_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void Worker::run_raw(void (*job)(void*), void* context) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    job_ = job;
    context_ = context;
    pending_ = true;
  }
  wake_.notify_one();
}

void Worker::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  done_.wait(lock, [this] { return !pending_; });
}

void Worker::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return pending_ || quit_; });
    if (quit_) return;
    lock.unlock();
    job_(context_);
    lock.lock();
    pending_ = false;
    done_.notify_one();
  }
}

}  // namespace proximity_detail

float point_capsule_distance(const Eigen::Vector3f& p, const Capsule& capsule,
                             Eigen::Vector3f* closest_on_capsule) {
  using namespace proximity_detail;
  const Segment s = make_segment(capsule);
  const float distance_m = surface_distance(s, axis_distance_sq(s, p.x(), p.y(), p.z()));
  if (closest_on_capsule != nullptr) {
    const Eigen::Vector3f ab = capsule.b - capsule.a;
    float t = (p - capsule.a).dot(ab) * s.inv_len2;
    t = std::clamp(t, 0.0F, 1.0F);
    const Eigen::Vector3f on_axis = capsule.a + t * ab;
    const Eigen::Vector3f out = p - on_axis;
    const float out_norm = out.norm();
    // Inside (or exactly on the axis of a zero-radius capsule): the point itself is the contact.
    if (distance_m <= 0.0F || out_norm <= 0.0F) {
      *closest_on_capsule = distance_m <= 0.0F ? p : on_axis;
    } else {
      *closest_on_capsule = on_axis + out * (capsule.radius_m / out_norm);
    }
  }
  return distance_m;
}

Contact closest_contact_brute(const PointCloud& points_base, const PointCloud& points_camera,
                              const RobotModel& robot) {
  std::vector<proximity_detail::CapsuleBound> capsules;
  proximity_detail::prepare_bounds(robot, capsules);
  const proximity_detail::Best best = proximity_detail::brute_search(points_base, capsules, nullptr);
  return proximity_detail::make_contact(best, points_base, points_camera, robot);
}

// The classic clamp-and-recompute construction (Ericson, Real-Time Collision Detection §5.1.9).
void closest_segment_params(const Eigen::Vector3f& p1, const Eigen::Vector3f& q1, const Eigen::Vector3f& p2,
                            const Eigen::Vector3f& q2, float& s, float& t) {
  const Eigen::Vector3f d1 = q1 - p1;
  const Eigen::Vector3f d2 = q2 - p2;
  const Eigen::Vector3f r = p1 - p2;
  const float a = d1.squaredNorm();
  const float e = d2.squaredNorm();
  const float f = d2.dot(r);
  if (a <= 0.0F && e <= 0.0F) {
    s = t = 0.0F;
    return;
  }
  if (a <= 0.0F) {
    s = 0.0F;
    t = std::clamp(f / e, 0.0F, 1.0F);
    return;
  }
  const float c = d1.dot(r);
  if (e <= 0.0F) {
    t = 0.0F;
    s = std::clamp(-c / a, 0.0F, 1.0F);
    return;
  }
  const float b = d1.dot(d2);
  const float denom = a * e - b * b;
  // Parallel segments (denom 0): any s works; 0 is then corrected by the clamps below.
  s = denom > 0.0F ? std::clamp((b * f - c * e) / denom, 0.0F, 1.0F) : 0.0F;
  t = (b * s + f) / e;
  if (t < 0.0F) {
    t = 0.0F;
    s = std::clamp(-c / a, 0.0F, 1.0F);
  } else if (t > 1.0F) {
    t = 1.0F;
    s = std::clamp((b - c) / a, 0.0F, 1.0F);
  }
}

}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// hrcsense proximity — the block scan behind the brute backend, and its optional second
// thread; internal to src/proximity/.
#pragma once

#include "capsule_math.hpp"

#include <condition_variable>
#include <cstddef>
#include <limits>
#include <mutex>
#include <thread>
#include <vector>

namespace hrcsense::proximity_detail {

inline constexpr size_t kNoBlock = std::numeric_limits<size_t>::max();

/// The smallest distance over a range of blocks and the first block that reaches it.
struct BlockResult {
  float distance_m = kInf;
  size_t block = kNoBlock;
};

/// One persistent helper thread for the two-thread brute scan. run() hands it a job and
/// returns at once; wait() blocks until the job is done. The job must outlive wait().
class Worker {
 public:
  Worker();
  ~Worker();
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  template <typename Job>
  void run(Job& job) {
    run_raw([](void* context) { (*static_cast<Job*>(context))(); }, &job);
  }
  void wait();

 private:
  void run_raw(void (*job)(void*), void* context);
  void loop();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  void (*job_)(void*) = nullptr;
  void* context_ = nullptr;
  bool pending_ = false;
  bool quit_ = false;
  std::thread thread_;  ///< last: starts after the fields above exist
};

/// The capsules of `robot` prepared for the scans, into `out` (capacity reused).
void prepare_bounds(const RobotModel& robot, std::vector<CapsuleBound>& out);

/// Scans blocks [first_block, last_block), each pruned against the running best, starting
/// from `upper_bound_m` (a distance some point is known to reach, or +inf).
BlockResult scan_blocks(const float* x, const float* y, const float* z, size_t n,
                        const std::vector<CapsuleBound>& capsules, size_t first_block, size_t last_block,
                        float upper_bound_m);

/// The lowest point (then capsule) index in `block.block` at exactly `block.distance_m`.
Best resolve_block(const float* x, const float* y, const float* z, size_t n,
                   const std::vector<CapsuleBound>& capsules, const BlockResult& block);

size_t block_count(size_t n);

/// The whole brute search; `worker` null for one thread.
Best brute_search(const PointCloud& points_base, const std::vector<CapsuleBound>& capsules, Worker* worker);

}  // namespace hrcsense::proximity_detail

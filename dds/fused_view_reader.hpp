// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — `hrcsense-view --fused`: reads a cell's cameras and its fused verdict off DDS
// into plain values (fused_view_types.hpp), so that the viewer never sees a DDS type.
#pragma once

#include "dds/fused_view_types.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace hrcsense::ros2 {

/// A camera the view expects (the cell configuration's `cameras:` entries).
struct FusedViewCamera {
  std::string name;
  Pose T_base_camera = Pose::Identity();
  Intrinsics intrinsics;  ///< where the configuration fixes them (simulated cameras); width 0: not known
};

struct FusedViewParams {
  uint32_t domain_id = 0;                    ///< `ros2.domain_id`
  std::string node_namespace = "/hrcsense";  ///< `ros2.namespace`
  std::vector<FusedViewCamera> cameras;
};

/// Subscribes to every configured camera's `<ns>/measurement/<NAME>`, `<ns>/<NAME>/foreground`
/// and `<ns>/<NAME>/depth_preview`, and to the fused `<ns>/verdict` (best-effort readers,
/// keep-last: they match reliable writers too, and a slow viewer reads the newest). Samples of
/// other cameras are never read (only configured names are subscribed). Not thread-safe: one
/// thread polls.
class FusedViewReader {
 public:
  explicit FusedViewReader(const FusedViewParams& params);  ///< throws Ros2Error
  ~FusedViewReader();
  FusedViewReader(const FusedViewReader&) = delete;
  FusedViewReader& operator=(const FusedViewReader&) = delete;

  /// Takes everything waiting (up to `timeout_ns` for the first sample) and returns the view:
  /// each camera's newest readable cloud, preview and measurement (a newer one replaces an older
  /// one; one that cannot be read is counted in `rejected`, its problem kept), the newest fused
  /// verdict stamped with the steady clock `steady_now_ns`.
  const FusedView& poll(int64_t timeout_ns, int64_t steady_now_ns);
  const FusedView& view() const { return view_; }
  /// Writers matched on each camera's measurement topic now.
  int32_t measurement_writers(size_t camera) const;

 private:
  struct Dds;
  std::unique_ptr<Dds> dds_;
  FusedView view_;
};

}  // namespace hrcsense::ros2

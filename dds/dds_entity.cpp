// SPDX-License-Identifier: Apache-2.0
// hrcsense dds — one participant per domain per process (dds_entity.hpp).
#include "dds/dds_entity.hpp"

#include <map>
#include <mutex>

namespace hrcsense::ros2 {

std::shared_ptr<const DdsEntity> domain_participant(uint32_t domain_id) {
  static std::mutex mutex;
  static std::map<uint32_t, std::weak_ptr<const DdsEntity>> participants;
  const std::lock_guard<std::mutex> lock(mutex);
  if (std::shared_ptr<const DdsEntity> alive = participants[domain_id].lock()) return alive;
  auto made = std::make_shared<const DdsEntity>(
      check_dds(dds_create_participant(domain_id, nullptr, nullptr), "DDS participant on domain " + std::to_string(domain_id)));
  participants[domain_id] = made;
  return made;
}

}  // namespace hrcsense::ros2

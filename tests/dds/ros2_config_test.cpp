// SPDX-License-Identifier: Apache-2.0
// The source.ros2.* and publish.* keys: defaults as docs/CONFIG.md says, bounds, ROS 2 names,
// and topics overridden one by one (make_source's mapping, through a source that cannot start).
#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

TEST(Ros2Config, DefaultsAreRealsenseRos4) {
  const Config c = load_config("", {});
  EXPECT_EQ(c.source.ros2.node_namespace, "/camera/camera");
  EXPECT_EQ(c.source.ros2.depth_topic, "");  // derived from the namespace
  EXPECT_TRUE(c.source.ros2.color);
  EXPECT_EQ(c.source.ros2.domain_id, 0);
  EXPECT_EQ(c.source.ros2.startup_timeout_s, 10.0);
  EXPECT_EQ(c.publish.node_namespace, "/camera/camera");
  EXPECT_EQ(c.publish.domain_id, 0);
  EXPECT_EQ(c.publish.wait_for_subscribers, 0);
}

TEST(Ros2Config, KeysAreReadAndBounded) {
  const Config c = load_config("", {"source.type=ros2", "source.ros2.namespace=/cell/d435_left",
                                    "source.ros2.depth_topic=/cell/d435_left/aligned_depth_to_color/image_raw",
                                    "source.ros2.domain_id=42", "source.ros2.color=false", "publish.domain_id=232",
                                    "publish.wait_for_subscribers=2", "publish.wait_timeout_s=5"});
  EXPECT_EQ(c.source.type, SourceType::ros2);
  EXPECT_EQ(c.source.ros2.node_namespace, "/cell/d435_left");
  EXPECT_EQ(c.source.ros2.depth_topic, "/cell/d435_left/aligned_depth_to_color/image_raw");
  EXPECT_EQ(c.source.ros2.domain_id, 42);
  EXPECT_FALSE(c.source.ros2.color);
  EXPECT_EQ(c.publish.domain_id, 232);
  EXPECT_EQ(c.publish.wait_for_subscribers, 2);
  EXPECT_EQ(c.publish.wait_timeout_s, 5.0);
  for (const std::string bad : {"source.ros2.domain_id=233", "source.ros2.domain_id=-1", "publish.domain_id=300",
                                "source.ros2.namespace=camera", "source.ros2.namespace=/camera/", "source.ros2.namespace=/a//b",
                                "source.ros2.depth_topic=/cam/depth image", "publish.namespace=/cam-1",
                                "source.ros2.startup_timeout_s=0", "publish.wait_for_subscribers=-1"}) {
    try {
      load_config("", {bad});
      ADD_FAILURE() << bad << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("key '" + bad.substr(0, bad.find('=')) + "'"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// safety.detection_range_m (issue 30, item 3): the range up to which safety.detection_mm holds
// for the camera and filter chain. A number >= 0 in metres, 0 (the default) meaning "not
// stated"; it reaches SsmParams and the effective configuration, and changes nothing else.
// Also the defaults the detection capability rests on, d = 40 mm with the speckle threshold
// 0.8 d below it, and the ssm-mode check that keeps them so (docs/CONFIG.md, docs/SAFETY.md
// "C and the detection capability").
#include "config_test_util.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

using test::expect_config_error;

TEST(DetectionRangeConfig, DefaultIsNotStatedAndAStatedRangeIsRead) {
  const Config defaults = load_config("", {});
  EXPECT_EQ(defaults.pipeline.safety.ssm.detection_range_m, 0.0F);
  // d 40 mm (C = 208 mm) and the speckle threshold 0.8 d below it, as docs/CONFIG.md states.
  EXPECT_EQ(defaults.pipeline.safety.ssm.detection_mm, 40.0F);
  EXPECT_EQ(defaults.pipeline.foreground.min_object_mm, 32.0F);

  const Config stated = load_config("", {"safety.mode=ssm", "safety.detection_range_m=2.5"});
  EXPECT_EQ(stated.pipeline.safety.ssm.detection_range_m, 2.5F);
  EXPECT_NE(stated.canonical_yaml.find("detection_range_m: 2.5"), std::string::npos) << stated.canonical_yaml;
  // A statement, not a term of S_p: it changes the configuration's hash and nothing else.
  EXPECT_NE(config_hash(stated), config_hash(load_config("", {"safety.mode=ssm"})));
  EXPECT_EQ(stated.pipeline.safety.ssm.detection_mm, 40.0F);
  // zones mode reads it too (it says what the camera can see, whatever rule decides).
  EXPECT_EQ(load_config("", {"safety.detection_range_m=3"}).pipeline.safety.ssm.detection_range_m, 3.0F);
  EXPECT_EQ(load_config("", {"safety.detection_range_m=0"}).pipeline.safety.ssm.detection_range_m, 0.0F);
}

TEST(DetectionRangeConfig, NegativeOrNonNumericRangeIsAnErrorNamingTheKey) {
  expect_config_error("", {"safety.detection_range_m=-0.1"}, {"'safety.detection_range_m'"});
  expect_config_error("", {"safety.detection_range_m=far"}, {"'safety.detection_range_m'"});
  expect_config_error("", {"safety.detection_range_m=1e39"}, {"'safety.detection_range_m'"});
  expect_config_error("", {"safety.detection_range_m=.nan"}, {"'safety.detection_range_m'"});
}

// In ssm mode the speckle threshold stays at most 0.8 d: a test piece of d measures down to
// about 0.88 d (docs/SAFETY.md), so min_object_mm = d would remove it while C counts on it.
TEST(DetectionRangeConfig, SpeckleThresholdAboveFourFifthsOfDetectionIsRefusedInSsmMode) {
  // 0.8 · 40 = 32: the default passes, 33 does not.
  EXPECT_EQ(load_config("", {"safety.mode=ssm", "foreground.min_object_mm=32"}).pipeline.foreground.min_object_mm,
            32.0F);
  expect_config_error("", {"safety.mode=ssm", "foreground.min_object_mm=33"},
                      {"'safety.detection_mm'", "'foreground.min_object_mm'", "0.8", "got min_object_mm 33 > 32"});
  // The old rule's pair, min_object_mm = d = 40, is what removed a 40 mm ball.
  expect_config_error("", {"safety.mode=ssm", "foreground.min_object_mm=40"}, {"'foreground.min_object_mm'"});
  // A coarser capability allows a coarser threshold (0.8 · 50 = 40); zones mode has no C.
  EXPECT_EQ(load_config("", {"safety.mode=ssm", "safety.detection_mm=50", "foreground.min_object_mm=40"})
                .pipeline.foreground.min_object_mm,
            40.0F);
  EXPECT_EQ(load_config("", {"foreground.min_object_mm=40"}).pipeline.foreground.min_object_mm, 40.0F);
}

}  // namespace
}  // namespace hrcsense

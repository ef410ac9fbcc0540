// SPDX-License-Identifier: Apache-2.0
// What a live tuning may change (live_tuning_refusal): in ssm mode the foreground may only
// become at least as sensitive as configured, and min_object_mm stays within the share of
// safety.detection_mm that load_config allows; in zones mode anything goes.

#include "hrcsense/config/config.hpp"
#include "hrcsense/pipeline_params.hpp"
#include "hrcsense/ssm.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

// k_sigma 3, min_margin_m 0.02 m, detection_mm 40 (so min_object_mm at most 32), min_object_mm 20.
PipelineParams live_tuning_configured(SafetyParams::Mode mode) {
  PipelineParams params;
  params.safety.mode = mode;
  params.safety.ssm.detection_mm = 40.0F;
  params.foreground.k_sigma = 3.0F;
  params.foreground.min_margin_m = 0.02F;
  params.foreground.min_object_mm = 20.0F;
  return params;
}

struct LiveTuningCase {
  const char* what;
  float k_sigma;
  float min_margin_m;
  float min_object_mm;
  const char* refused;  ///< what the ssm refusal starts with; "" when allowed
};

TEST(LiveTuningRefusal, SsmKeepsTheForegroundAtLeastAsSensitiveAsConfigured) {
  const float nan = std::nanf("");
  const std::vector<LiveTuningCase> cases = {
      {"as configured", 3.0F, 0.02F, 20.0F, ""},
      {"k_sigma below", 1.5F, 0.02F, 20.0F, ""},
      {"k_sigma above", 3.5F, 0.02F, 20.0F, "foreground.k_sigma 3.5 refused in ssm mode: above the configured 3 "},
      {"k_sigma just above", 3.001F, 0.02F, 20.0F, "foreground.k_sigma 3.001 refused"},
      {"k_sigma 0", 0.0F, 0.02F, 20.0F, "foreground.k_sigma 0 refused in ssm mode: expected a number > 0"},
      {"k_sigma NaN", nan, 0.02F, 20.0F, "foreground.k_sigma nan refused"},
      {"margin 0", 3.0F, 0.0F, 20.0F, ""},
      {"margin below", 3.0F, 0.01F, 20.0F, ""},
      {"margin above", 3.0F, 0.05F, 20.0F,
       "foreground.min_margin_m 0.05 refused in ssm mode: above the configured 0.02 m "},
      {"margin negative", 3.0F, -0.01F, 20.0F, "foreground.min_margin_m -0.01 refused in ssm mode: expected"},
      // min_object_mm is bound by 0.8 · detection_mm only, not by its configured 20 mm.
      {"min_object above configured", 3.0F, 0.02F, 30.0F, ""},
      {"min_object at 0.8 d", 3.0F, 0.02F, 32.0F, ""},
      {"min_object 0", 3.0F, 0.02F, 0.0F, ""},
      {"min_object above 0.8 d", 3.0F, 0.02F, 32.5F,
       "foreground.min_object_mm 32.5 refused in ssm mode: above 0.8 * safety.detection_mm = 32 mm "},
      {"min_object negative", 3.0F, 0.02F, -1.0F, "foreground.min_object_mm -1 refused"},
  };
  const PipelineParams ssm = live_tuning_configured(SafetyParams::Mode::ssm);
  const PipelineParams zones = live_tuning_configured(SafetyParams::Mode::zones);
  for (const LiveTuningCase& c : cases) {
    LiveTuning proposed = tuning_of(ssm);
    proposed.foreground.k_sigma = c.k_sigma;
    proposed.foreground.min_margin_m = c.min_margin_m;
    proposed.foreground.min_object_mm = c.min_object_mm;
    const std::string why = live_tuning_refusal(ssm, proposed);
    if (std::string(c.refused).empty()) {
      EXPECT_EQ(why, "") << c.what;
    } else {
      EXPECT_EQ(why.rfind(c.refused, 0), 0U) << c.what << ": " << why;
    }
    EXPECT_EQ(live_tuning_refusal(zones, proposed), "") << c.what << " (zones mode takes anything)";
  }
}

TEST(LiveTuningRefusal, SsmReasonSaysWhyAndHowToRaiseIt) {
  const PipelineParams ssm = live_tuning_configured(SafetyParams::Mode::ssm);
  LiveTuning proposed = tuning_of(ssm);
  proposed.foreground.k_sigma = 5.0F;
  EXPECT_EQ(live_tuning_refusal(ssm, proposed),
            "foreground.k_sigma 5 refused in ssm mode: above the configured 3 (a higher threshold can miss a person; "
            "edit the configuration to raise it)");
  proposed = tuning_of(ssm);
  proposed.foreground.min_object_mm = 40.0F;
  const std::string why = live_tuning_refusal(ssm, proposed);
  EXPECT_NE(why.find("speckle"), std::string::npos) << why;
}

TEST(LiveTuningRefusal, TheFilterAndBackendPartsAreNotJudged) {
  const PipelineParams ssm = live_tuning_configured(SafetyParams::Mode::ssm);
  LiveTuning proposed = tuning_of(ssm);
  proposed.backend = ProximityBackend::octree;
  proposed.filters.threshold.max_m = 1.0F;
  EXPECT_EQ(live_tuning_refusal(ssm, proposed), "");
}

// The bound on min_object_mm is load_config's, to the float: what the parser takes at start is
// taken live, and one step above it is refused by both.
TEST(LiveTuningRefusal, MinObjectBoundIsTheParsersBound) {
  const Config config =
      load_config("", {"safety.mode=ssm", "safety.detection_mm=30", "foreground.min_object_mm=24"});
  EXPECT_EQ(config.pipeline.foreground.min_object_mm, kSpeckleShareOfDetection * 30.0F);
  EXPECT_EQ(live_tuning_refusal(config.pipeline, tuning_of(config.pipeline)), "");
  LiveTuning proposed = tuning_of(config.pipeline);
  proposed.foreground.min_object_mm = std::nextafter(24.0F, 100.0F);
  EXPECT_NE(live_tuning_refusal(config.pipeline, proposed), "");
  EXPECT_THROW((void)load_config("", {"safety.mode=ssm", "safety.detection_mm=30", "foreground.min_object_mm=24.0001"}),
               ConfigError);
}

}  // namespace
}  // namespace hrcsense

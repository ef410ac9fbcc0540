// SPDX-License-Identifier: Apache-2.0
// hrcsense — what a live tuning may change in `ssm` mode (live_tuning_refusal,
// pipeline_params.hpp).
#include "hrcsense/pipeline_params.hpp"

#include "hrcsense/ssm.hpp"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace hrcsense {
namespace {

// The shortest text (3 to 9 significant digits) that reads back as `value`, so that a refusal
// never says "3.00 refused: above the configured 3.00" for 3.001.
std::string live_tuning_value_text(float value) {
  char text[32];
  for (int digits = 3; digits <= 9; ++digits) {
    std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(value));
    if (std::strtof(text, nullptr) == value) break;
  }
  return text;
}

std::string live_tuning_refused(const char* key, float value, const std::string& why) {
  return std::string(key) + " " + live_tuning_value_text(value) + " refused in ssm mode: " + why;
}

}  // namespace

std::string live_tuning_refusal(const PipelineParams& configured, const LiveTuning& proposed) {
  if (configured.safety.mode != SafetyParams::Mode::ssm) return {};
  const ForegroundParams& was = configured.foreground;
  const ForegroundParams& asked = proposed.foreground;
  // Each test is written so that NaN fails it.
  if (!(asked.k_sigma > 0.0F)) {
    return live_tuning_refused("foreground.k_sigma", asked.k_sigma, "expected a number > 0");
  }
  if (!(asked.k_sigma <= was.k_sigma)) {
    return live_tuning_refused("foreground.k_sigma", asked.k_sigma,
                               "above the configured " + live_tuning_value_text(was.k_sigma) +
                                   " (a higher threshold can miss a person; edit the configuration to raise it)");
  }
  if (!(asked.min_margin_m >= 0.0F)) {
    return live_tuning_refused("foreground.min_margin_m", asked.min_margin_m, "expected a number >= 0");
  }
  if (!(asked.min_margin_m <= was.min_margin_m)) {
    return live_tuning_refused("foreground.min_margin_m", asked.min_margin_m,
                               "above the configured " + live_tuning_value_text(was.min_margin_m) +
                                   " m (a wider margin can miss a person near the background; edit the "
                                   "configuration to raise it)");
  }
  // The same float product as load_config's check, so the two never disagree at the bound.
  const float max_min_object_mm = kSpeckleShareOfDetection * configured.safety.ssm.detection_mm;
  if (!(asked.min_object_mm >= 0.0F)) {
    return live_tuning_refused("foreground.min_object_mm", asked.min_object_mm, "expected a number >= 0");
  }
  if (!(asked.min_object_mm <= max_min_object_mm)) {
    return live_tuning_refused("foreground.min_object_mm", asked.min_object_mm,
                               "above " + live_tuning_value_text(kSpeckleShareOfDetection) +
                                   " * safety.detection_mm = " + live_tuning_value_text(max_min_object_mm) +
                                   " mm (blobs smaller than min_object_mm are removed as speckle, so a test "
                                   "piece of detection_mm would not be detected)");
  }
  return {};
}

}  // namespace hrcsense

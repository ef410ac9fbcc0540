// SPDX-License-Identifier: Apache-2.0
// hrcsense config — the live camera's keys (`source.serial`, `source.width`, ..., `source.color.*`,
// `source.options.*`, `source.settle_frames`; docs/CONFIG.md), checked against the D435's
// modes and the RealSense SDK's option ranges, so that a bad value fails at load time with its
// key rather than at the camera.
#include "key_reader.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace hrcsense::config_detail {
namespace {

/// The D435's depth rates (its stereo module) and its RGB sensor's.
const std::vector<int> kDepthFps = {6, 15, 30, 60, 90};
const std::vector<int> kColorFps = {6, 15, 30, 60};
/// Larger than any D400 stream (1920x1080 colour); a typo is caught here, an unoffered mode
/// by the camera's own list (realsense/realsense_plan.hpp).
constexpr int kMaxStreamSide = 4096;

/// The visual presets of a D400 (rs2_rs400_visual_preset), by their number in the SDK.
const std::vector<std::string> kVisualPresets = {"custom",        "default",      "hand",
                                                 "high_accuracy", "high_density", "medium_density"};

std::string list_text(const std::vector<int>& values) {
  std::string text;
  for (int v : values) text += (text.empty() ? "" : ", ") + std::to_string(v);
  return text;
}

void rate(KeyReader& r, const std::string& key, int& fps, const std::vector<int>& allowed, const char* what) {
  r.integer(key, fps, 1, 1000);
  for (int v : allowed) {
    if (v == fps) return;
  }
  r.fail(key, "expected one of " + list_text(allowed) + " frames/s (" + what + "), got " + std::to_string(fps));
}

void read_visual_preset(KeyReader& r, const std::string& key, std::vector<CameraOption>& out) {
  std::string name;
  r.text(key, name);
  for (size_t i = 0; i < kVisualPresets.size(); ++i) {
    if (kVisualPresets[i] == name) {
      out.push_back({"visual_preset", static_cast<float>(i)});
      return;
    }
  }
  std::string list;
  for (const std::string& preset : kVisualPresets) list += (list.empty() ? "" : ", ") + preset;
  r.fail(key, "expected one of " + list + ", got '" + name + "'");
}

// On / off as 1 / 0 or a YAML bool. 2 is "laser auto" on some firmwares: refused, because a
// cell's depth quality must not change with what the firmware decides.
void read_emitter(KeyReader& r, const std::string& key, const YAML::Node& node, std::vector<CameraOption>& out) {
  const std::string text = node.IsScalar() ? node.Scalar() : std::string();
  bool on = false;
  if (text == "2") {
    r.fail(key, "2 (laser auto, on some firmwares) is not supported: the emitter must be in a known state; "
                "expected true (1) or false (0)");
  }
  if (text == "0" || text == "1") {
    on = text == "1";
  } else if (!node.IsScalar() || !YAML::convert<bool>::decode(node, on)) {
    r.fail(key, "expected true (1, on) or false (0, off), got '" + text + "'");
  }
  r.set_effective(key, YAML::Node(on));
  out.push_back({"emitter_enabled", on ? 1.0F : 0.0F});
}

void read_options(KeyReader& r, std::vector<CameraOption>& out) {
  out.clear();
  // In the order the SDK gets them: a preset first (it resets the others), auto exposure
  // before a manual exposure.
  const std::string preset_key = "source.options.visual_preset";
  if (r.raw(preset_key).IsDefined()) read_visual_preset(r, preset_key, out);

  const std::string emitter_key = "source.options.emitter_enabled";
  const YAML::Node emitter = r.raw(emitter_key);
  if (emitter.IsDefined()) read_emitter(r, emitter_key, emitter, out);

  const std::string laser_key = "source.options.laser_power";
  if (r.raw(laser_key).IsDefined()) {
    double mw = 0.0;
    r.number(laser_key, mw, Bound::non_negative, 360.0);
    // The D435's laser power goes in steps of 30 mW; the SDK refuses values between the steps.
    if (std::fmod(mw, 30.0) != 0.0) {
      r.fail(laser_key, "expected a multiple of 30 in [0, 360] mW (the D435's steps), got " + double_text(mw));
    }
    out.push_back({"laser_power", static_cast<float>(mw)});
  }

  const std::string auto_key = "source.options.enable_auto_exposure";
  const std::string exposure_key = "source.options.exposure";
  const bool auto_given = r.raw(auto_key).IsDefined();
  const bool exposure_given = r.raw(exposure_key).IsDefined();
  bool auto_on = true;
  if (auto_given) r.flag(auto_key, auto_on);
  if (exposure_given && auto_given && auto_on) {
    r.fail_pair(auto_key, exposure_key, "a manual exposure needs auto exposure off; set enable_auto_exposure false");
  }
  // A manual exposure holds only with auto exposure off: say so to the SDK even when not written.
  if (auto_given || exposure_given) out.push_back({"enable_auto_exposure", auto_on && !exposure_given ? 1.0F : 0.0F});
  if (exposure_given) {
    int exposure_us = 0;
    r.integer(exposure_key, exposure_us, 1, 165000);  // µs, the D435's depth exposure range
    out.push_back({"exposure", static_cast<float>(exposure_us)});
  }
}

}  // namespace

void read_camera_source(KeyReader& r, SourceConfig& source) {
  r.text("source.serial", source.serial);
  r.integer("source.width", source.width, 1, kMaxStreamSide);
  r.integer("source.height", source.height, 1, kMaxStreamSide);
  rate(r, "source.fps", source.fps, kDepthFps, "the D435's depth rates");
  r.flag("source.color.enabled", source.color.enabled);
  r.integer("source.color.width", source.color.width, 1, kMaxStreamSide);
  r.integer("source.color.height", source.color.height, 1, kMaxStreamSide);
  rate(r, "source.color.fps", source.color.fps, kColorFps, "the D435's colour rates");
  read_options(r, source.options);
  // Up to 1000 frames: 11 s at 90 frames/s, far longer than auto exposure needs.
  r.integer("source.settle_frames", source.settle_frames, 0, 1000);
}

}  // namespace hrcsense::config_detail

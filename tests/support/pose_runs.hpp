// SPDX-License-Identifier: Apache-2.0
// Runs the hrcsense tool on a shipped cell with overrides and reads each frame line's reason
// code: the camera pose check's acceptance tests (short and long).
#pragma once

#include "scenes.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

namespace hrcsense::test {

struct FrameReason {
  int64_t frame = 0;
  std::string reason_code;
};

// The value after `"key":` in a JSON line, up to the next comma or brace, quotes removed.
inline std::string json_field(const std::string& line, const std::string& key) {
  const std::string tag = "\"" + key + "\":";
  const size_t at = line.find(tag);
  if (at == std::string::npos) return "";
  size_t begin = at + tag.size();
  size_t end = line.find_first_of(",}", begin);
  std::string value = line.substr(begin, end - begin);
  if (value.size() >= 2 && value.front() == '"') value = value.substr(1, value.size() - 2);
  return value;
}

/// The frame lines of `hrcsense run --config <config> <extra>` (written to `name`.jsonl in the
/// test's temporary directory), in order; empty when the tool failed.
inline std::vector<FrameReason> run_frame_reasons(const std::string& config, const std::string& extra,
                                                  const std::string& name) {
  const std::string out = std::string(::testing::TempDir()) + name + ".jsonl";
  // Without the colour camera: the pose check and the verdicts read depth only, and the colour
  // rendering is a quarter of the simulator's time.
  const std::string command = std::string(HRCSENSE_CLI) + " run --config " + scene_path(config) +
                              " --set sim.color=false " + extra + " --out " + out + " 2>/dev/null";
  if (std::system(command.c_str()) != 0) return {};
  std::vector<FrameReason> frames;
  std::ifstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("\"type\":\"frame\"") == std::string::npos) continue;
    frames.push_back({std::stoll(json_field(line, "frame")), json_field(line, "reason_code")});
  }
  return frames;
}

/// The first frame whose reason is `code` at or after `from`, or -1.
inline int64_t first_with(const std::vector<FrameReason>& frames, const std::string& code, int64_t from = 0) {
  for (const FrameReason& f : frames) {
    if (f.frame >= from && f.reason_code == code) return f.frame;
  }
  return -1;
}

}  // namespace hrcsense::test

// SPDX-License-Identifier: Apache-2.0
// Helpers for the recording tests: a scratch folder, the shared data, a collecting sink.
#pragma once

#include "hrcsense/pipeline.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace hrcsense::test {

/// A fresh folder under the system temp dir, removed at the end of the test; the process id in
/// its name keeps two test runs on one machine out of each other's folders.
struct ScratchDir {
  std::filesystem::path path;
  explicit ScratchDir(const std::string& name) {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = std::filesystem::temp_directory_path() /
           ("hrcsense_" + name + "_" + info->test_suite_name() + "_" + info->name() + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
    std::filesystem::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
};

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file << text;
}

inline std::vector<char> read_bytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

inline void write_bytes(const std::string& path, const std::vector<char>& bytes) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

/// ../shared/data/<name>, or "" when the shared data is absent (the test then skips).
inline std::string shared_data(const std::string& name) {
  const std::string path = std::string(HRCSENSE_SHARED_DIR) + "/data/" + name;
  return std::filesystem::exists(path) ? path : std::string();
}

/// The real D435 recording (6 frames/s, two depth frames, one colour frame), or "" when the
/// shared data is absent.
inline std::string shared_d435_bag() {
  const std::string dir = shared_data("librealsense_d435_single_frame");
  return dir.empty() ? dir : dir + "/single_depth_color_640x480.bag";
}

/// Keeps everything a run writes.
struct KeepingSink : Sink {
  std::vector<FrameResult> results;
  RunSummary summary_seen;
  void header(const RunHeader& /*header*/) override {}
  void frame(const FrameResult& result) override { results.push_back(result); }
  void summary(const RunSummary& summary) override { summary_seen = summary; }
};

}  // namespace hrcsense::test

// SPDX-License-Identifier: Apache-2.0
// Helpers for the config tests: a temporary folder and ConfigError expectations.
#pragma once

#include "hrcsense/config/config.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <unistd.h>

namespace hrcsense::test {

inline bool file_exists(const std::string& path) { return std::filesystem::exists(path); }

/// A fresh folder under the system's temporary directory, removed with its contents.
class TempDir {
 public:
  TempDir() {
    static std::atomic<int> counter{0};
    path_ = std::filesystem::temp_directory_path() /
            ("hrcsense_config_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  /// Writes `text` to `name` inside the folder and returns the file's path.
  std::string write(const std::string& name, const std::string& text) const {
    const std::string file = (path_ / name).string();
    std::ofstream(file) << text;
    return file;
  }
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

/// Expects load_config(path, overrides) to throw a ConfigError whose message contains
/// every string of `needles`.
inline void expect_config_error(const std::string& path, const std::vector<std::string>& overrides,
                                const std::vector<std::string>& needles) {
  try {
    (void)load_config(path, overrides);
    ADD_FAILURE() << "no ConfigError for " << path;
  } catch (const ConfigError& e) {
    const std::string message = e.what();
    for (const std::string& needle : needles) {
      EXPECT_NE(message.find(needle), std::string::npos) << "'" << needle << "' not in: " << message;
    }
  }
}

}  // namespace hrcsense::test

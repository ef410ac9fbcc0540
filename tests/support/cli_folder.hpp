// SPDX-License-Identifier: Apache-2.0
// Test support: a GoogleTest fixture that runs the `hrcsense` command line (HRCSENSE_CLI) in a
// temporary folder of its own, with stdout and stderr captured into files there.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

namespace hrcsense::test {

inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// What one command printed, and its exit code (-1 when a signal ended it).
struct CliOutcome {
  int exit_code = -1;
  std::string out;
  std::string err;
  std::vector<std::string> err_lines() const {
    std::vector<std::string> lines;
    std::istringstream in(err);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
  }
};

/// Each test gets a fresh folder, removed afterwards; run() executes the CLI inside it.
class CliFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("hrcsense_cli_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name() + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    std::filesystem::remove_all(dir_, ignored);
  }

  /// Runs `hrcsense ARGUMENTS` through the shell in the folder; `prefix` goes before it (e.g. a
  /// `ulimit -v N;`).
  CliOutcome run(const std::string& arguments, const std::string& prefix = "") const {
    const std::string command = "cd '" + dir_.string() + "' && " + prefix + " '" + HRCSENSE_CLI + "' " + arguments +
                                " > stdout.txt 2> stderr.txt";
    const int status = std::system(command.c_str());
    CliOutcome outcome;
    outcome.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    outcome.out = read_text(dir_ / "stdout.txt");
    outcome.err = read_text(dir_ / "stderr.txt");
    return outcome;
  }

  /// Writes a file into the folder; returns its name.
  std::string write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return name;
  }

  std::filesystem::path dir_;
};

}  // namespace hrcsense::test

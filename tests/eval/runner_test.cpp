// SPDX-License-Identifier: Apache-2.0
// The sweep runner as a library (eval/runner.hpp): it reports to its observer, never to the
// terminal. One row of the thesis box scene, 10 frames of which 5 learn the background.

#include "hrcsense/eval/runner.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <unistd.h>
#include <vector>

namespace hrcsense {
namespace {

TEST(RunSweep, ReportsProgressAndNotesToItsObserver) {
  const std::string dir =
      std::string(::testing::TempDir()) + "eval_runner_observer_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  eval::SweepRequest request;
  request.scenes = {std::string(HRCSENSE_SOURCE_DIR) + "/config/thesis-box-human.yaml"};
  request.sets = {"sim.color=false", "sim.width=424", "sim.height=240", "background.frames=5"};
  request.points = eval::sweep_grid({});
  request.frames = 10;
  request.out_dir = dir;
  request.label = "observed";
  std::vector<eval::SweepProgress> reports;
  std::vector<std::string> notes;
  request.observer.progress = [&](const eval::SweepProgress& p) { reports.push_back(p); };
  request.observer.note = [&](const std::string& note) { notes.push_back(note); };

  const eval::ResultTable table = eval::run_sweep(request);
  ASSERT_EQ(table.rows.size(), 1U);
  ASSERT_FALSE(reports.empty());
  const eval::SweepProgress& last = reports.back();
  EXPECT_TRUE(last.finished);
  for (size_t i = 0; i + 1 < reports.size(); ++i) EXPECT_FALSE(reports[i].finished);
  EXPECT_EQ(last.rows_done, 1);
  EXPECT_EQ(last.rows_total, 1);
  EXPECT_EQ(last.frames_done, 10);
  EXPECT_EQ(last.frames_total, 10);
  EXPECT_EQ(last.current.rfind("observed: ", 0), 0U) << last.current;
  ASSERT_EQ(notes.size(), 1U);
  EXPECT_NE(notes[0].find("1 rows in " + dir + "/results.csv"), std::string::npos) << notes[0];

  // Run again: every row is there, so it resumes and runs none.
  reports.clear();
  notes.clear();
  eval::run_sweep(request);
  ASSERT_EQ(notes.size(), 2U);
  EXPECT_NE(notes[0].find("resuming"), std::string::npos) << notes[0];
  EXPECT_NE(notes[1].find("(0 run now)"), std::string::npos) << notes[1];
  ASSERT_FALSE(reports.empty());
  EXPECT_EQ(reports.back().rows_total, 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// `hrcsense record` keeps the colour of a folder or bag source that has it (issue 31, item 9),
// on the real recordings in ../shared/data. Expectations come from their READMEs.
#include "recordings_test_util.hpp"
#include "../support/run_cli.hpp"

#include "hrcsense/recordings/recordings.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

using test::cli;
using test::CliResult;
using test::ScratchDir;

#define REQUIRE_SHARED(path_expression, path)                      \
  const std::string path = (path_expression);                      \
  if (path.empty()) GTEST_SKIP() << "../shared/data is absent"

/// `hrcsense record` of `source` (its --set arguments and limits) into a scratch bag, summarised;
/// fails the test unless the recording has a depth and a colour stream.
RecordingSummary record_with_colour(const std::string& source) {
  ScratchDir out("recolour");
  const std::string bag = out / "recorded.bag";
  const CliResult r = cli("record " + source + " --out " + bag);
  EXPECT_EQ(r.exit_code, 0) << r.out;
  const RecordingSummary summary = r.exit_code == 0 ? summarize_recording(bag) : RecordingSummary{};
  EXPECT_EQ(summary.streams.size(), 2U) << "depth and colour";
  return summary;
}

TEST(RecordColour, AFolderWithColourIsRecordedWithItsColourAndCalibration) {
  REQUIRE_SHARED(test::shared_data("ist_piv_lab_people"), folder);
  const RecordingSummary summary = record_with_colour("--set source.type=folder --set source.path=" + folder +
                                                      " --frames 3");
  ASSERT_EQ(summary.streams.size(), 2U);
  const RecordingStream& color = summary.streams[1];
  EXPECT_EQ(color.frames, 3);
  EXPECT_EQ(color.intrinsics.width, 640);
  EXPECT_EQ(color.intrinsics.height, 480);
  EXPECT_NEAR(color.intrinsics.fx, 534.2856, 1e-3) << "README: RGB camera K";
  EXPECT_NEAR(color.intrinsics.fy, 534.7452, 1e-3);
  // README: depth→RGB T = (-0.02631, 0.00028, -0.00078) m.
  ASSERT_TRUE(summary.T_color_depth.has_value());
  EXPECT_NEAR(summary.T_color_depth->translation().x(), -0.02631, 1e-5);
  EXPECT_NEAR(summary.T_color_depth->translation().z(), -0.00078, 1e-5);
}

TEST(RecordColour, ABagWithColourIsRecordedWithItsColourAndCalibration) {
  REQUIRE_SHARED(test::shared_d435_bag(), bag);
  const RecordingSummary summary = record_with_colour("--set source.type=bag --set source.path=" + bag);
  ASSERT_EQ(summary.streams.size(), 2U);
  const RecordingStream& color = summary.streams[1];
  EXPECT_GE(color.frames, 1);
  EXPECT_EQ(color.encoding, "rgb8");
  EXPECT_NEAR(color.intrinsics.fx, 613.2037, 1e-3) << "README: colour intrinsics";
  EXPECT_NEAR(color.intrinsics.ppy, 239.1830, 1e-3);
  ASSERT_TRUE(summary.T_color_depth.has_value());
  EXPECT_NEAR(summary.T_color_depth->translation().x(), 0.014311, 1e-6) << "README: Color_0/tf/0";
}

// `hrcsense run --record` keeps the colour too, although processing decodes none of its own.
TEST(RecordColourCli, RunRecordKeepsTheColourOfABag) {
  REQUIRE_SHARED(test::shared_d435_bag(), bag);
  ScratchDir out("runrecolour");
  const std::string recorded = out / "run.bag";
  const CliResult r = cli("run --set source.type=bag --set source.path=" + bag + " --set background.frames=1 --record " +
                          recorded + " --out " + (out / "run.jsonl"));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  const RecordingSummary summary = summarize_recording(recorded);
  ASSERT_EQ(summary.streams.size(), 2U) << "depth and colour";
  EXPECT_GE(summary.streams[1].frames, 1);
  EXPECT_NEAR(summary.streams[1].intrinsics.fx, 613.2037, 1e-3) << "README: colour intrinsics";
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// `hrcsense eval`'s sweeps (parse_sweep, sweep_grid) and its resumable results.csv
// (csv_field, split_csv_line, resume_results), against values written out by hand.

#include "hrcsense/eval/sweep.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense::eval {
namespace {

using Strings = std::vector<std::string>;

std::string message_of(const std::string& argument) {
  try {
    parse_sweep(argument);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(ParseSweep, ListsKeepTheirValuesAsWritten) {
  const SweepAxis axis = parse_sweep("proximity.backend=brute,kdtree,octree");
  EXPECT_EQ(axis.key, "proximity.backend");
  EXPECT_EQ(axis.values, (Strings{"brute", "kdtree", "octree"}));
  EXPECT_EQ(parse_sweep("filters.spatial.alpha=0.5").values, (Strings{"0.5"}));
}

TEST(ParseSweep, RangesIncludeBothEndsWithTheInputsDecimals) {
  EXPECT_EQ(parse_sweep("filters.temporal.persistence=0:8").values,
            (Strings{"0", "1", "2", "3", "4", "5", "6", "7", "8"}));
  EXPECT_EQ(parse_sweep("filters.spatial.alpha=0.25:1:0.25").values, (Strings{"0.25", "0.5", "0.75", "1"}));
  // 0.1 + 2·0.1 is 0.30000000000000004 in binary: written with one decimal, and still included.
  EXPECT_EQ(parse_sweep("safety.stop_distance_m=0.1:0.3:0.1").values, (Strings{"0.1", "0.2", "0.3"}));
  // B off the step grid: the last value is the one at or below B.
  EXPECT_EQ(parse_sweep("filters.spatial.delta=1:50:20").values, (Strings{"1", "21", "41"}));
  EXPECT_EQ(parse_sweep("robot.x=-0.5:0.5:0.5").values, (Strings{"-0.5", "0", "0.5"}));
  EXPECT_EQ(parse_sweep("a.b=3:3").values, (Strings{"3"}));
}

TEST(ParseSweep, BadArgumentsNameThemselves) {
  EXPECT_EQ(message_of("persistence"),
            "--sweep 'persistence': expected KEY=V1,V2,... or KEY=A:B[:STEP], e.g. filters.temporal.persistence=0:8");
  EXPECT_EQ(message_of("persistence=0:8"),
            "--sweep 'persistence=0:8': 'persistence' is no configuration key (keys have a section: "
            "safety.stop_distance_m)");
  EXPECT_EQ(message_of("a.b=1,,2"), "--sweep 'a.b=1,,2': an empty value");
  EXPECT_EQ(message_of("a.b=8:0"), "--sweep 'a.b=8:0': expected A <= B");
  EXPECT_EQ(message_of("a.b=0:8:0"), "--sweep 'a.b=0:8:0': expected STEP > 0");
  EXPECT_EQ(message_of("a.b=0:8:-1"), "--sweep 'a.b=0:8:-1': expected STEP > 0");
  EXPECT_EQ(message_of("a.b=1e3:2e3"),
            "--sweep 'a.b=1e3:2e3': expected decimal numbers in A:B[:STEP], e.g. 0.25:1:0.25");
  EXPECT_EQ(message_of("a.b=0:1:2:3"), "--sweep 'a.b=0:1:2:3': expected A:B or A:B:STEP");
  EXPECT_EQ(message_of("a.b=0:10000"), "--sweep 'a.b=0:10000': more than 10000 values");
  EXPECT_EQ(parse_sweep("a.b=1:10000").values.size(), 10000U);
}

TEST(SweepGrid, LastAxisChangesFastest) {
  const std::vector<SweepPoint> grid =
      sweep_grid({parse_sweep("filters.spatial.alpha=0.25,0.5"), parse_sweep("filters.spatial.delta=1:3")});
  ASSERT_EQ(grid.size(), 6U);
  const std::vector<Strings> expected = {{"filters.spatial.alpha=0.25", "filters.spatial.delta=1"},
                                         {"filters.spatial.alpha=0.25", "filters.spatial.delta=2"},
                                         {"filters.spatial.alpha=0.25", "filters.spatial.delta=3"},
                                         {"filters.spatial.alpha=0.5", "filters.spatial.delta=1"},
                                         {"filters.spatial.alpha=0.5", "filters.spatial.delta=2"},
                                         {"filters.spatial.alpha=0.5", "filters.spatial.delta=3"}};
  for (size_t i = 0; i < grid.size(); ++i) {
    EXPECT_EQ(grid[i].index, static_cast<int64_t>(i));
    EXPECT_EQ(grid[i].settings, expected[i]) << i;
  }
  EXPECT_EQ(settings_text(grid[4]), "filters.spatial.alpha=0.5;filters.spatial.delta=2");
}

TEST(SweepGrid, NoAxesIsOnePointAndAKeyTwiceIsAnError) {
  const std::vector<SweepPoint> one = sweep_grid({});
  ASSERT_EQ(one.size(), 1U);
  EXPECT_TRUE(one[0].settings.empty());
  EXPECT_EQ(settings_text(one[0]), "");
  try {
    sweep_grid({parse_sweep("a.b=1,2"), parse_sweep("a.b=3")});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), "--sweep: a.b is swept twice");
  }
}

TEST(Csv, FieldsAreQuotedOnlyWhenNeededAndSplitBack) {
  EXPECT_EQ(csv_field("walk.yaml"), "walk.yaml");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two lines\"");
  EXPECT_EQ(split_csv_line("1,\"a,b\",\"say \"\"hi\"\"\",,x"), (Strings{"1", "a,b", "say \"hi\"", "", "x"}));
  EXPECT_EQ(split_csv_line(""), (Strings{""}));
  EXPECT_THROW(split_csv_line("1,\"open"), std::invalid_argument);
}

class ResumeResults : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = std::string(::testing::TempDir()) + "resume_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".csv";
    std::filesystem::remove(path_);
  }
  void TearDown() override { std::filesystem::remove(path_); }
  void write(const std::string& text) const { std::ofstream(path_, std::ios::binary) << text; }
  std::string read() const {
    std::ifstream in(path_, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  std::string path_;
  const std::string header_ = "settings,scene,seed,frames";
};

TEST_F(ResumeResults, ANewFileGetsTheHeader) {
  const ResumeState state = resume_results(path_, header_, 3);
  EXPECT_FALSE(state.existed);
  EXPECT_EQ(state.rows, 0);
  EXPECT_TRUE(state.done.empty());
  EXPECT_EQ(read(), header_ + "\n");
}

TEST_F(ResumeResults, CompleteRowsAreDoneAndACutOffLineIsRemoved) {
  write(header_ + "\na.b=1,walk.yaml,1,300\n\"a.b=1;c.d=x,y\",walk.yaml,2,300\na.b=2,walk.ya");
  const ResumeState state = resume_results(path_, header_, 3);
  EXPECT_TRUE(state.existed);
  EXPECT_EQ(state.rows, 2);
  EXPECT_TRUE(state.dropped_partial);
  EXPECT_EQ(state.done, (std::set<std::string>{"a.b=1,walk.yaml,1,", "\"a.b=1;c.d=x,y\",walk.yaml,2,"}));
  EXPECT_EQ(row_key({"a.b=1", "walk.yaml", "1"}), "a.b=1,walk.yaml,1,");
  EXPECT_EQ(read(), header_ + "\na.b=1,walk.yaml,1,300\n\"a.b=1;c.d=x,y\",walk.yaml,2,300\n");
}

TEST_F(ResumeResults, AnotherSweepsTableOrABrokenRowIsAnErrorNamingTheFile) {
  write("settings,scene,seed,frames,fps\n");
  try {
    resume_results(path_, header_, 3);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path_ + ": not this sweep's table (its header differs); use another --out or remove it");
  }
  write(header_ + "\na.b=1,walk.yaml,1,300\na.b=2,walk.yaml,1\n");
  try {
    resume_results(path_, header_, 3);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), path_ + ":3: expected 4 fields, got 3");
  }
}

// One sweep point twice (two runs merged into one table): refused, naming both lines.
TEST_F(ResumeResults, ARowKeyTwiceIsAnErrorNamingBothLines) {
  write(header_ + "\na.b=1,walk.yaml,1,300\na.b=2,walk.yaml,1,300\na.b=1,walk.yaml,1,200\n");
  try {
    resume_results(path_, header_, 3);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              path_ + ":4: the row a.b=1,walk.yaml,1, is there twice (also line 2); use another --out or remove one");
  }
}

}  // namespace
}  // namespace hrcsense::eval

// SPDX-License-Identifier: Apache-2.0
// `hrcsense run` in ssm mode and the robot's stopping data (issue S2, part 3): a simulated cell
// without stopping data runs, warns at the start and says `stopping_data: "default"` in its
// header; a live robot state without them is refused before anything runs (exit 2, naming the
// keys); a table runs without the warning and says "table".
#include "../support/run_cli.hpp"
#include "../support/scenes.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>
#include <string>

namespace hrcsense {
namespace {

using nlohmann::json;
using test::cli;
using test::scene_path;

// The header line of a run's output (stdout and stderr together: the JSON lines start with '{').
json header_of(const std::string& out) {
  std::istringstream lines(out);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line.front() != '{') continue;
    const json parsed = json::parse(line, nullptr, false);
    if (!parsed.is_discarded() && parsed.value("type", "") == "header") return parsed;
  }
  return json();
}

const std::string kSmall = " --frames 2 --set sim.width=424 --set sim.height=240";

TEST(StoppingDataCli, SimulatedSsmCellWithoutStoppingDataRunsAndWarns) {
  const test::CliResult r = cli("run --config '" + scene_path("cell-ur5-moving.yaml") + "'" + kSmall);
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("without the robot's stopping data"), std::string::npos) << r.out;
  const json header = header_of(r.out);
  ASSERT_TRUE(header.is_object()) << r.out;
  EXPECT_EQ(header["stopping_data"], "default");
}

TEST(StoppingDataCli, LiveRobotStateWithoutStoppingDataIsRefusedAtStart) {
  const test::CliResult r =
      cli("run --config '" + scene_path("cell-ur5-moving.yaml") + "'" + kSmall + " --set robot.state.source=udp_json");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("'safety.stopping_table'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("'robot.state.source'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("stopping_data_confirmed"), std::string::npos) << r.out;
  EXPECT_TRUE(header_of(r.out).is_null()) << "nothing ran";
}

TEST(StoppingDataCli, TableRunsWithoutTheWarning) {
  const test::CliResult r = cli("run --config '" + scene_path("cell-ur5-moving.yaml") + "'" + kSmall +
                                " --set 'safety.stopping_table=[{speed_mps: 1.0, distance_m: 0.3, time_s: 0.4}]'");
  ASSERT_EQ(r.exit_code, 0) << r.out;
  EXPECT_EQ(r.out.find("without the robot's stopping data"), std::string::npos) << r.out;
  EXPECT_EQ(header_of(r.out)["stopping_data"], "table");
  // Zones mode says nothing of stopping data: null.
  const test::CliResult zones =
      cli("run --config '" + scene_path("cell-ur5-moving.yaml") + "'" + kSmall + " --set safety.mode=zones");
  ASSERT_EQ(zones.exit_code, 0) << zones.out;
  EXPECT_TRUE(header_of(zones.out)["stopping_data"].is_null());
}

}  // namespace
}  // namespace hrcsense

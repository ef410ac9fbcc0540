// SPDX-License-Identifier: Apache-2.0
// Tests of the YAML a configuration may hold: duplicate keys and sections, extra documents,
// unknown tags and leading zeros are errors naming the file (or the --set) and the key; the
// same holds for robot description files. Files that are folders or FIFOs are refused by name.
#include "config_test_util.hpp"
#include "../support/no_block.hpp"
#include "../support/run_cli.hpp"

#include <gtest/gtest.h>

#include <string>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

/// The ConfigError message of load_config(path, overrides); "" when it loads.
std::string error_of(const std::string& path, const std::vector<std::string>& overrides = {}) {
  try {
    (void)load_config(path, overrides);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return {};
}

const char* const kMinimalPostArm = R"(name: post
dh:
  - {d_m: 1, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
  - {d_m: 0, a_m: 0, alpha_deg: 0}
links:
  base: [{a_m: [0, 0, 0], b_m: [0, 0, 1], radius_m: 0.1}]
)";

TEST(ConfigStrict, DuplicateKeysAndSectionsNameFileLineAndKey) {
  TempDir dir;
  // An override appended to a file: yaml-cpp kept the first, so 0.3 silently stayed in force.
  const std::string appended = dir.write("appended.yaml", "safety:\n  stop_distance_m: 0.3\n  stop_distance_m: 0.45\n");
  EXPECT_EQ(error_of(appended), appended +
                                    ":3:3: duplicate key 'safety.stop_distance_m' (first at line 2); YAML readers "
                                    "silently keep only one of them");
  const std::string sections = dir.write("sections.yaml", "safety: {stop_distance_m: 0.3}\nsim: {fps: 30}\nsafety: {slow_distance_m: 2}\n");
  EXPECT_EQ(error_of(sections).rfind(sections + ":3:1: duplicate key 'safety' (first at line 1)", 0), 0U) << error_of(sections);
  // At any depth, inside lists too; quoting does not make a key different.
  const std::string deep = dir.write("deep.yaml",
                                     "scene:\n  objects:\n    - name: a\n      shapes: []\n    - name: b\n      'name': c\n");
  expect_config_error(deep, {}, {deep + ":6:7:", "duplicate key 'scene.objects[1].name'"});
  // The same name in two different maps is fine.
  EXPECT_EQ(error_of(dir.write("fine.yaml", "sim: {fps: 30}\nbackground: {frames: 5}\nforeground: {k_sigma: 4}\n")), "");
  // A --set value is held to the same rule, its keys named below the --set key.
  EXPECT_EQ(error_of("", {"foreground.workspace_base={min: [0, 0, 0], min: [1, 1, 1]}"}),
            "--set 'foreground.workspace_base={min: [0, 0, 0], min: [1, 1, 1]}': duplicate key "
            "'foreground.workspace_base.min' (first at line 1); YAML readers silently keep only one of them");
}

TEST(ConfigStrict, ASecondDocumentIsAnError) {
  TempDir dir;
  const std::string two = dir.write("two.yaml", "safety: {stop_distance_m: 0.3}\n---\nsafety: {stop_distance_m: 0.9}\n");
  EXPECT_EQ(error_of(two), two + ":2:1: a second YAML document (after '---' or '...'); a file holds one configuration");
  expect_config_error(dir.write("dots.yaml", "sim: {fps: 30}\n...\nsim: {fps: 15}\n"), {}, {"dots.yaml", "second YAML document"});
  expect_config_error("", {"safety.stop_distance_m=0.3\n---\n0.9"}, {"--set 'safety.stop_distance_m=", "second YAML document"});
  // One document with its markers, an empty file and a comment-only file are fine.
  EXPECT_EQ(error_of(dir.write("one.yaml", "---\nsim: {fps: 30}\n...\n")), "");
  EXPECT_EQ(error_of(dir.write("empty.yaml", "")), "");
  EXPECT_EQ(error_of(dir.write("comment.yaml", "# nothing yet\n")), "");
}

TEST(ConfigStrict, UnknownTagsAreErrorsNamingTheKey) {
  TempDir dir;
  const std::string custom = dir.write("tag.yaml", "safety:\n  stop_distance_m: !metres 0.3\n");
  EXPECT_EQ(error_of(custom), custom +
                                  ":2:20: unknown tag '!metres' on key 'safety.stop_distance_m'; only YAML's standard "
                                  "tags (!!str, !!int, !!float, !!bool, !!null, !!map, !!seq) are understood");
  expect_config_error(dir.write("seq.yaml", "robot:\n  points_base: !points [[0, 0, 1]]\n"), {},
                      {"seq.yaml:2:16:", "unknown tag '!points' on key 'robot.points_base'"});
  expect_config_error(dir.write("core.yaml", "sim: {fps: !!binary 30}\n"), {}, {"'!!binary'", "'sim.fps'"});
  expect_config_error("", {"sim.fps=!fast 30"}, {"--set 'sim.fps=!fast 30'", "unknown tag '!fast' on key 'sim.fps'"});
  // YAML's own tags are understood, and mean what they say.
  const Config c = load_config(dir.write("std.yaml", "safety: !!map {stop_distance_m: !!float 0.3}\nsource: {path: !!str 017}\n"), {});
  EXPECT_EQ(c.pipeline.safety.stop_distance_m, 0.3F);
  EXPECT_EQ(c.source.path, "017");
}

TEST(ConfigStrict, KeysMustBeNames) {
  TempDir dir;
  expect_config_error(dir.write("complex.yaml", "sim:\n  ? [fps]\n  : 30\n"), {}, {"complex.yaml:2:5:", "keys must be names"});
  expect_config_error(dir.write("alias.yaml", "sim:\n  &k fps: 30\n  *k : 15\n"), {}, {"alias.yaml:3:", "an alias", "keys must be names"});
}

TEST(ConfigStrict, LeadingZerosAreRefusedForEveryNumber) {
  // yaml-cpp reads 017 as 15 for an integer key and as 17 for a real one; YAML 1.1 says 15 and
  // YAML 1.2 says 17. Refuse it rather than guess.
  EXPECT_EQ(error_of("", {"sim.frames=017"}),
            "<defaults>: key 'sim.frames': '017' has a leading zero, which YAML 1.1 reads as octal and YAML 1.2 as "
            "decimal; write 17, or 15 if the octal value was meant");
  expect_config_error("", {"safety.slow_distance_m=01"}, {"'safety.slow_distance_m'", "'01' has a leading zero", "write 1"});
  expect_config_error("", {"background.frames=-0012"}, {"'background.frames'", "write -12, or -10"});
  expect_config_error("", {"filters.threshold.max=08"}, {"'filters.threshold.max'", "write 8"});  // no octal reading
  expect_config_error("", {"sim.fps=030e0"}, {"'sim.fps'", "write 30e0"});
  expect_config_error("", {"robot.points_base=[[0, 00, 1]]"}, {"'robot.points_base'", "write 0"});
  expect_config_error("", {"scene.objects=[{color: [255, 010, 0], shapes: [{sphere: {center: [0, 0, 2], radius_m: 1}}]}]"},
                      {"scene.objects[0].color", "'010'"});
  // Written plainly they load; 0.5 and 00.5 mean the same in both YAML versions.
  const Config c = load_config("", {"sim.frames=17", "safety.slow_distance_m=00.5", "safety.stop_distance_m=0.25",
                                    "source.seed=0x1F"});
  EXPECT_EQ(c.sim.frames, 17);
  EXPECT_EQ(c.pipeline.safety.slow_distance_m, 0.5F);
  EXPECT_EQ(c.sim.seed, 31U);  // hexadecimal is the same in YAML 1.1 and 1.2
}

TEST(ConfigStrict, RobotDescriptionFilesGoThroughTheSameChecks) {
  TempDir dir;
  const std::string dup = dir.write("dup.yaml", std::string(kMinimalPostArm) + "name: other\n");
  expect_config_error("", {"robot.model=custom", "robot.description=" + dup, "robot.joints_rad=[0, 0, 0, 0, 0, 0]"},
                      {"key 'robot.description'", dup + ":11:1: duplicate key 'name' (first at line 1)"});
  const std::string two = dir.write("two.yaml", std::string(kMinimalPostArm) + "---\nname: x\n");
  try {
    (void)load_robot_description(two);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(two + ":11:1: a second YAML document", 0), 0U) << e.what();
  }
  const std::string tagged = dir.write("tag.yaml", std::string(kMinimalPostArm) + "padding_m: !cm 2\n");
  expect_config_error("", {"robot.model=custom", "robot.description=" + tagged, "robot.joints_rad=[0, 0, 0, 0, 0, 0]"},
                      {tagged + ":11:12: unknown tag '!cm' on key 'padding_m'"});
  EXPECT_NO_THROW((void)load_robot_description(dir.write("good.yaml", kMinimalPostArm)));
}

TEST(ConfigStrict, AFolderAsConfigOrDescriptionIsAConfigErrorNamingIt) {
  TempDir dir;
  // Before: "basic_filebuf::underflow error reading the file: Is a directory", naming nothing.
  EXPECT_EQ(error_of(dir.path()), dir.path() + ": cannot open configuration file: is a directory, not a file");
  expect_config_error("", {"robot.model=custom", "robot.description=" + dir.path(), "robot.joints_rad=[0, 0, 0, 0, 0, 0]"},
                      {"key 'robot.description'", dir.path() + ": cannot open robot description: is a directory"});
}

TEST(ConfigStrict, TheCliExitsWith2NamingTheFolder) {
  TempDir dir;
  // Before: exit 1 and "basic_filebuf::underflow error reading the file: Is a directory".
  test::CliResult r = test::cli("run --config " + dir.path() + " --out " + dir.path() + "/out.jsonl");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("hrcsense: error: " + dir.path() + ": cannot open configuration file: is a directory"),
            std::string::npos)
      << r.out;
  r = test::cli("run --set robot.model=custom --set robot.description=" + dir.path() +
                " --set 'robot.joints_rad=[0,0,0,0,0,0]' --out " + dir.path() + "/out.jsonl");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("key 'robot.description': " + dir.path() + ": cannot open robot description: is a directory"),
            std::string::npos)
      << r.out;
  const std::string dup = dir.write("dup.yaml", "safety: {stop_distance_m: 0.3}\nsafety: {stop_distance_m: 0.6}\n");
  r = test::cli("info --config " + dup);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find(dup + ":2:1: duplicate key 'safety'"), std::string::npos) << r.out;
}

TEST(ConfigStrict, AFifoAsConfigOrDescriptionIsRefusedWithoutBlocking) {
  TempDir dir;
  const std::string fifo = dir.path() + "/config.yaml";
  test::make_fifo(fifo);
  const auto refused = [](const std::function<void()>& load, const std::string& needle) {
    return [load, needle] {
      try {
        load();
      } catch (const ConfigError& e) {
        return test::mentions(e.what(), {needle});
      }
      return false;
    };
  };
  EXPECT_EQ(test::run_with_deadline(refused([&] { (void)load_config(fifo, {}); },
                                            fifo + ": cannot open configuration file: is a FIFO (named pipe)")),
            test::ChildOutcome::passed);
  EXPECT_EQ(test::run_with_deadline(refused([&] { (void)load_robot_description(fifo); },
                                            fifo + ": cannot open robot description: is a FIFO (named pipe)")),
            test::ChildOutcome::passed);
}

}  // namespace
}  // namespace hrcsense

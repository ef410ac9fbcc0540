// SPDX-License-Identifier: Apache-2.0
// `hrcsense teach --config FILE --out PATH` and `background.reference` at the start of a run
// (issue 30, item 6; docs/SAFETY.md, "Commissioning a cell"), on a small noise-free scene: a
// camera at the base origin looking at a wall 2 m away, a robot point 0.2 m in front of the
// wall, and in person.yaml a box (a person standing still) 0.4 m from the robot point, there
// from frame 0 to frame 20.
#include "../support/cli_folder.hpp"

#include "hrcsense/io/io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Outcome = hrcsense::test::CliOutcome;

class TeachCli : public hrcsense::test::CliFolder {
 protected:
  std::string empty_scene() const {
    return write("empty.yaml",
                 "source: {type: sim, seed: 1}\n"
                 "sim: {width: 424, height: 240, frames: 60, noise: false, color: false}\n"
                 "camera:\n"
                 "  T_base_camera: {translation_m: [0, 0, 0], rotation_rpy_deg: [0, 0, 0]}\n"
                 "filters: {preset: none}\n"
                 "background: {frames: 12}\n"
                 "robot: {model: points, points_base: [[0.3, 0, 1.8]]}\n"
                 "scene:\n"
                 "  objects:\n"
                 "    - name: wall\n"
                 "      static: true\n"
                 "      shapes:\n"
                 "        - plane: {point: [0, 0, 2.0], normal: [0, 0, 1]}\n");
  }
  std::string person_scene() const {
    empty_scene();
    return write("person.yaml", hrcsense::test::read_text(dir_ / "empty.yaml") +
                                    "    - name: person\n"
                                    "      static: false\n"
                                    "      first_frame: 0\n"
                                    "      last_frame: 20\n"
                                    "      shapes:\n"
                                    "        - box: {min: [-0.3, -0.3, 1.5], max: [-0.1, 0.3, 1.7]}\n");
  }
  std::vector<nlohmann::json> frames(const std::string& file) const {
    std::vector<nlohmann::json> lines;
    std::istringstream in(hrcsense::test::read_text(dir_ / file));
    for (std::string line; std::getline(in, line);) {
      nlohmann::json j = nlohmann::json::parse(line);
      if (j["type"] == "frame") lines.push_back(j);
    }
    return lines;
  }
};

TEST_F(TeachCli, WritesALoadableReferenceAndSaysWhere) {
  const Outcome outcome = run("teach --config " + empty_scene() + " --out cell/reference.bin");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_NE(outcome.out.find("reference background written to cell/reference.bin (424x240, learnt by frame 11)"),
            std::string::npos)
      << outcome.out;
  const hrcsense::BackgroundModel model = hrcsense::load_background((dir_ / "cell/reference.bin").string());
  EXPECT_EQ(model.width, 424);
  EXPECT_EQ(model.height, 240);
  // The wall at 2 m, learnt as a run learns it.
  EXPECT_NEAR(model.mean_m[120 * 424 + 212], 2.0F, 0.002F);
}

// background.path and background.reference in the configuration are not read by teach: the
// reference is learnt from the source even when neither file exists yet.
TEST_F(TeachCli, IgnoresBackgroundPathAndReference) {
  const Outcome outcome = run("teach --config " + empty_scene() +
                              " --set background.path=bg.bin --set background.reference=reference.bin --out reference.bin");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "reference.bin"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bg.bin"));
  EXPECT_NE(outcome.err.find("not read"), std::string::npos) << outcome.err;
}

TEST_F(TeachCli, FailsNamingTheSourceWhenItEndsBeforeTheBackgroundIsLearnt) {
  const Outcome outcome = run("teach --config " + empty_scene() + " --set sim.frames=5 --out reference.bin");
  EXPECT_EQ(outcome.exit_code, 1);
  EXPECT_NE(outcome.err.find("hrcsense: error: teach: the source (sim, "), std::string::npos) << outcome.err;
  EXPECT_NE(outcome.err.find("ended after 5 frame(s) before the background was learnt (background.frames 12"),
            std::string::npos)
      << outcome.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "reference.bin"));
  const Outcome limited = run("teach --config " + empty_scene() + " --frames 4 --out reference.bin");
  EXPECT_EQ(limited.exit_code, 1);
  EXPECT_NE(limited.err.find("stopped at --frames 4"), std::string::npos) << limited.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "reference.bin"));
}

TEST_F(TeachCli, BadArgumentsAreUsageErrors) {
  const std::string scene = empty_scene();
  EXPECT_EQ(run("teach --config " + scene).exit_code, 2);  // --out is required
  EXPECT_EQ(run("teach --config " + scene + " --out r.bin --bogus").exit_code, 2);
  EXPECT_EQ(run("teach --config missing.yaml --out r.bin").exit_code, 2);
  EXPECT_EQ(run("teach --config " + scene + " --set background.frams=3 --out r.bin").exit_code, 2);
}

TEST_F(TeachCli, RunWithoutAReferenceWarnsAtStart) {
  const Outcome outcome = run("run --config " + empty_scene() + " --frames 13 --out run.jsonl");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_NE(outcome.err.find("no background.reference: a person standing still while the background is learnt "
                             "becomes background"),
            std::string::npos)
      << outcome.err;
  EXPECT_NE(outcome.err.find("hrcsense teach"), std::string::npos) << outcome.err;
}

TEST_F(TeachCli, ReferenceAndPathTogetherIgnoreThePathWithAWarning) {
  const std::string scene = empty_scene();
  ASSERT_EQ(run("teach --config " + scene + " --out reference.bin").exit_code, 0);
  const Outcome outcome = run("run --config " + scene +
                              " --set background.reference=reference.bin --set background.path=bg.bin --frames 14 "
                              "--out run.jsonl");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  EXPECT_NE(outcome.err.find("background.path 'bg.bin' is ignored"), std::string::npos) << outcome.err;
  EXPECT_EQ(outcome.err.find("no background.reference"), std::string::npos) << outcome.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "bg.bin"));  // neither loaded nor saved
  // The empty cell against its reference: learnt by frame 11, then measured.
  const std::vector<nlohmann::json> lines = frames("run.jsonl");
  ASSERT_EQ(lines.size(), 14U);
  EXPECT_EQ(lines[11]["reason_code"], "learning_background");
  EXPECT_EQ(lines[12]["verdict"], "run");
  EXPECT_EQ(lines[13]["verdict"], "run");
}

TEST_F(TeachCli, MissingDamagedOrMismatchedReferenceIsAnErrorNamingIt) {
  const std::string scene = empty_scene();
  const Outcome missing = run("run --config " + scene + " --set background.reference=nowhere.bin --frames 3");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("key 'background.reference': no such file 'nowhere.bin'"), std::string::npos)
      << missing.err;

  write("damaged.bin", "HRCSBKGD not a background");
  const Outcome damaged = run("run --config " + scene + " --set background.reference=damaged.bin --frames 3");
  EXPECT_EQ(damaged.exit_code, 1);
  EXPECT_NE(damaged.err.find("hrcsense: error: damaged.bin: "), std::string::npos) << damaged.err;

  // Taught without filters (424x240), run with the sdk chain (decimation x2: 212x120).
  ASSERT_EQ(run("teach --config " + scene + " --out reference.bin").exit_code, 0);
  const Outcome other_size =
      run("run --config " + scene + " --set background.reference=reference.bin --set filters.preset=sdk --frames 3");
  EXPECT_EQ(other_size.exit_code, 1);
  EXPECT_NE(other_size.err.find("reference.bin: reference background is 424x240 but the filtered source is 212x120"),
            std::string::npos)
      << other_size.err;
}

// End to end: the person stands 0.4 m from the robot while the first batch is learnt.
TEST_F(TeachCli, APersonInTheFirstBatchStopsTheRunWithBackgroundNotEmpty) {
  ASSERT_EQ(run("teach --config " + empty_scene() + " --out reference.bin").exit_code, 0);
  const std::string scene = person_scene();
  // Without the reference (today's behaviour) the person is learnt and frames 12-20 say run.
  ASSERT_EQ(run("run --config " + scene + " --frames 21 --out plain.jsonl").exit_code, 0);
  const std::vector<nlohmann::json> plain = frames("plain.jsonl");
  ASSERT_EQ(plain.size(), 21U);
  for (size_t i = 12; i < 21; ++i) EXPECT_EQ(plain[i]["verdict"], "run") << i;

  const Outcome outcome =
      run("run --config " + scene + " --set background.reference=reference.bin --out checked.jsonl");
  ASSERT_EQ(outcome.exit_code, 0) << outcome.err;
  const std::vector<nlohmann::json> lines = frames("checked.jsonl");
  ASSERT_EQ(lines.size(), 60U);
  // Frame 11 completes the first batch: refused, naming the box and its depth (its front face is
  // 1.5 m from the camera, a side face reaches back to 1.7 m).
  EXPECT_EQ(lines[11]["reason_code"], "background_not_empty");
  const std::string reason = lines[11]["verdict_reason"];
  EXPECT_NE(reason.find("background not empty: 1 object(s) nearer than background.reference 'reference.bin'"),
            std::string::npos)
      << reason;
  EXPECT_NE(reason.find("pixels u "), std::string::npos) << reason;
  EXPECT_NE(reason.find(" m from the camera"), std::string::npos) << reason;
  // Every frame stops until a batch without the person is learnt; then the cell runs.
  size_t first_run = lines.size();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (lines[i]["verdict"] == "run") {
      first_run = i;
      break;
    }
    EXPECT_EQ(lines[i]["verdict"], "stop") << i;
  }
  EXPECT_GT(first_run, 20U);  // the person leaves after frame 20
  EXPECT_LT(first_run, 40U);  // a batch of 12 clean frames follows within 12-23 frames
  // The frame that completes the accepted batch is a learning frame like the ones before it.
  for (size_t i = 11; i + 1 < first_run; ++i) EXPECT_EQ(lines[i]["reason_code"], "background_not_empty") << i;
  EXPECT_EQ(lines[first_run - 1]["reason_code"], "learning_background");
  for (size_t i = first_run; i < lines.size(); ++i) EXPECT_EQ(lines[i]["verdict"], "run") << i;
}

}  // namespace

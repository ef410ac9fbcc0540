// SPDX-License-Identifier: Apache-2.0
// link.rtde.write: speed_slider in safety.mode: ssm (issue 30, item 5). The controller keeps the
// slider at its last value when hrcsense dies, so the pair is refused unless
// link.rtde.slider_unguarded_ok says the robot guards it; zones mode and the register path are
// unaffected, and every shipped scene still loads.
#include "config_test_util.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::expect_config_error;
using test::TempDir;

// The closed-form stopping data confirmed: a live cell is refused without (safety_config_test.cpp).
constexpr const char* kSliderInSsm = R"(robot: {state: {host: 127.0.0.1}}
safety: {mode: ssm, stopping_data_confirmed: true}
link: {rtde: {write: speed_slider}}
)";

TEST(RtdeSliderConfig, SliderInSsmModeIsRefusedNamingBothKeysAndTheFile) {
  const TempDir dir;
  const std::string path = dir.write("slider_ssm.yaml", kSliderInSsm);
  expect_config_error(path, {},
                      {path, "'link.rtde.write'", "'safety.mode'", "link.rtde.slider_unguarded_ok", "register"});
  // The same through --set, on a file that says neither.
  const std::string plain = dir.write("plain.yaml", "robot: {state: {host: 127.0.0.1}}\n");
  expect_config_error(plain, {"safety.mode=ssm", "link.rtde.write=speed_slider"},
                      {plain, "'link.rtde.write'", "'safety.mode'"});
  // An explicit false is the default: still refused.
  expect_config_error(path, {"link.rtde.slider_unguarded_ok=false"}, {path, "'link.rtde.write'", "'safety.mode'"});
}

TEST(RtdeSliderConfig, AcknowledgedSliderInSsmModeLoads) {
  const TempDir dir;
  const std::string path = dir.write("slider_ssm_ok.yaml", std::string(kSliderInSsm) +
                                                               "# the robot pauses the program when the slider "
                                                               "input is not refreshed (docs/SAFETY.md)\n");
  const Config config = load_config(path, {"link.rtde.slider_unguarded_ok=true"});
  EXPECT_EQ(config.link.rtde_write, RtdeWrite::speed_slider);
  EXPECT_TRUE(config.link.rtde_slider_unguarded_ok);
  EXPECT_EQ(config.pipeline.safety.mode, SafetyParams::Mode::ssm);
  // The key is part of the effective configuration (and so of config_hash).
  EXPECT_NE(config.canonical_yaml.find("slider_unguarded_ok: true"), std::string::npos) << config.canonical_yaml;
}

TEST(RtdeSliderConfig, DefaultIsFalseAndOtherCombinationsNeedNoAcknowledgement) {
  EXPECT_FALSE(LinkConfig{}.rtde_slider_unguarded_ok);
  EXPECT_FALSE(load_config("", {}).link.rtde_slider_unguarded_ok);
  const std::vector<std::string> host = {"robot.state.host=127.0.0.1", "safety.stopping_data_confirmed=true"};
  const auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), host.begin(), host.end());
    return load_config("", extra);
  };
  // zones mode: the slider is allowed (the scale is not the protection there).
  EXPECT_EQ(with({"link.rtde.write=speed_slider"}).link.rtde_write, RtdeWrite::speed_slider);
  // ssm with the register path (a URScript watchdog stops the program): allowed.
  EXPECT_EQ(with({"safety.mode=ssm", "link.rtde.write=register"}).link.rtde_write, RtdeWrite::input_register);
  // ssm without RTDE writing: allowed.
  EXPECT_EQ(with({"safety.mode=ssm"}).link.rtde_write, RtdeWrite::off);
  // A value that is not a boolean names the key.
  expect_config_error("", {"link.rtde.slider_unguarded_ok=maybe"}, {"link.rtde.slider_unguarded_ok"});
}

TEST(RtdeSliderConfig, ShippedScenesStillLoad) {
  const std::filesystem::path folder = std::filesystem::path(HRCSENSE_SOURCE_DIR) / "config";
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".yaml") continue;
    ++scenes;
    EXPECT_NO_THROW((void)load_config(entry.path().string(), {})) << entry.path().filename();
  }
  EXPECT_GE(scenes, 6);
}

}  // namespace
}  // namespace hrcsense

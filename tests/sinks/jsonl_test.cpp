// SPDX-License-Identifier: Apache-2.0
// Tests of JsonLinesSink: each line parses back (nlohmann) with every binding field.
#include "hrcsense/sinks/sinks.hpp"

#include "hrcsense/safety.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using nlohmann::json;

std::vector<json> parse_lines(const std::string& text) {
  std::vector<json> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) lines.push_back(json::parse(line));
  return lines;
}

void expect_vec3(const json& value, const Eigen::Vector3f& expected) {
  ASSERT_TRUE(value.is_array()) << value;
  ASSERT_EQ(value.size(), 3U);
  for (int i = 0; i < 3; ++i) {
    // Written floats read back to the same float: far below 0.1 mm.
    EXPECT_EQ(static_cast<float>(value[static_cast<size_t>(i)].get<double>()), expected[i]) << value;
  }
}

FrameResult contact_result() {
  FrameResult r;
  r.frame = 123;
  r.timestamp_ns = 4'100'000'001;
  r.valid = true;
  r.verdict.state = VerdictState::slow;
  r.verdict.speed_scale = 0.4375F;
  r.verdict.reason = "person at \"0.72 m\"\n";
  r.contact.valid = true;
  r.contact.distance_m = 0.7234567F;
  r.contact.closest_camera = {0.1234567F, -0.25F, 1.0001F};
  r.contact.closest_base = {-1.5F, 2.0000999F, 0.3F};
  r.contact.closest_robot_base = {-0.5F, -0.5F, 0.5F};
  r.contact.robot_link = 3;
  r.foreground_points = 1492;
  r.invalid_pixels = 17;
  r.latency_us = 812.5;
  r.timings = {{"foreground", 700.25}, {"proximity", 4.5}};
  r.host_time_ns = 9'000'000'123;
  r.robot_state.valid = true;
  r.robot_state.q_rad = {2.2, -1.5, 1.4, -1.7, -1.5708, 0.125};
  r.robot_state_age_ms = 3.5;
  Contact truth;
  truth.valid = true;
  truth.distance_m = 0.725F;
  truth.closest_base = {-1.5F, 2.0F, 0.301F};
  r.truth = truth;
  return r;
}

TEST(JsonLinesSink, HeaderCarriesVersionSourceAndIntrinsics) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  RunHeader header;
  header.version = "9.8.7";
  header.commit = "abc123";
  header.config_hash = "0123456789abcdef";
  header.robot_state = "udp_json";
  header.unknown_background_share = 0.125;
  header.source.type = "sim";
  header.source.description = "a scene";
  header.source.frame_count = 400;
  header.source.nominal_fps = 30.0;
  header.source.stereo_baseline_mm = 49.864F;
  Intrinsics& in = header.source.intrinsics;
  in.width = 848;
  in.height = 480;
  in.fx = 418.2654F;
  in.fy = 418.2655F;
  in.ppx = 424.1575F;
  in.ppy = 238.2404F;
  in.model = Distortion::brown_conrady;
  in.coeffs = {0.1F, -0.2F, 0.0F, 0.0F, 0.05F};
  sink.header(header);

  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 1U);
  const json& h = lines[0];
  EXPECT_EQ(h["type"], "header");
  EXPECT_EQ(h["version"], "9.8.7");
  EXPECT_EQ(h["commit"], "abc123");
  EXPECT_EQ(h["config_hash"], "0123456789abcdef");
  // Every output says what hrcsense is not (issue G2).
  EXPECT_NE(h["safety_notice"].get<std::string>().find("not a safety-rated device"), std::string::npos);
  EXPECT_EQ(h["robot_state"], "udp_json");
  EXPECT_EQ(h["unknown_background_share"].get<double>(), 0.125);
  EXPECT_EQ(h["source"]["type"], "sim");
  EXPECT_EQ(h["source"]["description"], "a scene");
  EXPECT_EQ(h["source"]["frame_count"], 400);
  EXPECT_EQ(h["source"]["nominal_fps"], 30.0);
  EXPECT_EQ(h["source"]["stereo_baseline_mm"].get<float>(), 49.864F);
  const json& i = h["intrinsics"];
  EXPECT_EQ(i["width"], 848);
  EXPECT_EQ(i["height"], 480);
  EXPECT_EQ(i["fx"].get<float>(), 418.2654F);
  EXPECT_EQ(i["fy"].get<float>(), 418.2655F);
  EXPECT_EQ(i["ppx"].get<float>(), 424.1575F);
  EXPECT_EQ(i["ppy"].get<float>(), 238.2404F);
  EXPECT_EQ(i["model"], "Brown Conrady");  // the SDK's name
  ASSERT_EQ(i["coeffs"].size(), 5U);
  EXPECT_EQ(i["coeffs"][0].get<float>(), 0.1F);
  EXPECT_EQ(i["coeffs"][1].get<float>(), -0.2F);
  EXPECT_EQ(i["coeffs"][4].get<float>(), 0.05F);
  EXPECT_FALSE(h["source"].contains("serial"));  // not a camera: no device keys
}

TEST(JsonLinesSink, HeaderNamesTheLiveCamera) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  RunHeader header;
  header.source.type = "realsense";
  header.source.camera_name = "Intel RealSense D435";
  header.source.camera_serial = "012345678901";
  header.source.camera_firmware = "5.13.0.50";
  sink.header(header);
  const json h = json::parse(out.str());
  EXPECT_EQ(h["source"]["name"], "Intel RealSense D435");
  EXPECT_EQ(h["source"]["serial"], "012345678901");  // a string: serials keep their leading zero
  EXPECT_EQ(h["source"]["firmware"], "5.13.0.50");
  // Not a simulated sensor: no model, written as null (the key is always there).
  ASSERT_TRUE(h["source"].contains("sensor_model"));
  EXPECT_TRUE(h["source"]["sensor_model"].is_null());
}

TEST(JsonLinesSink, HeaderNamesTheSimulatedSensorModel) {
  for (const std::string model : {"d435", "structured_light"}) {
    std::ostringstream out;
    JsonLinesSink sink(out);
    RunHeader header;
    header.source.type = "sim";
    header.source.sensor_model = model;
    sink.header(header);
    const json h = json::parse(out.str());
    EXPECT_EQ(h["source"]["sensor_model"], model);
  }
}

TEST(JsonLinesSink, FrameWithContactHasEveryField) {
  std::ostringstream out;
  JsonLinesSink sink(out, "brute");
  sink.frame(contact_result());
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 1U);
  const json& f = lines[0];
  EXPECT_EQ(f["type"], "frame");
  EXPECT_EQ(f["frame"], 123);
  EXPECT_EQ(f["timestamp_ns"].get<int64_t>(), 4'100'000'001);
  EXPECT_EQ(f["timestamp_s"].get<double>(), 4.100000001);
  EXPECT_EQ(f["valid"], true);
  EXPECT_EQ(f["verdict"], "slow");
  EXPECT_EQ(f["verdict_reason"], "person at \"0.72 m\"\n");  // escaped and read back
  EXPECT_EQ(f["speed_scale"].get<double>(), 0.4375);
  EXPECT_EQ(f["distance_m"].get<float>(), 0.7234567F);
  expect_vec3(f["closest_camera"], {0.1234567F, -0.25F, 1.0001F});
  expect_vec3(f["closest_base"], {-1.5F, 2.0000999F, 0.3F});
  expect_vec3(f["closest_robot_base"], {-0.5F, -0.5F, 0.5F});
  EXPECT_EQ(f["robot_link"], 3);
  EXPECT_EQ(f["backend"], "brute");
  EXPECT_EQ(f["foreground_points"], 1492);
  EXPECT_EQ(f["invalid_pixels"], 17);
  EXPECT_EQ(f["latency_us"].get<double>(), 812.5);
  ASSERT_EQ(f["timings_us"].size(), 2U);
  EXPECT_EQ(f["timings_us"]["foreground"].get<double>(), 700.25);
  EXPECT_EQ(f["timings_us"]["proximity"].get<double>(), 4.5);
  EXPECT_EQ(f["truth"]["distance_m"].get<float>(), 0.725F);
  expect_vec3(f["truth"]["closest_base"], {-1.5F, 2.0F, 0.301F});
  EXPECT_EQ(f["host_time_ns"].get<int64_t>(), 9'000'000'123);
  EXPECT_EQ(f["joints_rad"].get<std::vector<double>>(), (std::vector<double>{2.2, -1.5, 1.4, -1.7, -1.5708, 0.125}));
  EXPECT_EQ(f["robot_state_age_ms"].get<double>(), 3.5);
}

// S2's fields: the ssm terms with T_r's parts (which add up to reaction_time_s), Z_r's part from
// the robot state's age, unknown_margin_m, and the header's stopping_data (null in zones mode).
TEST(JsonLinesSink, SsmTermsCarryTheReactionTimesPartsAndTheUnknownMargin) {
  std::ostringstream out;
  JsonLinesSink sink(out, "brute");
  FrameResult r = contact_result();
  SsmTerms t;
  t.frame_age_s = 0.03;
  t.frame_period_s = 0.0625;
  t.source_latency_s = 0.033;
  t.controller_latency_s = 0.05;
  t.receiver_timeout_s = 0.2;
  t.reaction_time_s = 0.375;
  t.z_r_m = 0.04F;
  t.z_r_state_m = 0.03F;
  r.ssm = t;
  r.unknown_distance_m = 1.25F;
  r.unknown_margin_m = -0.125F;
  sink.frame(r);
  const json f = json::parse(out.str());
  const json& parts = f["ssm"]["reaction_time_parts"];
  EXPECT_EQ(parts["frame_age_s"].get<double>(), 0.03);
  EXPECT_EQ(parts["frame_period_s"].get<double>(), 0.0625);
  EXPECT_EQ(parts["source_latency_s"].get<double>(), 0.033);
  EXPECT_EQ(parts["controller_latency_s"].get<double>(), 0.05);
  EXPECT_EQ(parts["receiver_timeout_s"].get<double>(), 0.2);
  EXPECT_EQ(f["ssm"]["reaction_time_s"].get<double>(), 0.375);
  EXPECT_EQ(f["ssm"]["z_r_state_m"].get<float>(), 0.03F);
  EXPECT_EQ(f["unknown_margin_m"].get<float>(), -0.125F);
  // Without unknown space: null.
  std::ostringstream none;
  JsonLinesSink second(none, "brute");
  second.frame(contact_result());
  EXPECT_TRUE(json::parse(none.str())["unknown_margin_m"].is_null());
  // The header: where S_s comes from in ssm mode, null in zones mode (an empty name).
  for (const char* data : {"table", ""}) {
    std::ostringstream head;
    JsonLinesSink header_sink(head, "brute");
    RunHeader header;
    header.stopping_data = data;
    header_sink.header(header);
    const json h = json::parse(head.str());
    if (*data != '\0') {
      EXPECT_EQ(h["stopping_data"], data);
    } else {
      EXPECT_TRUE(h["stopping_data"].is_null());
    }
  }
}

// truth.contact_label is the extras' answer, asked only for a frame with a truth and a measured
// contact; without a labeller (any source but the simulator) it is null.
TEST(JsonLinesSink, ContactLabelComesFromTheExtrasOnlyForAMeasuredContact) {
  std::ostringstream out;
  int asked = 0;
  JsonLinesExtras extras;
  extras.contact_label = [&asked](const FrameResult&) {
    ++asked;
    return "person";
  };
  JsonLinesSink labelled(out, "brute", extras);
  FrameResult r = contact_result();
  labelled.frame(r);
  r.contact.valid = false;
  labelled.frame(r);
  JsonLinesSink plain(out);
  plain.frame(contact_result());
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 3U);
  EXPECT_EQ(lines[0]["truth"]["contact_label"], "person");
  EXPECT_TRUE(lines[1]["truth"]["contact_label"].is_null());
  EXPECT_TRUE(lines[2]["truth"]["contact_label"].is_null());
  EXPECT_EQ(asked, 1);
}

TEST(JsonLinesSink, FrameWithoutContactWritesNulls) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  FrameResult r = contact_result();
  r.contact.valid = false;
  r.truth->valid = false;
  r.timings.clear();
  r.timestamp_ns = 3'000'000'000;
  r.robot_state.valid = false;
  sink.frame(r);
  r.truth.reset();  // a source without ground truth: no truth member at all
  sink.frame(r);
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 2U);
  const json& f = lines[0];
  EXPECT_EQ(f["timestamp_s"].get<double>(), 3.0);
  for (const char* key : {"distance_m", "closest_camera", "closest_base", "closest_robot_base", "robot_link"}) {
    ASSERT_TRUE(f.contains(key)) << key;
    EXPECT_TRUE(f[key].is_null()) << key;
  }
  EXPECT_TRUE(f["timings_us"].is_object());
  EXPECT_TRUE(f["timings_us"].empty());
  EXPECT_TRUE(f["truth"]["distance_m"].is_null());
  EXPECT_TRUE(f["truth"]["closest_base"].is_null());
  EXPECT_FALSE(lines[1].contains("truth"));
  EXPECT_TRUE(f["joints_rad"].is_null());  // no valid robot state
}

TEST(JsonLinesSink, SummaryHasEveryRunSummaryField) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  RunSummary s;
  s.frames_in = 130;
  s.frames_processed = 129;
  s.frames_dropped = 1;
  s.frames_dropped_camera = 4;
  s.frames_valid = 110;
  s.verdict_run = 100;
  s.verdict_slow = 9;
  s.verdict_stop = 20;
  s.wall_s = 2.5;
  s.fps = 51.6;
  s.latency_p50_us = 1019.25;
  s.latency_p99_us = 1941.75;
  s.min_distance_m = 1.2196938F;
  s.end_reason = "end of source";
  s.timestamps.backwards = 2;
  s.timestamps.repeated = 3;
  s.timestamps.gaps = 4;
  s.timestamps.frames_skipped = 9;
  s.timestamps.jumps = 1;
  s.unknown_background_share = 0.0625;
  s.robot_state.samples.accepted = 1000;
  s.robot_state.samples.rejected_non_finite = 1;
  s.robot_state.samples.rejected_backwards = 2;
  s.robot_state.samples.rejected_jump = 3;
  s.robot_state.samples.rejected_limits = 4;
  s.robot_state.connections = 2;
  s.robot_state.disconnects = 1;
  s.robot_state.malformed = 4;
  s.robot_state.last_problem = "127.0.0.1:40000: q: expected 6 numbers";
  sink.summary(s);
  s.min_distance_m = -1.0F;
  s.error = "processing error: std::bad_alloc";
  sink.summary(s);
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 2U);
  const json& j = lines[0];
  EXPECT_EQ(j["type"], "summary");
  EXPECT_EQ(j["frames_in"], 130);
  EXPECT_EQ(j["frames_processed"], 129);
  EXPECT_EQ(j["frames_dropped"], 1);
  EXPECT_EQ(j["frames_dropped_camera"], 4);
  EXPECT_EQ(j["frames_valid"], 110);
  EXPECT_EQ(j["verdict_run"], 100);
  EXPECT_EQ(j["verdict_slow"], 9);
  EXPECT_EQ(j["verdict_stop"], 20);
  EXPECT_EQ(j["wall_s"].get<double>(), 2.5);
  EXPECT_EQ(j["fps"].get<double>(), 51.6);
  EXPECT_EQ(j["latency_p50_us"].get<double>(), 1019.25);
  EXPECT_EQ(j["latency_p99_us"].get<double>(), 1941.75);
  EXPECT_EQ(j["min_distance_m"].get<float>(), 1.2196938F);
  EXPECT_EQ(j["end_reason"], "end of source");
  EXPECT_TRUE(j["error"].is_null());  // the run ended normally
  EXPECT_EQ(j["end_reason_code"], "source_ended");
  EXPECT_EQ(j["timestamps_backwards"], 2);
  EXPECT_EQ(j["timestamps_repeated"], 3);
  EXPECT_EQ(j["timestamp_gaps"], 4);
  EXPECT_EQ(j["frames_skipped_source"], 9);
  EXPECT_EQ(j["timestamp_jumps"], 1);
  EXPECT_EQ(j["unknown_background_share"].get<double>(), 0.0625);
  const json& robot = j["robot_state"];
  EXPECT_EQ(robot["accepted"], 1000);
  EXPECT_EQ(robot["rejected_non_finite"], 1);
  EXPECT_EQ(robot["rejected_backwards"], 2);
  EXPECT_EQ(robot["rejected_jump"], 3);
  EXPECT_EQ(robot["rejected_limits"], 4);
  EXPECT_EQ(robot["connections"], 2);
  EXPECT_EQ(robot["disconnects"], 1);
  EXPECT_EQ(robot["malformed"], 4);
  EXPECT_EQ(robot["last_problem"], "127.0.0.1:40000: q: expected 6 numbers");
  EXPECT_TRUE(lines[1]["min_distance_m"].is_null());  // never any foreground
  EXPECT_EQ(lines[1]["error"], "processing error: std::bad_alloc");
}

// R1 item 4: each line reaches the file descriptor when it is written, not when a buffer of
// a few kilobytes fills: read back through a pipe right after each call, without closing.
TEST(JsonLinesSink, EveryLineIsFlushedAtOnce) {
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  ASSERT_EQ(::fcntl(fds[0], F_SETFL, O_NONBLOCK), 0);
  std::ofstream file("/dev/fd/" + std::to_string(fds[1]));
  ASSERT_TRUE(file.is_open());
  JsonLinesSink sink(file);
  auto available = [&] {
    std::string text;
    char buffer[65536];
    for (ssize_t n; (n = ::read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<size_t>(n));
    return text;
  };
  RunHeader header;
  header.version = "test";
  sink.header(header);
  EXPECT_EQ(json::parse(available())["type"], "header");
  FrameResult result;
  result.verdict = stop_verdict(ReasonCode::learning_background, "learning background (1/100 frames)");
  sink.frame(result);
  const std::string frame_line = available();
  ASSERT_FALSE(frame_line.empty()) << "the frame line is still in the stream's buffer";
  EXPECT_EQ(frame_line.back(), '\n');
  EXPECT_EQ(json::parse(frame_line)["verdict"], "stop");
  EXPECT_EQ(json::parse(frame_line)["reason_code"], "learning_background");
  EXPECT_FALSE(sink.failed());
  file.close();
  ::close(fds[0]);
  ::close(fds[1]);
}

// R1 item 5: a stream that fails (the reader left) makes the sink report it, so the run ends.
TEST(JsonLinesSink, FailedStreamIsReported) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  EXPECT_FALSE(sink.failed());
  out.setstate(std::ios::badbit);
  sink.frame(FrameResult{});
  EXPECT_TRUE(sink.failed());
  EXPECT_EQ(sink.failure(), "write failed");
}

TEST(JsonLinesSink, NonFiniteNumbersBecomeNull) {
  std::ostringstream out;
  JsonLinesSink sink(out);
  FrameResult r = contact_result();
  r.contact.distance_m = std::numeric_limits<float>::quiet_NaN();
  sink.frame(r);
  const json f = json::parse(out.str());
  EXPECT_TRUE(f["distance_m"].is_null());
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// A stop that stands for no new source frame is its own line type, so frames can be counted.
TEST(JsonLinesSink, VerdictWithoutSourceFrameHasItsOwnType) {
  std::ostringstream out;
  JsonLinesSink sink(out, "brute");
  FrameResult result;
  result.frame = 7;
  result.source_frame = false;
  result.verdict = stop_verdict(ReasonCode::source_ended, "source ended");
  sink.frame(result);
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 1U);
  EXPECT_EQ(lines[0]["type"], "verdict");
  EXPECT_EQ(lines[0]["frame"], 7);
  EXPECT_EQ(lines[0]["verdict"], "stop");
  EXPECT_EQ(lines[0]["verdict_reason"], "source ended");
}

// The controller's status (rtde): announced in the header, one object per frame that has it,
// null in one that has not, and its counters in the summary's robot_state.
TEST(JsonLinesSink, RobotStatusInHeaderFramesAndSummary) {
  std::ostringstream out;
  JsonLinesSink sink(out, "brute");
  RunHeader header;
  header.robot_state = "rtde";
  header.robot_state_reports = {"robot_status", "tcp_pose_check"};
  sink.header(header);
  FrameResult result;
  result.robot_state.valid = true;
  result.robot_state.status.known = true;
  result.robot_state.status.robot_mode = 7;
  result.robot_state.status.safety_mode = 3;
  result.robot_state.status.speed_scaling = 0.25;
  result.robot_state.status.tcp_pose_mismatch = true;
  sink.frame(result);
  result.robot_state = RobotState{};  // stale: no status
  sink.frame(result);
  RunSummary summary;
  summary.robot_status.frames_reported = 10;
  summary.robot_status.frames_not_running = 4;
  summary.robot_status.frames_protective_stop = 3;
  summary.robot_status.mode_changes = 2;
  summary.robot_status.frames_tcp_pose_mismatch = 1;
  sink.summary(summary);

  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 4U);
  EXPECT_EQ(lines[0]["robot_state"], "rtde");
  EXPECT_EQ(lines[0]["robot_state_reports"], json::array({"robot_status", "tcp_pose_check"}));
  const json& status = lines[1]["robot_status"];
  EXPECT_EQ(status["robot_mode"], 7);
  EXPECT_EQ(status["robot_mode_name"], "running");
  EXPECT_EQ(status["safety_mode"], 3);
  EXPECT_EQ(status["safety_mode_name"], "protective_stop");
  EXPECT_EQ(status["speed_scaling"].get<double>(), 0.25);
  EXPECT_EQ(status["tcp_pose_mismatch"], true);
  ASSERT_TRUE(lines[2].contains("robot_status"));
  EXPECT_TRUE(lines[2]["robot_status"].is_null());
  const json& robot = lines[3]["robot_state"];
  EXPECT_EQ(robot["frames_with_status"], 10);
  EXPECT_EQ(robot["frames_not_running"], 4);
  EXPECT_EQ(robot["frames_protective_stop"], 3);
  EXPECT_EQ(robot["mode_changes"], 2);
  EXPECT_EQ(robot["frames_tcp_pose_mismatch"], 1);
}

// A source without a status (fixed, sim, udp_json) writes no robot_status key at all.
TEST(JsonLinesSink, NoRobotStatusKeyForSourcesWithoutOne) {
  std::ostringstream out;
  JsonLinesSink sink(out, "brute");
  RunHeader header;
  header.robot_state = "sim";
  sink.header(header);
  sink.frame(FrameResult{});
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 2U);
  EXPECT_EQ(lines[0]["robot_state_reports"], json::array());
  EXPECT_FALSE(lines[1].contains("robot_status"));
}

// `run --record`: the recorder's counters as their own object, apart from the pipeline's
// frames_dropped; null when the run recorded nothing.
TEST(JsonLinesSink, SummaryHasTheRecordersCountersOrNull) {
  std::ostringstream out;
  AppCounters app;  // what the extras report at each summary
  JsonLinesExtras extras;
  extras.app_counters = [&app] { return app; };
  JsonLinesSink sink(out, "brute", extras);
  RunSummary summary;
  summary.frames_dropped = 2;
  sink.summary(summary);
  app.record = RecordCounters{297, 3, {"rec/a-000.bag", "rec/\"b\"-001.bag"}, ""};
  sink.summary(summary);
  app.record->error = "rec/a-001.bag: write failed at byte 5: No space left on device";
  sink.summary(summary);
  const std::vector<json> lines = parse_lines(out.str());
  ASSERT_EQ(lines.size(), 3U);
  ASSERT_TRUE(lines[0].contains("record"));
  EXPECT_TRUE(lines[0]["record"].is_null());
  const json& record = lines[1]["record"];
  EXPECT_EQ(record["frames_recorded"], 297);
  EXPECT_EQ(record["frames_dropped"], 3);
  EXPECT_EQ(record["files"], json::array({"rec/a-000.bag", "rec/\"b\"-001.bag"}));
  EXPECT_TRUE(record["error"].is_null());
  EXPECT_EQ(lines[1]["frames_dropped"], 2);
  EXPECT_EQ(lines[2]["record"]["error"], "rec/a-001.bag: write failed at byte 5: No space left on device");
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// link.rtde.write: the input packages against bytes laid out by hand from
// ../shared/specs/ur-rtde.md, and RtdeLinkSink against the fake controller's input session
// (tests/net/fake_rtde_controller.hpp) on 127.0.0.1: what arrives (the recipe, the values, the
// stops), IN_USE refusals, malformed replies, a lost connection, and what a reconnect writes
// first (never a value older than one heartbeat period). Every wait is bounded.
#include "../support/units.hpp"
#include "cli_cell.hpp"
#include "fake_rtde_controller.hpp"

#include "hrcsense/clock.hpp"
#include "src/net/rtde_protocol.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <memory>
#include <ostream>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

namespace hrcsense {
namespace {

using test::FakeInputWrite;
using test::FakeRtdeController;
using test::FakeRtdeScript;
using test::RtdeFault;

using test::kMs;

// Waits (real time, at most `seconds`, looking every millisecond) until `done()`.
bool eventually(const std::function<bool()>& done, double seconds = 5.0) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (!done()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

FrameResult verdict(VerdictState state, float scale) {
  FrameResult r;
  r.verdict.state = state;
  r.verdict.speed_scale = scale;
  return r;
}

RtdeLinkParams params_for(const FakeRtdeController& fake, RtdeLinkParams::Mode mode) {
  RtdeLinkParams params;
  params.host = "127.0.0.1";
  params.port = fake.port();
  params.mode = mode;
  params.heartbeat_hz = 10.0;  // 100 ms on the fake clock
  return params;
}

// ---- The packages

TEST(RtdeWriteEncode, SetupInputsAndDataPackageByteForByte) {
  // "speed_slider_mask,speed_slider_fraction": 17 + 1 + 21 = 39 bytes; size 42 = 0x2A.
  const std::vector<uint8_t> setup = rtde::encode_setup_inputs("speed_slider_mask,speed_slider_fraction");
  ASSERT_EQ(setup.size(), 42U);
  EXPECT_EQ(setup[0], 0x00);
  EXPECT_EQ(setup[1], 0x2A);
  EXPECT_EQ(setup[2], 0x49);  // 'I'
  EXPECT_EQ(std::string(setup.begin() + 3, setup.end()), "speed_slider_mask,speed_slider_fraction");
  EXPECT_THROW(rtde::encode_setup_inputs(std::string(2049, 'a')), std::invalid_argument);

  // Recipe 3: UINT32 1, DOUBLE 0.5 (0x3FE0000000000000); size 3 + 1 + 4 + 8 = 16.
  rtde::InputValue mask;
  mask.type = rtde::InputValue::Type::uint32;
  mask.u32 = 1;
  rtde::InputValue fraction;
  fraction.f64 = 0.5;
  const std::vector<uint8_t> data = rtde::encode_input_data(3, {mask, fraction});
  const std::vector<uint8_t> expected = {0x00, 0x10, 0x55, 0x03, 0x00, 0x00, 0x00, 0x01,
                                         0x3F, 0xE0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(data, expected);
  // One DOUBLE 0.25 (0x3FD0000000000000): size 12.
  fraction.f64 = 0.25;
  const std::vector<uint8_t> one = {0x00, 0x0C, 0x55, 0x01, 0x3F, 0xD0, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  EXPECT_EQ(rtde::encode_input_data(1, {fraction}), one);
}

TEST(RtdeWriteEncode, InputSetupRepliesAreCheckedNamingTheInput) {
  // The spec's worked reply: recipe 1, "UINT32,DOUBLE".
  const std::vector<uint8_t> bytes = {0x00, 0x11, 0x49, 0x01, 0x55, 0x49, 0x4E, 0x54, 0x33,
                                      0x32, 0x2C, 0x44, 0x4F, 0x55, 0x42, 0x4C, 0x45};
  const rtde::PackageSplit split = rtde::split_package(bytes.data(), bytes.size());
  ASSERT_EQ(split.status, rtde::SplitStatus::package);
  rtde::SetupReply reply;
  std::string error;
  ASSERT_TRUE(rtde::parse_setup_reply(split.package, rtde::PackageType::setup_inputs, reply, error)) << error;
  const std::string slider = "speed_slider_mask,speed_slider_fraction";
  EXPECT_TRUE(rtde::check_input_setup(reply, slider, {"UINT32", "DOUBLE"}, error)) << error;

  reply.types = {"IN_USE", "DOUBLE"};
  EXPECT_FALSE(rtde::check_input_setup(reply, slider, {"UINT32", "DOUBLE"}, error));
  EXPECT_EQ(error,
            "CONTROL_PACKAGE_SETUP_INPUTS: input 'speed_slider_mask' is IN_USE: another RTDE client (UR's ROS "
            "driver, a fieldbus adapter) already writes it");
  reply.types = {"UINT32", "NOT_FOUND"};
  EXPECT_FALSE(rtde::check_input_setup(reply, slider, {"UINT32", "DOUBLE"}, error));
  EXPECT_EQ(error, "CONTROL_PACKAGE_SETUP_INPUTS: input 'speed_slider_fraction' NOT_FOUND on this controller");
  reply.types = {"UINT32", "INT32"};
  EXPECT_FALSE(rtde::check_input_setup(reply, slider, {"UINT32", "DOUBLE"}, error));
  EXPECT_EQ(error, "CONTROL_PACKAGE_SETUP_INPUTS: input 'speed_slider_fraction' is 'INT32', expected DOUBLE");
  reply.types = {"DOUBLE"};
  EXPECT_FALSE(rtde::check_input_setup(reply, slider, {"UINT32", "DOUBLE"}, error));
  EXPECT_EQ(error, "CONTROL_PACKAGE_SETUP_INPUTS: 1 types for 2 requested inputs");
}

// ---- The sink against the fake controller

TEST(RtdeWrite, SpeedSliderGetsTheScaleClampedAboveZeroAndAStopAtTheEnd) {
  SteadyClock steady;
  FakeRtdeController fake(FakeRtdeScript{}, steady);
  fake.start({});
  FakeClock clock(0);  // the heartbeat never comes due
  RtdeLinkParams params = params_for(fake, RtdeLinkParams::Mode::speed_slider);
  params.min_speed_slider = 0.05;
  {
    RtdeLinkSink sink(params, clock);
    EXPECT_EQ(sink.input_names(), "speed_slider_mask,speed_slider_fraction");
    // Before any frame: the stop value (the slider's minimum) as soon as the inputs are set up.
    ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 1; }));
    const struct {
      VerdictState state;
      float scale;
      double expected;
    } steps[] = {{VerdictState::run, 1.0F, 1.0},   {VerdictState::slow, 0.5F, 0.5},
                 {VerdictState::stop, 0.0F, 0.05}, {VerdictState::slow, 0.02F, 0.05},
                 {VerdictState::slow, 0.375F, 0.375}};
    size_t count = 1;
    for (const auto& step : steps) {
      sink.frame(verdict(step.state, step.scale));
      ++count;
      ASSERT_TRUE(eventually([&] { return fake.inputs().size() == count; })) << step.expected;
      EXPECT_EQ(fake.inputs().back().values, (std::vector<double>{1.0, step.expected}));
    }
    sink.summary(RunSummary{});
    ASSERT_TRUE(eventually([&] { return sink.counters().stop_writes == 3; }));  // first, stop, final
    const RtdeLinkCounters counters = sink.counters();
    EXPECT_EQ(counters.writes, 7);
    EXPECT_EQ(counters.last_value, 0.05);
    EXPECT_TRUE(counters.last_problem.empty()) << counters.last_problem;
  }
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 7; })) << "the final stop arrives";
  fake.stop();
  const std::vector<std::string> setups = fake.input_setups();
  ASSERT_EQ(setups.size(), 1U);
  EXPECT_EQ(setups[0], "speed_slider_mask,speed_slider_fraction");
  const std::vector<FakeInputWrite> inputs = fake.inputs();
  ASSERT_EQ(inputs.size(), 7U);
  EXPECT_EQ(inputs.back().values, (std::vector<double>{1.0, 0.05})) << "the final stop";
  for (const FakeInputWrite& write : inputs) {
    EXPECT_EQ(write.values[0], 1.0) << "mask";
    EXPECT_GE(write.values[1], 0.05) << "never below the minimum, never a hard 0";
  }
  EXPECT_EQ(fake.input_errors(), 0);
}

TEST(RtdeWrite, RegisterGetsTheScaleAndZeroForStop) {
  SteadyClock steady;
  FakeRtdeController fake(FakeRtdeScript{}, steady);
  fake.start({});
  FakeClock clock(0);
  RtdeLinkParams params = params_for(fake, RtdeLinkParams::Mode::input_register);
  params.register_index = 27;
  {
    RtdeLinkSink sink(params, clock);
    ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 1; }));
    EXPECT_EQ(fake.inputs().back().values, std::vector<double>{0.0}) << "no verdict yet: stop";
    size_t count = 1;
    for (const auto& [state, scale, expected] :
         {std::tuple{VerdictState::run, 1.0F, 1.0}, std::tuple{VerdictState::slow, 0.25F, 0.25},
          std::tuple{VerdictState::stop, 0.7F, 0.0}}) {
      sink.frame(verdict(state, scale));
      ++count;
      ASSERT_TRUE(eventually([&] { return fake.inputs().size() == count; }));
      EXPECT_EQ(fake.inputs().back().values, std::vector<double>{expected});
    }
    sink.frame(verdict(VerdictState::run, 1.0F));
    ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 5; }));
  }  // no summary: the destructor writes the stop
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 6; })) << "the destructor's stop arrives";
  fake.stop();
  EXPECT_EQ(fake.input_setups(), std::vector<std::string>{"input_double_register_27"});
  ASSERT_EQ(fake.inputs().size(), 6U);
  EXPECT_EQ(fake.inputs().back().values, std::vector<double>{0.0});
  EXPECT_EQ(fake.input_errors(), 0);
}

TEST(RtdeWrite, HeartbeatWritesTheStopValueWhileNoFrameComes) {
  SteadyClock steady;
  FakeRtdeController fake(FakeRtdeScript{}, steady);
  fake.start({});
  FakeClock clock(0);
  RtdeLinkSink sink(params_for(fake, RtdeLinkParams::Mode::input_register), clock);
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 1; }));
  sink.frame(verdict(VerdictState::run, 1.0F));
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 2; }));
  EXPECT_EQ(fake.inputs().back().values, std::vector<double>{1.0});
  clock.advance(150 * kMs);  // more than one period (100 ms) since the frame
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 3; }));
  EXPECT_EQ(fake.inputs().back().values, std::vector<double>{0.0});
  clock.advance(100 * kMs);
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 4; }));
  EXPECT_EQ(fake.inputs().back().values, std::vector<double>{0.0});
}

TEST(RtdeWrite, InUseIsARefusalNamingTheInputAndTheKey) {
  SteadyClock steady;
  FakeRtdeScript script;
  script.in_use = {"speed_slider_mask"};  // UR's ROS driver owns the slider
  FakeRtdeController fake(script, steady);
  fake.start({});
  FakeClock clock(0);
  RtdeLinkParams params = params_for(fake, RtdeLinkParams::Mode::speed_slider);
  params.backoff_initial_s = 0.01;
  params.backoff_max_s = 0.02;
  RtdeLinkSink sink(params, clock);
  ASSERT_TRUE(eventually([&] { return sink.counters().refusals >= 2; })) << "refused, and tried again";
  // frame() never waits for the controller.
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < 100; ++k) sink.frame(verdict(VerdictState::run, 1.0F));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(50));
  const RtdeLinkCounters counters = sink.counters();
  EXPECT_FALSE(counters.connected);
  EXPECT_EQ(counters.writes, 0);
  EXPECT_EQ(counters.streaming, 0);
  EXPECT_EQ(counters.last_problem.rfind("link.rtde.write speed_slider: RTDE 127.0.0.1:" + std::to_string(fake.port()) +
                                            ": CONTROL_PACKAGE_SETUP_INPUTS: input 'speed_slider_mask' is IN_USE",
                                        0),
            0U)
      << counters.last_problem;
  EXPECT_TRUE(fake.inputs().empty());
}

TEST(RtdeWrite, MalformedSetupReplyIsCountedAndTheNextConnectionWrites) {
  SteadyClock steady;
  FakeRtdeScript script;
  script.fault = RtdeFault::malformed_input_reply;  // the first connection only
  FakeRtdeController fake(script, steady);
  fake.start({});
  FakeClock clock(0);
  RtdeLinkSink sink(params_for(fake, RtdeLinkParams::Mode::input_register), clock);
  ASSERT_TRUE(eventually([&] { return !fake.inputs().empty(); }));
  const RtdeLinkCounters counters = sink.counters();
  EXPECT_EQ(counters.malformed, 1);
  EXPECT_EQ(counters.connections, 2);
  EXPECT_EQ(counters.streaming, 1);
  EXPECT_EQ(fake.inputs().front().connection, 2) << "nothing written on the malformed connection";
}

TEST(RtdeWrite, LostConnectionIsCountedAndTheNewestValueIsWrittenAgain) {
  SteadyClock steady;
  FakeRtdeScript script;
  script.fault = RtdeFault::close_inputs;
  script.fault_at = 2;  // closes after the initial stop and one frame
  FakeRtdeController fake(script, steady);
  fake.start({});
  FakeClock clock(0);
  RtdeLinkSink sink(params_for(fake, RtdeLinkParams::Mode::input_register), clock);
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 1; }));
  sink.frame(verdict(VerdictState::slow, 0.625F));
  ASSERT_TRUE(eventually([&] { return fake.faulted(); }));
  // The next connection starts with the newest verdict, not a stale default.
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() >= 3; }));
  const std::vector<FakeInputWrite> inputs = fake.inputs();
  EXPECT_EQ(inputs[1].connection, 1);
  EXPECT_EQ(inputs[1].values, std::vector<double>{0.625});
  EXPECT_EQ(inputs[2].connection, 2);
  EXPECT_EQ(inputs[2].values, std::vector<double>{0.625});
  ASSERT_TRUE(eventually([&] { return sink.counters().disconnects == 1; }));
  EXPECT_NE(sink.counters().last_problem.find("connection closed by the controller"), std::string::npos)
      << sink.counters().last_problem;
}

// ---- A reconnect never brings back a value older than one heartbeat period

// The fake closes the first connection after two writes (the initial stop and a `run`) and
// serves the next client only on release(), so the test moves the sink's clock while the link
// is down. Register or slider; the newest frame either the `run` written on the first
// connection or a `slow` handed over while the link was down (pending when the writer
// reconnects).
struct ReconnectCase {
  RtdeLinkParams::Mode mode;
  bool frame_while_down;
};

void PrintTo(const ReconnectCase& c, std::ostream* out) {
  *out << (c.mode == RtdeLinkParams::Mode::input_register ? "register" : "speed_slider")
       << (c.frame_while_down ? ", newest frame while the link is down" : ", newest frame written before the drop");
}

class RtdeWriteReconnect : public ::testing::TestWithParam<ReconnectCase> {
 protected:
  SteadyClock steady_;
  FakeRtdeController fake_{reconnect_script(), steady_};
  FakeClock clock_{0};
  std::unique_ptr<RtdeLinkSink> sink_;

  static FakeRtdeScript reconnect_script() {
    FakeRtdeScript script;
    script.fault = RtdeFault::close_inputs_hold;
    script.fault_at = 2;
    return script;
  }
  void SetUp() override {
    fake_.start({});
    sink_ = std::make_unique<RtdeLinkSink>(params_for(fake_, GetParam().mode), clock_);  // a 100 ms period
  }
  void TearDown() override {
    fake_.release();
    sink_.reset();
    fake_.stop();
  }
  double stop_value() const { return sink_->value_for(VerdictState::stop, 0.0F); }
  // The fraction or register value of a write (the slider's mask comes first).
  static double written(const FakeInputWrite& write) { return write.values.back(); }
  // The writes of the connections after the first, in order.
  std::vector<FakeInputWrite> after_reconnect() const {
    std::vector<FakeInputWrite> later;
    for (const FakeInputWrite& write : fake_.inputs()) {
      if (write.connection != 1) later.push_back(write);
    }
    return later;
  }
  // A `run` frame at clock time 0 written, the link dropped by the controller; with
  // frame_while_down a `slow` 0.5 frame 20 ms later, while the link is down. Then the clock
  // moves on until the newest frame is `age_ns` old, and the controller takes the writer's next
  // connection. Returns the newest frame's value.
  double drop_and_reconnect_at(int64_t age_ns) {
    EXPECT_TRUE(eventually([&] { return fake_.inputs().size() == 1; })) << "the initial stop";
    sink_->frame(verdict(VerdictState::run, 1.0F));
    EXPECT_TRUE(eventually([&] { return fake_.faulted() && fake_.inputs().size() == 2; }));
    EXPECT_EQ(written(fake_.inputs().back()), 1.0) << "the run on the first connection";
    EXPECT_TRUE(eventually([&] { return sink_->counters().disconnects == 1; })) << "the writer saw the close";
    double newest = 1.0;
    if (GetParam().frame_while_down) {
      clock_.advance(20 * kMs);
      sink_->frame(verdict(VerdictState::slow, 0.5F));
      newest = 0.5;
    }
    clock_.advance(age_ns);
    fake_.release();  // the next connection is served
    EXPECT_TRUE(eventually([&] { return !after_reconnect().empty(); })) << "the writer reconnects";
    return newest;
  }
};

TEST_P(RtdeWriteReconnect, AfterMoreThanOnePeriodTheStopValueComesFirst) {
  drop_and_reconnect_at(150 * kMs);  // older than one period (100 ms)
  ASSERT_FALSE(after_reconnect().empty());
  EXPECT_EQ(written(after_reconnect().front()), stop_value()) << "never the old run or slow on a new connection";
  // The next frame's value follows as usual.
  sink_->frame(verdict(VerdictState::run, 1.0F));
  ASSERT_TRUE(eventually([&] { return after_reconnect().size() == 2; }));
  EXPECT_EQ(written(after_reconnect()[1]), 1.0);
  EXPECT_EQ(fake_.input_errors(), 0);
}

TEST_P(RtdeWriteReconnect, WithinOnePeriodTheNewestValueComesFirstAndItsStopOnePeriodAfterTheFrame) {
  const double newest = drop_and_reconnect_at(60 * kMs);
  ASSERT_FALSE(after_reconnect().empty());
  EXPECT_EQ(written(after_reconnect().front()), newest);
  // The heartbeat's stop comes one period after the frame, as on a connection that never broke,
  // not one period after the reconnect (which is 60 ms later).
  clock_.advance(50 * kMs);
  ASSERT_TRUE(eventually([&] { return after_reconnect().size() == 2; })) << "the heartbeat's stop";
  EXPECT_EQ(written(after_reconnect()[1]), stop_value());
}

TEST_P(RtdeWriteReconnect, ExactlyOnePeriodOldIsWrittenAndStoppedAtOnce) {
  const double newest = drop_and_reconnect_at(100 * kMs);  // "at most one period": still written
  ASSERT_TRUE(eventually([&] { return after_reconnect().size() == 2; })) << "the heartbeat is due at once";
  EXPECT_EQ(written(after_reconnect()[0]), newest);
  EXPECT_EQ(written(after_reconnect()[1]), stop_value());
}

INSTANTIATE_TEST_SUITE_P(Cases, RtdeWriteReconnect,
                         ::testing::Values(ReconnectCase{RtdeLinkParams::Mode::input_register, false},
                                           ReconnectCase{RtdeLinkParams::Mode::input_register, true},
                                           ReconnectCase{RtdeLinkParams::Mode::speed_slider, false},
                                           ReconnectCase{RtdeLinkParams::Mode::speed_slider, true}),
                         [](const ::testing::TestParamInfo<ReconnectCase>& info) {
                           return std::string(info.param.mode == RtdeLinkParams::Mode::input_register ? "register"
                                                                                                      : "slider") +
                                  (info.param.frame_while_down ? "_frame_while_down" : "_frame_written");
                         });

// A clock that stands still except for one jump: armed by the thread that made it, it moves on
// by `jump_ns` right after that thread's next reading. The sink's frame() stamps its frame before
// the jump and the writer thread sees the time after it, as if the writer had been held up that
// long between the frame and its write (a slow send, a thread not scheduled).
class HeldUpWriterClock final : public RunClock {
 public:
  int64_t now_ns() const override {
    const int64_t t_ns = now_ns_.load();
    if (std::this_thread::get_id() == owner_ && armed_.exchange(false)) now_ns_ += jump_ns_.load();
    return t_ns;
  }
  void sleep_until(int64_t, const std::atomic<bool>*) override {}
  void jump_after_my_next_read(int64_t jump_ns) {
    jump_ns_ = jump_ns;
    armed_ = true;
  }

 private:
  const std::thread::id owner_ = std::this_thread::get_id();
  mutable std::atomic<int64_t> now_ns_{0};
  mutable std::atomic<bool> armed_{false};
  std::atomic<int64_t> jump_ns_{0};
};

TEST(RtdeWrite, AValueOlderThanOnePeriodWhenItsWriteComesDueIsWrittenAsTheStop) {
  SteadyClock steady;
  FakeRtdeController fake(FakeRtdeScript{}, steady);
  fake.start({});
  HeldUpWriterClock clock;
  RtdeLinkSink sink(params_for(fake, RtdeLinkParams::Mode::input_register), clock);  // a 100 ms period
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 1; })) << "the initial stop";
  clock.jump_after_my_next_read(150 * kMs);
  sink.frame(verdict(VerdictState::run, 1.0F));  // stamped 0; the writer takes it at 150 ms
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 2; }));
  EXPECT_EQ(fake.inputs().back().values, std::vector<double>{0.0}) << "not the run of 150 ms ago";
  sink.frame(verdict(VerdictState::run, 1.0F));  // a fresh one is written as it is
  ASSERT_TRUE(eventually([&] { return fake.inputs().size() == 3; }));
  EXPECT_EQ(fake.inputs().back().values, std::vector<double>{1.0});
  EXPECT_EQ(sink.counters().stop_writes, 2);
}

TEST(RtdeWrite, NoControllerNeverBlocksAndTheDestructorIsBounded) {
  uint16_t port = 0;
  {
    SteadyClock steady;
    const FakeRtdeController probe(FakeRtdeScript{}, steady);  // a port that is free once it closes
    port = static_cast<uint16_t>(probe.port());
  }
  FakeClock clock(0);
  RtdeLinkParams params;
  params.host = "127.0.0.1";
  params.port = port;
  const auto start = std::chrono::steady_clock::now();
  {
    RtdeLinkSink sink(params, clock);
    for (int k = 0; k < 100; ++k) sink.frame(verdict(VerdictState::run, 1.0F));
    sink.summary(RunSummary{});
    ASSERT_TRUE(eventually([&] { return !sink.counters().last_problem.empty(); }));
    EXPECT_NE(sink.counters().last_problem.find("connect"), std::string::npos) << sink.counters().last_problem;
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
}

TEST(RtdeWrite, ParametersOutsideTheirRangeNameTheKey) {
  FakeClock clock(0);
  RtdeLinkParams params;
  params.host = "127.0.0.1";
  params.register_index = 23;
  try {
    RtdeLinkSink sink(params, clock);
    ADD_FAILURE() << "register 23 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()).rfind("link.rtde.register: ", 0), 0U) << e.what();
  }
  params.register_index = 24;
  params.min_speed_slider = 0.0;
  EXPECT_THROW((RtdeLinkSink{params, clock}), std::invalid_argument);
}

}  // namespace
}  // namespace hrcsense

namespace hrcsense {
namespace {

// ---- `hrcsense run` with link.rtde.write

TEST(RtdeWriteCli, RunWritesTheFramesSpeedScalesAndEndsWithAStop) {
  SteadyClock steady;
  FakeRtdeController fake(FakeRtdeScript{}, steady);
  fake.start({});
  // The noise-free UR5 cell (paced, 75 frames at 30 fps: 2.5 s; a box beside the arm from frame 15).
  const std::string config = test::write_cli_cell("rtde_write");
  const std::string out = std::string(::testing::TempDir()) + "rtde_write_cli.jsonl";
  const std::string command = std::string(HRCSENSE_CLI) + " run --config " + config +
                              " --set link.rtde.write=register --set link.rtde.register=31"
                              " --set robot.state.host=127.0.0.1 --set robot.state.port=" +
                              std::to_string(fake.port()) + " --out " + out + " 2>/dev/null";
  EXPECT_EQ(std::system(command.c_str()), 0) << command;
  std::vector<double> scales;  // of the verdicts the run wrote
  std::ifstream in(out);
  std::string line;
  while (std::getline(in, line)) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j.at("type") == "frame" && j.at("verdict") != "stop") {
      scales.push_back(static_cast<double>(j.at("speed_scale").get<float>()));
    }
  }
  in.close();
  std::remove(out.c_str());
  std::remove(config.c_str());
  ASSERT_TRUE(eventually([&] { return !fake.inputs().empty() && fake.inputs().back().values == std::vector<double>{0.0}; }));
  fake.stop();
  ASSERT_GE(scales.size(), 3U) << "the cell runs after learning, until the box comes";
  EXPECT_EQ(fake.input_setups(), std::vector<std::string>{"input_double_register_31"});
  const std::vector<FakeInputWrite> inputs = fake.inputs();
  int moving = 0;
  for (const FakeInputWrite& write : inputs) {
    ASSERT_EQ(write.values.size(), 1U);
    if (write.values[0] == 0.0) continue;  // a stop verdict, or no verdict yet
    ++moving;
    EXPECT_NE(std::find(scales.begin(), scales.end(), write.values[0]), scales.end())
        << write.values[0] << " is no verdict's speed scale";
  }
  EXPECT_GE(moving, 3);
  EXPECT_EQ(inputs.back().values, std::vector<double>{0.0}) << "the last write is a stop";
  EXPECT_EQ(fake.input_errors(), 0);
}

}  // namespace
}  // namespace hrcsense

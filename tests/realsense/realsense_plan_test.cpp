// SPDX-License-Identifier: Apache-2.0
// Tests of the live camera's plain decisions (realsense/realsense_plan.hpp), without the SDK:
// intrinsics, profiles, USB 2, options, clocks, drops, settling, devices.
#include "realsense/realsense_plan.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace hrcsense {
namespace {

bool contains(const std::string& text, const std::string& needle) { return text.find(needle) != std::string::npos; }

TEST(RealSenseIntrinsics, CopiesEveryFieldAndTheModelNumber) {
  // A D435 at 848x480 as rs2_intrinsics gives it (ppx/ppy before fx/fy there).
  SdkIntrinsics sdk{848, 480, 424.5F, 241.25F, 421.0F, 422.0F, 2, {0.1F, -0.2F, 0.003F, 0.004F, 0.05F}};
  const Intrinsics in = intrinsics_from_sdk(sdk);
  EXPECT_EQ(in.width, 848);
  EXPECT_EQ(in.height, 480);
  EXPECT_EQ(in.ppx, 424.5F);
  EXPECT_EQ(in.ppy, 241.25F);
  EXPECT_EQ(in.fx, 421.0F);
  EXPECT_EQ(in.fy, 422.0F);
  EXPECT_EQ(in.model, Distortion::inverse_brown_conrady);  // rs2_distortion 2
  EXPECT_EQ(in.coeffs[0], 0.1F);
  EXPECT_EQ(in.coeffs[1], -0.2F);
  EXPECT_EQ(in.coeffs[4], 0.05F);
  sdk.model = 0;
  EXPECT_EQ(intrinsics_from_sdk(sdk).model, Distortion::none);
  sdk.model = 5;
  EXPECT_EQ(intrinsics_from_sdk(sdk).model, Distortion::kannala_brandt4);
}

TEST(RealSenseIntrinsics, UnknownModelNumberIsAnErrorNamingIt) {
  for (int model : {6, -1, 42}) {
    SdkIntrinsics sdk;
    sdk.model = model;
    try {
      (void)intrinsics_from_sdk(sdk);
      FAIL() << "model " << model << " accepted";
    } catch (const RealSenseError& e) {
      EXPECT_TRUE(contains(e.what(), "distortion model " + std::to_string(model))) << e.what();
    }
  }
}

// Part of what a D435 on USB 3 offers, in no particular order.
std::vector<ProfileDescriptor> d435_usb3() {
  return {{StreamKind::depth, "Z16", 848, 480, 30},   {StreamKind::depth, "Z16", 848, 480, 90},
          {StreamKind::depth, "Z16", 640, 480, 30},   {StreamKind::depth, "Z16", 848, 480, 60},
          {StreamKind::infrared, "Y8", 848, 480, 90}, {StreamKind::color, "RGB8", 848, 480, 30},
          {StreamKind::color, "YUYV", 1280, 720, 30}, {StreamKind::color, "RGB8", 1280, 720, 30},
          {StreamKind::depth, "Z16", 1280, 720, 30}};
}

TEST(RealSenseProfiles, DefaultIs848x480At30AndNinetyWorks) {
  RealSenseParams params;
  ProfileChoice choice = choose_profiles(d435_usb3(), params, false);
  EXPECT_EQ(choice.depth.width, 848);
  EXPECT_EQ(choice.depth.height, 480);
  EXPECT_EQ(choice.depth.fps, 30);
  EXPECT_EQ(choice.depth.format, "Z16");
  EXPECT_FALSE(choice.color);
  params.fps = 90;
  choice = choose_profiles(d435_usb3(), params, false);
  EXPECT_EQ(choice.depth.fps, 90);
  EXPECT_EQ(choice.depth.stream, StreamKind::depth);
}

TEST(RealSenseProfiles, ColourIsRgb8AtItsOwnMode) {
  RealSenseParams params;
  params.color = true;
  params.color_width = 1280;
  params.color_height = 720;
  const ProfileChoice choice = choose_profiles(d435_usb3(), params, false);
  ASSERT_TRUE(choice.color);
  EXPECT_EQ(choice.color->format, "RGB8");  // not the YUYV one of the same size
  EXPECT_EQ(choice.color->width, 1280);
  EXPECT_EQ(choice.color->fps, 30);
}

TEST(RealSenseProfiles, NothingMatchingListsWhatTheCameraOffers) {
  RealSenseParams params;
  params.fps = 15;
  try {
    (void)choose_profiles(d435_usb3(), params, false);
    FAIL() << "848x480 @ 15 is not in the list";
  } catch (const RealSenseError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, "no depth Z16 848x480 @ 15")) << message;
    EXPECT_TRUE(contains(message, "source.fps")) << message;
    // Largest first, rates fastest first; infrared and colour are not depth.
    EXPECT_TRUE(contains(message, "it offers 1280x720 @ 30; 848x480 @ 90, 60, 30; 640x480 @ 30")) << message;
    EXPECT_FALSE(contains(message, "USB 2")) << message;
  }
  params.fps = 30;
  params.color = true;
  params.color_fps = 60;
  try {
    (void)choose_profiles(d435_usb3(), params, false);
    FAIL() << "colour 848x480 @ 60 is not in the list";
  } catch (const RealSenseError& e) {
    EXPECT_TRUE(contains(e.what(), "no colour RGB8 848x480 @ 60 (source.color); it offers 1280x720 @ 30; 848x480 @ 30"))
        << e.what();
  }
}

TEST(RealSenseProfiles, OnUsb2TheMessageExplainsTheLimit) {
  // What a D435 on USB 2.1 offered (librealsense issue 4962): no 848x480 at all.
  const std::vector<ProfileDescriptor> usb2 = {{StreamKind::depth, "Z16", 640, 480, 30},
                                               {StreamKind::depth, "Z16", 640, 480, 15},
                                               {StreamKind::depth, "Z16", 1280, 720, 6}};
  try {
    (void)choose_profiles(usb2, RealSenseParams{}, true);
    FAIL() << "848x480 is not offered";
  } catch (const RealSenseError& e) {
    const std::string message = e.what();
    EXPECT_TRUE(contains(message, "it offers 1280x720 @ 6; 640x480 @ 30, 15")) << message;
    EXPECT_TRUE(contains(message, "USB 2")) << message;
    EXPECT_TRUE(contains(message, "640x480 @ 30")) << message;
    EXPECT_TRUE(contains(message, "USB 3 port")) << message;
  }
  EXPECT_EQ(offered_text(usb2, StreamKind::color, "RGB8"), "none");
}

TEST(RealSenseUsb, TypeDescriptorSaysUsb2) {
  EXPECT_TRUE(is_usb2("2.1"));
  EXPECT_TRUE(is_usb2("2.0"));
  EXPECT_FALSE(is_usb2("3.2"));
  EXPECT_FALSE(is_usb2("3.0"));
  EXPECT_FALSE(is_usb2(""));  // a file or an unknown connection
}

TEST(RealSenseOptions, AutoExposureAndSettling) {
  RealSenseParams params;
  EXPECT_TRUE(auto_exposure_on(params.options));  // the D435 starts with it on
  EXPECT_EQ(frames_to_settle(params), 30);
  params.settle_frames = 12;
  EXPECT_EQ(frames_to_settle(params), 12);
  params.options = {{"visual_preset", 3.0F}, {"enable_auto_exposure", 0.0F}, {"exposure", 8500.0F}};
  EXPECT_FALSE(auto_exposure_on(params.options));
  EXPECT_EQ(frames_to_settle(params), 0);
  params.options = {{"enable_auto_exposure", 1.0F}};
  EXPECT_TRUE(auto_exposure_on(params.options));
}

TEST(RealSenseSettle, SkipsTheFirstFramesAfterEachRestart) {
  SettleGate gate;
  gate.frames = 3;
  std::vector<bool> skipped;
  for (int i = 0; i < 5; ++i) skipped.push_back(gate.skip());
  EXPECT_EQ(skipped, (std::vector<bool>{true, true, true, false, false}));
  gate.restart();  // a reconnect: the exposure settles again
  EXPECT_TRUE(gate.skip());
  SettleGate none;  // auto exposure off: nothing skipped
  EXPECT_FALSE(none.skip());
}

TEST(RealSenseClock, LearnsTheOffsetFromTheFastestFrame) {
  HostClockMapper mapper;
  // Hardware clock at 1000 ms when the host's steady clock reads 5 s + 20 ms transport.
  EXPECT_EQ(mapper.host_time_ns(1000.0, TimestampDomain::hardware_clock, 5'020'000'000), 5'020'000'000);
  // The next frame 33.3 ms later travelled only 10 ms: the offset tightens to 4.010 s.
  EXPECT_EQ(mapper.host_time_ns(1033.3, TimestampDomain::hardware_clock, 5'043'300'000), 5'043'300'000);
  EXPECT_EQ(mapper.offset_ns, 4'010'000'000);
  // A slower one (30 ms) is mapped with that offset: 1066.6 ms + 4.010 s, 20 ms before its arrival.
  EXPECT_EQ(mapper.host_time_ns(1066.6, TimestampDomain::hardware_clock, 5'096'600'000), 5'076'600'000);
  EXPECT_EQ(mapper.relearned, 0);
}

TEST(RealSenseClock, AJumpOrANewDomainIsLearntAgain) {
  HostClockMapper mapper;
  EXPECT_EQ(mapper.host_time_ns(1000.0, TimestampDomain::hardware_clock, 5'000'000'000), 5'000'000'000);
  // The camera's clock reset to 0 (a firmware restart): mapped 1 s before arrival, far beyond
  // 200 ms of lag; learnt again, the frame gets its arrival time.
  EXPECT_EQ(mapper.host_time_ns(0.0, TimestampDomain::hardware_clock, 5'033'000'000), 5'033'000'000);
  EXPECT_EQ(mapper.relearned, 1);
  EXPECT_EQ(mapper.offset_ns, 5'033'000'000);
  // Global time (epoch ms) instead: another clock.
  EXPECT_EQ(mapper.host_time_ns(1.7e12, TimestampDomain::global_time, 5'066'000'000), 5'066'000'000);
  EXPECT_EQ(mapper.relearned, 2);
  EXPECT_EQ(mapper.domain, TimestampDomain::global_time);
  mapper.reset();
  EXPECT_EQ(mapper.host_time_ns(10.0, TimestampDomain::system_time, 6'000'000'000), 6'000'000'000);
  EXPECT_EQ(mapper.relearned, 2);  // a reset is not a jump
}

TEST(RealSenseClock, TimestampMsToNs) {
  EXPECT_EQ(timestamp_ms_to_ns(1.5), 1'500'000);
  EXPECT_EQ(timestamp_ms_to_ns(1234567.25), 1'234'567'250'000);
  EXPECT_EQ(timestamp_ms_to_ns(0.0000004), 0);
}

TEST(RealSenseDrops, FrameNumberGapsAreCounted) {
  FrameGapCounter counter;
  for (uint64_t n : {10U, 11U, 12U, 15U, 16U, 20U}) counter.add(n);
  EXPECT_EQ(counter.dropped, 2 + 3);  // 13, 14 and 17, 18, 19
}

TEST(RealSenseDrops, ResetsAndWrapsAreNotGaps) {
  FrameGapCounter counter;
  counter.add(5000);
  counter.add(0);  // the counter restarted (new stream): nothing lost that we can count
  counter.add(1);
  counter.add(1);  // repeated
  EXPECT_EQ(counter.dropped, 0);
  counter.add(1 + 200'000);  // a jump beyond max_gap: a new stream too
  EXPECT_EQ(counter.dropped, 0);
  // A 32-bit counter wrapping: 4294967294, then 1; 4294967295 and 0 were lost.
  counter.add(4294967294ULL);
  counter.add(1);
  EXPECT_EQ(counter.dropped, 2);
  counter.reset();
  counter.add(100);  // after a reconnect the first number is not compared
  EXPECT_EQ(counter.dropped, 2);
}

TEST(RealSenseLink, StopsWhileUnpluggedUntilTheSameSerialStreamsAgain) {
  CameraLink link;
  link.serial = "825312072719";
  EXPECT_EQ(link.silence_code(), ReasonCode::no_frame);
  link.frame_arrived(1'000'000'000);
  EXPECT_EQ(link.state, CameraLink::State::streaming);
  EXPECT_TRUE(link.readable());
  EXPECT_FALSE(link.restart_due(1'000'000'000));

  link.device_removed("000000000001", 2'000'000'000);  // another camera: not ours
  EXPECT_EQ(link.state, CameraLink::State::streaming);
  link.device_removed("825312072719", 2'000'000'000);
  EXPECT_EQ(link.state, CameraLink::State::disconnected);
  EXPECT_FALSE(link.readable());
  EXPECT_EQ(link.silence_code(), ReasonCode::camera_disconnected);
  EXPECT_EQ(link.describe(4'500'000'000), "camera 825312072719 disconnected 2.500 s ago, waiting for it");
  link.frame_arrived(2'010'000'000);  // a frame still queued from before: not back
  EXPECT_EQ(link.state, CameraLink::State::disconnected);
  EXPECT_FALSE(link.restart_due(3'000'000'000));

  link.device_added("000000000001", 5'000'000'000);  // a different camera plugged in
  EXPECT_EQ(link.state, CameraLink::State::disconnected);
  link.device_added("825312072719", 6'000'000'000);
  EXPECT_EQ(link.state, CameraLink::State::reconnecting);
  EXPECT_EQ(link.silence_code(), ReasonCode::camera_disconnected);  // back, but no frame yet
  EXPECT_TRUE(link.restart_due(6'000'000'000));
  link.restart_failed(6'000'000'000);  // still booting
  EXPECT_FALSE(link.restart_due(6'500'000'000));
  EXPECT_FALSE(link.readable());
  EXPECT_TRUE(link.restart_due(7'000'000'000));  // retry_ns (1 s) later
  link.restart_started();
  EXPECT_TRUE(link.readable());  // read frames; no more restarts while the first one is awaited
  EXPECT_FALSE(link.restart_due(9'000'000'000));
  EXPECT_EQ(link.describe(7'000'000'000), "camera 825312072719 disconnected 5.000 s ago, restarting it");
  link.frame_arrived(7'100'000'000);
  EXPECT_EQ(link.state, CameraLink::State::streaming);
  EXPECT_EQ(link.silence_code(), ReasonCode::no_frame);
  EXPECT_EQ(link.describe(7'100'000'000), "");
  EXPECT_EQ(link.disconnects, 1);
}

TEST(RealSenseDevices, ListingNamesEachCameraAndItsDepthModes) {
  DeviceDescriptor d435{"Intel RealSense D435", "825312072719", "05.13.00.50", "3.2", d435_usb3()};
  DeviceDescriptor slow{"Intel RealSense D435", "819312072632", "05.11.15.00", "2.1",
                        {{StreamKind::depth, "Z16", 640, 480, 30}}};
  const std::string text = format_devices({d435, slow});
  EXPECT_TRUE(contains(text, "Intel RealSense D435\n  serial: 825312072719\n  firmware: 05.13.00.50\n  usb: 3.2\n"
                             "  depth (Z16): 1280x720 @ 30; 848x480 @ 90, 60, 30; 640x480 @ 30\n"
                             "  colour (RGB8): 1280x720 @ 30; 848x480 @ 30\n"))
      << text;
  EXPECT_TRUE(contains(text, "usb: 2.1\n  warning: the camera is on a USB 2 connection")) << text;
  EXPECT_EQ(format_devices({}), "no RealSense camera found\n");
}

TEST(RealSenseMessages, NoSdkSaysHowToGetIt) {
  const std::string message = realsense_missing_message("hrcsense devices");
  EXPECT_EQ(message.rfind("hrcsense devices: ", 0), 0U) << message;
  EXPECT_TRUE(contains(message, "without the RealSense SDK (librealsense2)")) << message;
  EXPECT_TRUE(contains(message, "librealsense2-dev")) << message;
  EXPECT_TRUE(contains(message, "README, 'Cameras'")) << message;
}

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// Recorded joint states (issue C2 part 3): the JointState parser of /hrcsense/joint_states
// (joints mapped by name, never by position; every kind of damage an error naming the field),
// the writer's joint names and velocities, and BagSource's recorded_robot_state(): the state
// stamped with each frame's timestamp, exactly, or none. Messages are serialised by hand here
// (ROS1: little-endian, uint32 length prefixes), independently of the writer. No ../shared data.
#include "recordings_test_util.hpp"

#include "hrcsense/recordings/bag_writer.hpp"
#include "hrcsense/io/io.hpp"
#include "hrcsense/recordings/recordings.hpp"
#include "src/recordings/bag_messages.hpp"
#include "src/recordings/bag_reader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

using test::ScratchDir;

/// A sensor_msgs/JointState as ROS1 serialises it.
struct JointStateBytes {
  std::vector<uint8_t> bytes;
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) bytes.push_back(static_cast<uint8_t>(v >> (8 * i)));
  }
  void f64(double v) {
    uint64_t bits = 0;
    std::memcpy(&bits, &v, 8);
    u32(static_cast<uint32_t>(bits));
    u32(static_cast<uint32_t>(bits >> 32));
  }
  void text(const std::string& s) {
    u32(static_cast<uint32_t>(s.size()));
    bytes.insert(bytes.end(), s.begin(), s.end());
  }
  /// header (seq 7, stamp sec.nsec, frame_id "base"), name[], position[], velocity[], effort[].
  static JointStateBytes make(uint32_t sec, uint32_t nsec, const std::vector<std::string>& names,
                              const std::vector<double>& position, const std::vector<double>& velocity,
                              const std::vector<double>& effort = {}) {
    JointStateBytes m;
    m.u32(7);
    m.u32(sec);
    m.u32(nsec);
    m.text("base");
    m.u32(static_cast<uint32_t>(names.size()));
    for (const std::string& n : names) m.text(n);
    for (const std::vector<double>* values : {&position, &velocity, &effort}) {
      m.u32(static_cast<uint32_t>(values->size()));
      for (double v : *values) m.f64(v);
    }
    return m;
  }
  std::string parse(bag::JointStateMessage& out) const { return bag::parse_joint_state(bag::Cursor{bytes.data(), bytes.size()}, out); }
};

const std::vector<std::string> kUr = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
                                      "wrist_1_joint",      "wrist_2_joint",       "wrist_3_joint"};

TEST(JointStateMessage, MapsJointsByNameWhateverTheirOrderOrPrefix) {
  // The order of a ROS driver's /joint_states (alphabetical in some versions), a prefix, and a
  // gripper joint hrcsense does not know.
  const JointStateBytes m = JointStateBytes::make(
      12, 345, {"ur_wrist_3_joint", "ur_elbow_joint", "gripper_finger_joint", "ur_shoulder_lift_joint",
                "ur_shoulder_pan_joint", "ur_wrist_1_joint", "ur_wrist_2_joint"},
      {6.0, 3.0, 0.04, 2.0, 1.0, 4.0, 5.0}, {-6.0, -3.0, 9.9, -2.0, -1.0, -4.0, -5.0});
  bag::JointStateMessage out;
  ASSERT_EQ(m.parse(out), "");
  EXPECT_EQ(out.stamp_ns, 12'000'000'345LL);
  EXPECT_EQ(out.position_rad, (JointAngles{1.0, 2.0, 3.0, 4.0, 5.0, 6.0}));
  EXPECT_TRUE(out.has_velocity);
  EXPECT_EQ(out.velocity_rad_s, (JointAngles{-1.0, -2.0, -3.0, -4.0, -5.0, -6.0}));
}

TEST(JointStateMessage, AcceptsHrcsensesOlderNamesAndNoVelocities) {
  const JointStateBytes m = JointStateBytes::make(
      1, 0, {"joint_5", "joint_4", "joint_3", "joint_2", "joint_1", "joint_0"}, {0.6, 0.5, 0.4, 0.3, 0.2, 0.1}, {});
  bag::JointStateMessage out;
  ASSERT_EQ(m.parse(out), "");
  EXPECT_EQ(out.position_rad, (JointAngles{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  EXPECT_FALSE(out.has_velocity);
  EXPECT_EQ(out.velocity_rad_s, JointAngles{});
}

TEST(JointStateMessage, JointIndexNeedsAWholeName) {
  EXPECT_EQ(bag::joint_index("elbow_joint"), 2);
  EXPECT_EQ(bag::joint_index("arm/elbow_joint"), 2);
  EXPECT_EQ(bag::joint_index("ur5e_wrist_2_joint"), 4);
  EXPECT_EQ(bag::joint_index("joint_3"), 3);
  EXPECT_EQ(bag::joint_index("myelbow_joint"), -1) << "a prefix ends in '_' or '/'";
  EXPECT_EQ(bag::joint_index("joint_6"), -1);
  EXPECT_EQ(bag::joint_index("elbow"), -1);
  EXPECT_EQ(bag::joint_index(""), -1);
}

TEST(JointStateMessage, DamageIsAnErrorNamingTheField) {
  const std::vector<double> six = {1, 2, 3, 4, 5, 6};
  const auto problem = [](const JointStateBytes& m) {
    bag::JointStateMessage out;
    out.position_rad[0] = 42.0;
    const std::string text = m.parse(out);
    EXPECT_EQ(out.position_rad[0], 42.0) << "a failed parse leaves its output alone";
    return text;
  };
  std::vector<std::string> five(kUr.begin(), kUr.end() - 1);
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, five, {1, 2, 3, 4, 5}, {})),
            "joint_states has no joint wrist_3_joint (or joint_5)");
  std::vector<std::string> twice = kUr;
  twice[5] = "joint_1";
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, twice, six, {})),
            "joint_states name[5] 'joint_1' names joint shoulder_lift_joint again");
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, kUr, {1, 2, 3}, {})), "joint_states position[] has 3 entries, name[] 6");
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, kUr, six, {1, 2})), "joint_states velocity[] has 2 entries, name[] 6");
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, kUr, six, {}, {1})), "joint_states effort[] has 1 entries, name[] 6");
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, kUr, {1, 2, std::nan(""), 4, 5, 6}, {})),
            "joint_states position[2] (elbow_joint) is not finite");
  EXPECT_EQ(problem(JointStateBytes::make(0, 0, kUr, six, {0, 0, 0, 0, std::numeric_limits<double>::infinity(), 0})),
            "joint_states velocity[4] (wrist_2_joint) is not finite");
  // Cut off anywhere: an error, never a read past the message.
  const JointStateBytes whole = JointStateBytes::make(3, 4, kUr, six, six, six);
  for (size_t size = 0; size < whole.bytes.size(); ++size) {
    bag::JointStateMessage out;
    const std::string text = bag::parse_joint_state(bag::Cursor{whole.bytes.data(), size}, out);
    EXPECT_NE(text.find("cut off"), std::string::npos) << size << " bytes: " << text;
  }
  // A damaged count is refused before any loop runs over it.
  JointStateBytes huge;
  huge.u32(0);
  huge.u32(0);
  huge.u32(0);
  huge.text("");
  huge.u32(0xFFFFFFF0U);
  EXPECT_EQ(problem(huge), "joint_states name[] has 4294967280 entries (at most 64)");
}

// ---- the writer and BagSource

Frame tiny_frame(int64_t index) {
  Frame frame;
  frame.index = index;
  frame.timestamp_ns = 5'000'000'007LL + index * 33'333'333LL;
  frame.depth.resize(8, 6);
  for (size_t i = 0; i < frame.depth.pixels.size(); ++i) frame.depth.pixels[i] = static_cast<uint16_t>(900 + i);
  frame.intrinsics = Intrinsics{8, 6, 6.5F, 6.25F, 3.5F, 2.5F, Distortion::brown_conrady, {0, 0, 0, 0, 0}};
  return frame;
}

JointAngles q_of(int64_t index) {
  return {0.1 * static_cast<double>(index), -1.0, 1.5, -2.0, 0.25, -0.125 * static_cast<double>(index)};
}
JointAngles qd_of(int64_t index) { return {0.5, 0.0, -0.25, 0.0, 1.0 / 3.0, static_cast<double>(index)}; }

/// Four frames; joint states before frames 0, 1 and 3 (none for frame 2). `after`: each joint
/// state after its frame instead, as hrcsense wrote them before joint states were replayed.
void write_joint_bag(const std::string& path, bool after = false) {
  BagWriterParams params;
  params.sdk_metadata = false;
  params.joint_names.assign(kUrJointNames.begin(), kUrJointNames.end());
  BagWriter writer(path, params);
  for (int64_t i = 0; i < 4; ++i) {
    const Frame frame = tiny_frame(i);
    if (after) writer.add_depth(frame);
    if (i != 2) writer.add_joint_state(frame.timestamp_ns, q_of(i), qd_of(i));
    if (!after) writer.add_depth(frame);
  }
  writer.close();
}

TEST(RecordedJointStates, TheWriterNamesTheJointsAsTold) {
  ScratchDir dir("joints");
  write_joint_bag(dir / "ur.bag");
  BagReader reader(dir / "ur.bag");
  BagMessage m;
  int found = 0;
  for (int guard = 0; guard < 100 && reader.next(m); ++guard) {
    if (reader.connections().at(m.conn).topic != "/hrcsense/joint_states") continue;
    // The names, read straight from the bytes: header (4 + 8 + 4 + "" 0), count, then strings.
    ++found;
    size_t at = 16;
    uint32_t count = 0;
    std::memcpy(&count, m.data + at, 4);
    at += 4;
    ASSERT_EQ(count, 6U);
    for (const std::string& want : kUr) {
      uint32_t n = 0;
      std::memcpy(&n, m.data + at, 4);
      EXPECT_EQ(std::string(reinterpret_cast<const char*>(m.data + at + 4), n), want);
      at += 4 + n;
    }
  }
  EXPECT_EQ(found, 3);
}

TEST(RecordedJointStates, EachFrameGetsTheStateStampedWithItsTimestampOrNone) {
  ScratchDir dir("joints");
  write_joint_bag(dir / "j.bag");
  RecordingParams params{dir / "j.bag"};
  params.with_joint_states = true;
  params.loop = true;
  BagSource bag(params);
  std::unique_ptr<RobotStateSource> states = bag.recorded_robot_state();
  ASSERT_NE(states, nullptr);
  EXPECT_EQ(states->origin(), RobotStateOrigin::recorded);
  Frame frame;
  for (int64_t n = 0; n < 8; ++n) {  // two laps: the second one's timestamps are shifted
    ASSERT_EQ(bag.next(frame), Source::Status::frame) << n;
    const int64_t i = n % 4;
    RobotState state;
    const bool found = states->state_at(frame.timestamp_ns, state);
    EXPECT_EQ(state.origin, RobotStateOrigin::recorded);
    if (i == 2) {
      EXPECT_FALSE(found) << "frame " << n << " was recorded without a joint state";
      EXPECT_FALSE(state.valid);
      EXPECT_NE(states->error().find(dir / "j.bag"), std::string::npos) << states->error();
      EXPECT_NE(states->error().find(std::to_string(frame.timestamp_ns) + " ns"), std::string::npos) << states->error();
      continue;
    }
    ASSERT_TRUE(found) << "frame " << n << ": " << states->error();
    EXPECT_TRUE(state.valid);
    EXPECT_EQ(state.q_rad, q_of(i)) << "frame " << n;
    EXPECT_EQ(state.qd_rad_s, qd_of(i)) << "frame " << n;
    EXPECT_EQ(state.sample_time_ns, frame.timestamp_ns) << "age 0";
    // Exact: a nanosecond off is another frame's time.
    EXPECT_FALSE(states->state_at(frame.timestamp_ns + 1, state));
    EXPECT_FALSE(states->state_at(frame.timestamp_ns - 1, state));
  }
  EXPECT_EQ(states->stats().samples.accepted, 6);
  EXPECT_EQ(states->stats().samples.rejected_backwards, 0);
}

TEST(RecordedJointStates, AStateAfterItsFrameInTheFileIsNeverUsed) {
  // Whether processing would see it would depend on the threads' timing: it is refused always.
  ScratchDir dir("joints");
  write_joint_bag(dir / "late.bag", true);
  RecordingParams params{dir / "late.bag"};
  params.with_joint_states = true;
  BagSource bag(params);
  std::unique_ptr<RobotStateSource> states = bag.recorded_robot_state();
  ASSERT_NE(states, nullptr);
  Frame frame;
  int frames = 0;
  for (int guard = 0; guard < 10 && bag.next(frame) == Source::Status::frame; ++guard) {
    ++frames;
    RobotState state;
    EXPECT_FALSE(states->state_at(frame.timestamp_ns, state)) << "frame " << frame.index;
  }
  EXPECT_EQ(frames, 4);
  EXPECT_EQ(states->stats().samples.accepted, 0);
  EXPECT_EQ(states->stats().samples.rejected_backwards, 3);
}

TEST(RecordedJointStates, NoneWithoutTheTopicOrWhenNotAskedFor) {
  ScratchDir dir("joints");
  {
    BagWriter writer(dir / "plain.bag");
    writer.add_depth(tiny_frame(0));
  }
  RecordingParams params{dir / "plain.bag"};
  params.with_joint_states = true;
  EXPECT_EQ(BagSource(params).recorded_robot_state(), nullptr) << "the bag has no /hrcsense/joint_states";
  write_joint_bag(dir / "j.bag");
  EXPECT_EQ(BagSource(RecordingParams{dir / "j.bag"}).recorded_robot_state(), nullptr) << "not asked for";
}

TEST(RecordedJointStates, AMalformedStateEndsThePlaybackNamingFileFrameAndField) {
  ScratchDir dir("joints");
  {
    BagWriterParams params;
    params.joint_names = {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
                          "gripper_joint"};  // no wrist 3
    BagWriter writer(dir / "bad.bag", params);
    writer.add_joint_state(tiny_frame(0).timestamp_ns, q_of(0));
    writer.add_depth(tiny_frame(0));
    writer.add_joint_state(tiny_frame(1).timestamp_ns, q_of(1));
    writer.add_depth(tiny_frame(1));
  }
  RecordingParams params{dir / "bad.bag"};
  // Without joint states the same bag plays: a recording's robot topic is not its depth.
  BagSource plain(params);
  Frame frame;
  EXPECT_EQ(plain.next(frame), Source::Status::frame);
  EXPECT_EQ(plain.next(frame), Source::Status::frame);
  params.with_joint_states = true;
  try {
    BagSource bag(params);
    FAIL() << "the first joint state comes before the first frame: opening fails";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(dir / "bad.bag"), std::string::npos) << what;
    EXPECT_NE(what.find("/hrcsense/joint_states"), std::string::npos) << what;
    EXPECT_NE(what.find("before frame 0"), std::string::npos) << what;
    EXPECT_NE(what.find("no joint wrist_3_joint"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace hrcsense

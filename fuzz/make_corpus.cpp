// SPDX-License-Identifier: Apache-2.0
// Writes the fuzzers' seed corpus: tiny valid inputs (a few hundred bytes to a few KB each).
// Usage: hrcsense-fuzz-corpus <fuzz/corpus>. The files are committed; rerun after a format change.
#include "../tests/support/bag_writer.hpp"
#include "fuzz_entries.hpp"
#include "hrcsense/net/link.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <vector>

namespace {

using namespace hrcsense;

Frame tiny_frame(int64_t index) {
  Frame frame;
  frame.index = index;
  frame.timestamp_ns = 1'000'000'123LL + index * 33'333'333LL;
  frame.depth.resize(8, 6);
  for (size_t i = 0; i < frame.depth.pixels.size(); ++i) {
    frame.depth.pixels[i] = static_cast<uint16_t>(700 + 3 * i + static_cast<size_t>(index));
  }
  frame.intrinsics = Intrinsics{8, 6, 6.5F, 6.25F, 3.5F, 2.5F, Distortion::brown_conrady, {0.1F, -0.05F, 0, 0, 0.01F}};
  return frame;
}

void write_bag(const std::string& path, const test::BagWriterParams& params, bool color) {
  test::BagWriter writer(path, params);
  for (int64_t i = 0; i < 2; ++i) {
    const Frame frame = tiny_frame(i);
    writer.add_depth(frame);
    if (color && i == 0) {
      ColorImage rgb{4, 3, std::vector<uint8_t>(4 * 3 * 3, 0x80)};
      Pose T = Pose::Identity();
      T.translation() = Eigen::Vector3d(0.015, 0, 0);
      writer.add_color(frame.timestamp_ns + 5, static_cast<uint32_t>(frame.index), rgb,
                       Intrinsics{4, 3, 3.0F, 3.0F, 1.5F, 1.0F}, T);
    }
  }
  writer.close();
}

/// Two frames, each after its robot joint state with UR's names and velocities, as hrcsense
/// records them (/hrcsense/joint_states).
void write_joint_state_bag(const std::string& path) {
  test::BagWriterParams params;
  params.sdk_metadata = false;
  params.joint_names.assign(kUrJointNames.begin(), kUrJointNames.end());
  test::BagWriter writer(path, params);
  for (int64_t i = 0; i < 2; ++i) {
    const Frame frame = tiny_frame(i);
    const double t = 0.1 * static_cast<double>(i);
    writer.add_joint_state(frame.timestamp_ns, JointAngles{t, -1.0, 1.5, -2.0, 0.5, -t}, JointAngles{1, 0, 0, 0, 0, -1});
    writer.add_depth(frame);
  }
  writer.close();
}

void write_bytes(const std::filesystem::path& path, const uint8_t* bytes, size_t size) {
  std::ofstream file(path, std::ios::binary | std::ios::trunc);
  file.write(reinterpret_cast<const char*>(bytes), static_cast<std::streamsize>(size));
}

/// The link's datagrams (version 2, docs/SAFETY.md): one of each kind from one session, a frame
/// without a contact, a damaged CRC, a truncated datagram, and a version 1 frame (41 bytes, no
/// session), which the decoder must refuse by name.
void write_link_seeds(const std::filesystem::path& folder) {
  constexpr uint32_t kSession = 0x5EED0001U;
  constexpr float kNoContact = std::numeric_limits<float>::quiet_NaN();
  const auto datagram = [](LinkKind kind, uint32_t sequence, int64_t timestamp_ns, VerdictState verdict,
                           ReasonCode reason, float scale, float distance_m, float protective_m, uint16_t age_ms) {
    LinkDatagram d;
    d.kind = kind;
    d.session = kSession;
    d.sequence = sequence;
    d.timestamp_ns = timestamp_ns;
    d.verdict = verdict;
    d.reason = reason;
    d.speed_scale = scale;
    d.distance_m = distance_m;
    d.protective_distance_m = protective_m;
    d.robot_state_age_ms = age_ms;
    return encode_link_datagram(d);
  };
  const LinkBytes frame = datagram(LinkKind::frame, 41, 1'234'567'890'123, VerdictState::slow,
                                   ReasonCode::in_slow_zone, 0.5F, 0.8F, 1.0F, 4);
  write_bytes(folder / "frame", frame.data(), frame.size());
  const LinkBytes no_contact = datagram(LinkKind::frame, 42, 1'234'600'000'000, VerdictState::run,
                                        ReasonCode::no_foreground, 1.0F, kNoContact, 0.5F, 3);
  write_bytes(folder / "no_contact", no_contact.data(), no_contact.size());
  const LinkBytes heartbeat = datagram(LinkKind::heartbeat, 43, 1'234'600'000'000, VerdictState::stop,
                                       ReasonCode::no_frame, 0.0F, kNoContact, 0.0F, 0);
  write_bytes(folder / "heartbeat", heartbeat.data(), heartbeat.size());
  const LinkBytes final_stop = datagram(LinkKind::final_stop, 44, 1'234'600'000'000, VerdictState::stop,
                                        ReasonCode::frame_limit_reached, 0.0F, kNoContact, 0.0F, 0);
  write_bytes(folder / "final_stop", final_stop.data(), final_stop.size());
  LinkBytes bad_crc = datagram(LinkKind::frame, 45, 1'234'633'333'333, VerdictState::stop,
                               ReasonCode::in_stop_zone, 0.0F, 0.2F, 0.5F, 5);
  bad_crc[kLinkDatagramSize - 1] ^= 0x5A;
  write_bytes(folder / "bad_crc", bad_crc.data(), bad_crc.size());
  const LinkBytes short_source = datagram(LinkKind::frame, 46, 1, VerdictState::run, ReasonCode::no_foreground,
                                          1.0F, kNoContact, 0.0F, 0);
  write_bytes(folder / "short", short_source.data(), 20);
  // Version 1: the same layout up to byte 36, then the CRC-32 of bytes 0..36; no session.
  std::vector<uint8_t> version1(frame.begin(), frame.begin() + 37);
  version1[4] = 1;
  const uint32_t crc = crc32_ieee(version1.data(), version1.size());
  for (int i = 0; i < 4; ++i) version1.push_back(static_cast<uint8_t>(crc >> (8 * i)));
  write_bytes(folder / "version1", version1.data(), version1.size());
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s <corpus folder>\n", argv[0]);
    return 2;
  }
  const std::filesystem::path root(argv[1]);
  std::filesystem::create_directories(root / "bag");
  std::filesystem::create_directories(root / "folder");
  std::filesystem::create_directories(root / "link");
  write_link_seeds(root / "link");
  test::BagWriterParams lz4;
  lz4.stereo_baseline_mm = 50.0F;
  write_bag((root / "bag/lz4_indexed_color.bag").string(), lz4, true);
  test::BagWriterParams none;
  none.compression = test::BagCompression::none;
  none.write_index = false;
  write_bag((root / "bag/none_unindexed.bag").string(), none, false);
  test::BagWriterParams old_sdk;
  old_sdk.trailing_depth_units = false;
  old_sdk.depth_units_option_m = 0.0001F;
  old_sdk.file_version = 3;
  write_bag((root / "bag/lz4_units_option.bag").string(), old_sdk, false);
  write_joint_state_bag((root / "bag/lz4_joint_states.bag").string());
  const char* names[fuzz::kFolderTargets] = {"depth_png", "dataset_json", "frames_txt", "color_png",
                                             "color_jpeg", "depth_txt", "rgb_txt", "hrcsense_json"};
  for (int t = 0; t < fuzz::kFolderTargets; ++t) {
    std::ofstream file(root / "folder" / names[t], std::ios::binary | std::ios::trunc);
    file << fuzz::folder_seed(static_cast<fuzz::FolderTarget>(t));
  }
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
// hrcsense — the SDK's messages as the .bag writer serialises them (bag_writer_messages.hpp).
#include "bag_writer_messages.hpp"

#include <algorithm>
#include <cstring>

namespace hrcsense::bag_write {

// Byte by byte rather than one 4-byte insert: inlined into a message builder's fresh vector,
// the insert makes GCC 12 warn falsely (-Wstringop-overflow), and CI builds with -Werror.
void put32(std::vector<uint8_t>& b, uint32_t v) {
  for (int shift = 0; shift < 32; shift += 8) b.push_back(static_cast<uint8_t>(v >> shift));
}
void put64(std::vector<uint8_t>& b, uint64_t v) {
  put32(b, static_cast<uint32_t>(v));
  put32(b, static_cast<uint32_t>(v >> 32));
}
void put_f32(std::vector<uint8_t>& b, float v) {
  uint32_t bits = 0;
  std::memcpy(&bits, &v, 4);
  put32(b, bits);
}
void put_f64(std::vector<uint8_t>& b, double v) {
  uint64_t bits = 0;
  std::memcpy(&bits, &v, 8);
  put64(b, bits);
}
void put_string(std::vector<uint8_t>& b, const std::string& s) {
  put32(b, static_cast<uint32_t>(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
void put_time(std::vector<uint8_t>& b, int64_t ns) {
  const int64_t t = std::max<int64_t>(ns, 0);
  put32(b, static_cast<uint32_t>(t / 1000000000LL));
  put32(b, static_cast<uint32_t>(t % 1000000000LL));
}

std::vector<uint8_t> camera_info_message(const Intrinsics& in) {
  std::vector<uint8_t> b;
  put32(b, 0);  // header: seq, stamp, frame_id (the SDK leaves it default)
  put_time(b, 0);
  put_string(b, "");
  put32(b, static_cast<uint32_t>(in.height));
  put32(b, static_cast<uint32_t>(in.width));
  put_string(b, std::string(distortion_name(in.model)));
  put32(b, 5);
  for (float c : in.coeffs) put_f64(b, c);
  const double k[9] = {in.fx, 0.0, in.ppx, 0.0, in.fy, in.ppy, 0.0, 0.0, 1.0};
  for (double v : k) put_f64(b, v);
  for (int i = 0; i < 9 + 12; ++i) put_f64(b, 0.0);  // R, P: the SDK leaves them zero
  put32(b, 0);                                      // binning_x, binning_y
  put32(b, 0);
  for (int i = 0; i < 4; ++i) put32(b, 0);  // roi
  b.push_back(0);
  return b;
}

std::vector<uint8_t> transform_message(const Pose& T) {
  std::vector<uint8_t> b;
  const Eigen::Quaterniond q(T.linear());
  for (double v : {T.translation().x(), T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w()}) {
    put_f64(b, v);
  }
  return b;
}

std::vector<uint8_t> stream_info_message(uint32_t fps, const std::string& encoding) {
  std::vector<uint8_t> b;
  put32(b, fps);
  put_string(b, encoding);
  b.push_back(1);  // is_recommended
  return b;
}

std::vector<uint8_t> key_value_message(const std::string& key, const std::string& value) {
  std::vector<uint8_t> b;
  put_string(b, key);
  put_string(b, value);
  return b;
}

std::vector<uint8_t> string_message(const std::string& text) {
  std::vector<uint8_t> b;
  put_string(b, text);
  return b;
}

std::vector<uint8_t> u32_message(uint32_t v) {
  std::vector<uint8_t> b;
  put32(b, v);
  return b;
}

std::vector<uint8_t> f32_message(float v) {
  std::vector<uint8_t> b;
  put_f32(b, v);
  return b;
}

Pose extrinsics_pose(const Extrinsics& e) {
  Pose T = Pose::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) T.linear()(i, j) = e.rotation[static_cast<size_t>(3 * j + i)];
  }
  T.translation() = Eigen::Vector3d(e.translation_m[0], e.translation_m[1], e.translation_m[2]);
  return T;
}

}  // namespace hrcsense::bag_write

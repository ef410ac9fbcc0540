// SPDX-License-Identifier: Apache-2.0
// The RTDE reader's per-package work: framing (split_package) and decoding (parse_data_package) of
// the data packages of hrcsense's output recipe (kOutputVariables: 180 bytes each), as a byte
// stream of 64 packages is drained from the socket. Packages/s is the figure: a 500 Hz
// controller needs 500 of them per second.
#include "src/net/rtde_protocol.hpp"

#include <benchmark/benchmark.h>

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense {
namespace {

constexpr int kPackagesPerStream = 64;

// The recipe a controller's reply to kOutputVariables gives (protocol 2 types, in order).
rtde::OutputRecipe hrcsense_recipe() {
  rtde::SetupReply reply;
  reply.recipe_id = 1;
  reply.types = {"DOUBLE", "VECTOR6D", "VECTOR6D", "INT32", "INT32", "DOUBLE", "DOUBLE", "VECTOR6D"};
  rtde::OutputRecipe recipe;
  std::string error;
  if (!rtde::make_output_recipe(reply, rtde::kOutputVariables, recipe, error)) throw std::runtime_error(error);
  return recipe;
}

void put_be(std::vector<uint8_t>& out, uint64_t bits, int bytes) {
  for (int shift = 8 * (bytes - 1); shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(bits >> shift));
}

void put_double(std::vector<uint8_t>& out, double v) {
  uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  put_be(out, bits, 8);
}

// `count` data packages of the recipe, back to back, with a moving timestamp and joints.
std::vector<uint8_t> data_stream(int count) {
  std::vector<uint8_t> stream;
  for (int k = 0; k < count; ++k) {
    std::vector<uint8_t> payload{1};  // recipe id
    put_double(payload, 16412.206 + 0.002 * k);                            // timestamp
    for (int j = 0; j < 6; ++j) put_double(payload, 0.1 * j + 1e-3 * k);  // actual_q
    for (int j = 0; j < 6; ++j) put_double(payload, 0.05 * j);            // actual_qd
    put_be(payload, 7, 4);                                                 // robot_mode: running
    put_be(payload, 1, 4);                                                 // safety_mode: normal
    put_double(payload, 1.0);                                              // speed_scaling
    put_double(payload, 1.0);                                              // target_speed_fraction
    for (int j = 0; j < 6; ++j) put_double(payload, 0.2 * j);             // actual_TCP_pose
    put_be(stream, payload.size() + rtde::kHeaderSize, 2);
    stream.push_back(static_cast<uint8_t>(rtde::PackageType::data));
    stream.insert(stream.end(), payload.begin(), payload.end());
  }
  return stream;
}

// One package decoded again and again: the parser alone.
void Rtde_parse_data(benchmark::State& state) {
  const rtde::OutputRecipe recipe = hrcsense_recipe();
  const std::vector<uint8_t> bytes = data_stream(1);
  const rtde::Package frame = rtde::split_package(bytes.data(), bytes.size()).package;
  rtde::DataSample sample;
  std::string error;
  for (auto _ : state) {
    const bool ok = rtde::parse_data_package(frame, recipe, sample, error);
    benchmark::DoNotOptimize(ok);
    benchmark::DoNotOptimize(sample);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(Rtde_parse_data)->Name("Rtde/parse_data/180B");

// A received buffer of 64 packages framed and decoded as the reader thread does.
void Rtde_split_and_parse(benchmark::State& state) {
  const rtde::OutputRecipe recipe = hrcsense_recipe();
  const std::vector<uint8_t> bytes = data_stream(kPackagesPerStream);
  rtde::DataSample sample;
  std::string error;
  for (auto _ : state) {
    size_t at = 0;
    int parsed = 0;
    while (at < bytes.size()) {
      const rtde::PackageSplit split = rtde::split_package(bytes.data() + at, bytes.size() - at);
      if (split.status != rtde::SplitStatus::package) break;
      parsed += rtde::parse_data_package(split.package, recipe, sample, error) ? 1 : 0;
      at += split.consumed;
    }
    benchmark::DoNotOptimize(parsed);
    benchmark::DoNotOptimize(sample);
  }
  state.SetItemsProcessed(state.iterations() * kPackagesPerStream);
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(Rtde_split_and_parse)->Name("Rtde/split_and_parse/stream_64x180B");

}  // namespace
}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: any bytes as a stream from an RTDE controller, framed by split_package and each
// package given to the parser of its type, as the client does: a setup reply becomes the recipe
// for the data packages after it (hrcsense's own recipe until then). Nothing may read past a
// package, crash or loop; a size below 3 ends the stream, as it ends the client's connection.
#include "src/net/rtde_protocol.hpp"

#include <cstddef>
#include <cstdint>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace hrcsense::rtde;
  OutputRecipe recipe;
  std::string error;
  SetupReply own{1, {"DOUBLE", "VECTOR6D", "VECTOR6D", "INT32", "INT32", "DOUBLE", "DOUBLE", "VECTOR6D"}};
  if (!make_output_recipe(own, kOutputVariables, recipe, error)) __builtin_trap();
  size_t at = 0;
  while (at < size) {
    const PackageSplit split = split_package(data + at, size - at);
    if (split.status != SplitStatus::package) break;  // truncated at the end, or malformed
    if (split.consumed < kHeaderSize || split.consumed > size - at) __builtin_trap();
    at += split.consumed;
    const Package& frame = split.package;
    bool accepted = false;
    ControllerVersion version;
    TextMessage text;
    SetupReply reply;
    DataSample sample;
    switch (static_cast<PackageType>(frame.type)) {
      case PackageType::request_protocol_version:
      case PackageType::start:
      case PackageType::pause:
        parse_accepted(frame, static_cast<PackageType>(frame.type), accepted, error);
        break;
      case PackageType::get_urcontrol_version: parse_controller_version(frame, version, error); break;
      case PackageType::text_message: parse_text_message(frame, text, error); break;
      case PackageType::setup_outputs:
      case PackageType::setup_inputs:
        if (parse_setup_reply(frame, static_cast<PackageType>(frame.type), reply, error)) {
          OutputRecipe next;
          if (make_output_recipe(reply, kOutputVariables, next, error)) recipe = next;
        }
        break;
      case PackageType::data: parse_data_package(frame, recipe, sample, error); break;
      default: break;  // unknown: skipped by its size
    }
  }
  return 0;
}

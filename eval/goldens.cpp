// SPDX-License-Identifier: Apache-2.0
// hrcsense — the golden comparison (goldens.hpp): each case of an SDK golden set parsed from
// cases.json into a filter chain, its inputs read and cropped, the chain run block by block
// (with a disparity tap where the case saves one) and every output compared bit for bit.
#include "hrcsense/eval/goldens.hpp"

#include "hrcsense/filters.hpp"
#include "hrcsense/io/io.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace hrcsense::eval {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// A case as it runs: the chain, where a disparity tap is taken, and the frames.
struct GoldenCase {
  std::string name;
  FilterChainParams chain;
  int tap_after = -1;  ///< index in chain.order after which the "save" tap is taken; -1 none
  Intrinsics intrinsics;
  float depth_scale_m = 0.001F;
  float baseline_mm = 0.0F;
  std::vector<std::string> inputs;  ///< absolute paths
  json crop;                        ///< null or {x, y, width, height}
};

[[noreturn]] void bad_case(const std::string& name, const std::string& what) {
  throw std::runtime_error("case '" + name + "': " + what);
}

// An integer option: the SDK's options are floats in cases.json and truncate, as its uint8 options
// do; a missing one keeps `value` (the params struct's default).
void integer_option(const json& options, const char* key, int& value) {
  value = static_cast<int>(options.value(key, static_cast<double>(value)));
}

// Every option missing from a case keeps the default of FilterChainParams (filters.hpp), which
// are the SDK's defaults.
void read_block_options(const std::string& name, const json& step, FilterChainParams& chain) {
  const std::string filter = step.at("filter").get<std::string>();
  const json options = step.value("options_friendly", json::object());
  const auto block = filter_block_from_name(filter);
  if (!block) bad_case(name, "unknown filter '" + filter + "'");
  chain.order.push_back(*block);
  switch (*block) {
    case FilterBlock::threshold:
      chain.threshold.min_m = options.value("min", chain.threshold.min_m);
      chain.threshold.max_m = options.value("max", chain.threshold.max_m);
      break;
    case FilterBlock::decimation:
      integer_option(options, "magnitude", chain.decimation.magnitude);
      break;
    case FilterBlock::spatial:
      chain.spatial.alpha = options.value("alpha", chain.spatial.alpha);
      integer_option(options, "delta", chain.spatial.delta);
      integer_option(options, "magnitude", chain.spatial.magnitude);
      integer_option(options, "holes_fill", chain.spatial.holes_fill);
      break;
    case FilterBlock::temporal:
      chain.temporal.alpha = options.value("alpha", chain.temporal.alpha);
      integer_option(options, "delta", chain.temporal.delta);
      integer_option(options, "persistence", chain.temporal.persistence);
      break;
    case FilterBlock::hole_filling:
      integer_option(options, "mode", chain.hole_filling.mode);
      break;
    case FilterBlock::to_disparity:
    case FilterBlock::to_depth:
      break;
  }
}

GoldenCase parse_case(const json& item, const fs::path& shared_dir) {
  GoldenCase c;
  c.name = item.at("name").get<std::string>();
  for (const json& step : item.at("chain")) {
    if (step.at("filter").get<std::string>() == "save") {
      c.tap_after = static_cast<int>(c.chain.order.size()) - 1;
      continue;
    }
    read_block_options(c.name, step, c.chain);
  }
  const std::string order_problem = check_filter_order(c.chain.order);
  if (!order_problem.empty()) bad_case(c.name, order_problem);
  const json& si = item.at("stream_intrinsics");
  c.intrinsics.width = si.at("width").get<int>();
  c.intrinsics.height = si.at("height").get<int>();
  c.intrinsics.fx = si.at("fx").get<float>();
  c.intrinsics.fy = si.at("fy").get<float>();
  c.intrinsics.ppx = si.at("ppx").get<float>();
  c.intrinsics.ppy = si.at("ppy").get<float>();
  c.intrinsics.model = Distortion::brown_conrady;
  c.depth_scale_m = item.at("depth_units").get<float>();
  c.baseline_mm = item.value("stereo_baseline_mm", 0.0F);
  for (const json& input : item.at("inputs")) c.inputs.push_back((shared_dir / input.get<std::string>()).string());
  c.crop = item.value("crop", json());
  return c;
}

// Reads input `path` into frame.depth, cropped as the case says.
void load_input(const GoldenCase& c, const std::string& path, DepthImage& scratch, Frame& frame) {
  read_depth_png(path, scratch);
  int x = 0, y = 0, w = scratch.width, h = scratch.height;
  if (!c.crop.is_null()) {
    x = c.crop.at("x").get<int>();
    y = c.crop.at("y").get<int>();
    w = c.crop.at("width").get<int>();
    h = c.crop.at("height").get<int>();
    if (x < 0 || y < 0 || x + w > scratch.width || y + h > scratch.height) bad_case(c.name, "crop outside " + path);
  }
  if (w != c.intrinsics.width || h != c.intrinsics.height) {
    bad_case(c.name, path + " is " + std::to_string(w) + "x" + std::to_string(h) + " after cropping; intrinsics say " +
                         std::to_string(c.intrinsics.width) + "x" + std::to_string(c.intrinsics.height));
  }
  frame.depth.depth_scale_m = c.depth_scale_m;
  frame.depth.resize(w, h);
  for (int v = 0; v < h; ++v) {
    const uint16_t* src = scratch.pixels.data() + static_cast<size_t>(v + y) * scratch.width + x;
    std::copy(src, src + w, frame.depth.pixels.data() + static_cast<size_t>(v) * w);
  }
  frame.intrinsics = c.intrinsics;
  frame.stereo_baseline_mm = c.baseline_mm;
}

std::vector<float> read_f32(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  in.seekg(0, std::ios::end);
  const auto bytes = static_cast<size_t>(in.tellg());
  in.seekg(0);
  std::vector<float> values(bytes / sizeof(float));
  in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(float)));
  return values;
}

// One golden output as it is compared: its file as cases.json names it, its frame and width.
struct GoldenOutput {
  std::string file;
  int64_t frame_index = 0;
  int width = 0;
};

template <typename T>
void compare(const std::vector<T>& ours, const std::vector<T>& sdk, const GoldenOutput& where, GoldenCaseResult& result) {
  for (size_t i = 0; i < ours.size(); ++i) {
    // Bit-level equality for floats too (a NaN or -0 in the golden must be reproduced).
    if (std::memcmp(&ours[i], &sdk[i], sizeof(T)) == 0) continue;
    ++result.values_differing;
    result.largest_difference =
        std::max(result.largest_difference, std::fabs(static_cast<double>(ours[i]) - static_cast<double>(sdk[i])));
    if (!result.first_mismatch) {
      const int x = static_cast<int>(i % static_cast<size_t>(where.width));
      const int y = static_cast<int>(i / static_cast<size_t>(where.width));
      result.first_mismatch =
          GoldenMismatch{where.file, where.frame_index, x, y, static_cast<double>(ours[i]), static_cast<double>(sdk[i])};
    }
  }
}

bool close_to(float ours, double sdk) { return std::fabs(static_cast<double>(ours) - sdk) <= 1e-5 * std::fabs(sdk) + 1e-6; }

// Compares one golden output with what the chain produced for its frame.
void check_output(const json& output, const fs::path& golden_dir, const Frame& frame, const DisparityImage* tap,
                  GoldenCaseResult& result) {
  const GoldenOutput where{output.at("file").get<std::string>(), output.at("frame_index").get<int64_t>(),
                           output.at("width").get<int>()};
  const std::string file = (golden_dir / where.file).string();
  const int w = where.width;
  const int h = output.at("height").get<int>();
  if (output.at("format").get<std::string>() == "DISPARITY32") {
    if (tap == nullptr || tap->width != w || tap->height != h) {
      result.problem = "no disparity tap of " + std::to_string(w) + "x" + std::to_string(h);
      return;
    }
    const std::vector<float> sdk = read_f32(file);
    if (sdk.size() != tap->pixels.size()) throw std::runtime_error(file + ": expected " + std::to_string(w * h) + " floats");
    return compare(tap->pixels, sdk, where, result);
  }
  if (frame.depth.width != w || frame.depth.height != h) {
    result.problem = "size " + std::to_string(frame.depth.width) + "x" + std::to_string(frame.depth.height) +
                   ", SDK " + std::to_string(w) + "x" + std::to_string(h);
    return;
  }
  const json& in = output.at("intrinsics");
  if (!close_to(frame.intrinsics.fx, in.at("fx").get<double>()) || !close_to(frame.intrinsics.fy, in.at("fy").get<double>()) ||
      !close_to(frame.intrinsics.ppx, in.at("ppx").get<double>()) ||
      !close_to(frame.intrinsics.ppy, in.at("ppy").get<double>())) {
    result.problem = "intrinsics differ";
  }
  DepthImage sdk;
  read_depth_png(file, sdk);
  if (sdk.width != w || sdk.height != h) throw std::runtime_error(file + ": size differs from cases.json");
  compare(frame.depth.pixels, sdk.pixels, where, result);
}

// Runs one case, filling `result` as it goes (so that a case that throws part way keeps what
// it compared before).
void run_case(const json& item, const fs::path& shared_dir, const fs::path& golden_dir, GoldenCaseResult& result) {
  const GoldenCase c = parse_case(item, shared_dir);
  result.name = c.name;
  FilterChain chain;
  chain.params = c.chain;
  Frame input, output;
  DepthImage scratch;
  DisparityImage tap;
  for (size_t f = 0; f < c.inputs.size(); ++f) {
    load_input(c, c.inputs[f], scratch, input);
    input.index = static_cast<int64_t>(f);
    chain.start(input, output);
    for (size_t b = 0; b < chain.block_count(); ++b) {
      chain.run_block(b, output);
      if (static_cast<int>(b) == c.tap_after) tap = chain.disparity();
    }
    for (const json& out : item.at("outputs")) {
      if (out.at("frame_index").get<size_t>() != f) continue;
      const bool is_tap = out.at("format").get<std::string>() == "DISPARITY32";
      check_output(out, golden_dir, output, is_tap && c.tap_after >= 0 ? &tap : nullptr, result);
      ++result.outputs_checked;
    }
  }
  if (result.outputs_checked != item.at("outputs").size()) result.problem = "outputs for frames that have no input";
}

// The name a case is reported under, even when its entry is malformed.
std::string case_name(const json& item) {
  if (item.is_object() && item.contains("name") && item.at("name").is_string()) return item.at("name").get<std::string>();
  return "<unnamed>";
}

}  // namespace

size_t GoldenReport::bit_exact() const {
  return static_cast<size_t>(
      std::count_if(cases.begin(), cases.end(), [](const GoldenCaseResult& c) { return c.match(); }));
}

GoldenReport verify_filter_goldens(const std::string& cases_json, const std::string& shared_dir) {
  std::ifstream file(cases_json);
  if (!file) throw GoldenFileError(cases_json + ": cannot open cases file");
  json root;
  try {
    root = json::parse(file);
  } catch (const json::exception& e) {
    throw GoldenFileError(cases_json + ": not valid JSON: " + e.what());
  }
  if (!root.contains("cases") || !root.at("cases").is_array()) {
    throw GoldenFileError(cases_json + ": expected a \"cases\" array");
  }
  const fs::path golden_dir = fs::path(cases_json).parent_path();
  GoldenReport report;
  for (const json& item : root.at("cases")) {
    GoldenCaseResult& result = report.cases.emplace_back();
    result.name = case_name(item);
    try {
      run_case(item, shared_dir, golden_dir, result);
    } catch (const std::exception& e) {
      // One broken case (a missing input, a bad option) is reported and the others still run.
      result.error = e.what();
    }
  }
  return report;
}

}  // namespace hrcsense::eval

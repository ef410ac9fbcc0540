// SPDX-License-Identifier: Apache-2.0
// The code each fuzz target runs on one input, shared by the libFuzzer targets (clang, preset
// fuzz) and by tests/recordings/fuzz_corpus_test.cpp (GCC), which replays the seed corpus and
// every crash reproducer in fuzz/regressions/ through the very same path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace hrcsense::fuzz {

/// What one input did: frames delivered, then "" (clean end) or the source's error message.
/// Anything but an IoError escaping (or a sanitizer report) is a bug the fuzzer reports.
struct Outcome {
  int frames = 0;
  std::string error;
};

/// The bytes as a .bag file (in memory where the system allows, else a temp file), played by
/// BagSource with colour decoding on until its end or first error, then summarised as
/// `hrcsense info` does.
Outcome run_bag(const uint8_t* data, size_t size);

/// Which file of an otherwise valid recording folder an input of run_folder replaces: its
/// first byte modulo kFolderTargets; the remaining bytes are the file's content.
enum class FolderTarget : uint8_t {
  depth_png = 0,        ///< ist layout: depth/000000.png
  dataset_json = 1,     ///< ist layout: intrinsics.json (the datasets' form)
  frames_txt = 2,       ///< ist layout: frames.txt
  color_png = 3,        ///< ist layout: rgb/000000.png
  color_jpeg = 4,       ///< ist layout: rgb/000001.jpg
  depth_txt = 5,        ///< TUM layout: depth.txt
  rgb_txt = 6,          ///< TUM layout: rgb.txt
  hrcsense_json = 7,    ///< TUM layout: intrinsics.json (hrcsense's own form)
};
inline constexpr int kFolderTargets = 8;

/// Writes the input into its folder (a per-process temp folder, rebuilt valid around it) and
/// plays that folder with FolderSource (colour on) to its end or first error, then summarises it.
Outcome run_folder(const uint8_t* data, size_t size);

/// The valid content run_folder starts from for `target`, prefixed with the selector byte: the
/// seed corpus (fuzz/make_corpus.cpp writes it).
std::string folder_seed(FolderTarget target);

/// The bytes as a YAML configuration file, read by load_config. Either it loads, and then every
/// parameter the stages use is finite, or it fails with a ConfigError naming the file; anything
/// else (another exception, a crash, a sanitizer report) breaks the contract. Outcome::error is
/// the ConfigError's message ("" when the file loaded); frames is 1 when it loaded.
Outcome run_config(const uint8_t* data, size_t size);

}  // namespace hrcsense::fuzz

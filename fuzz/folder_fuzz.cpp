// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the first byte picks a file of a valid recording folder (depth PNG, colour
// PNG or JPEG, intrinsics.json, frames.txt, depth.txt, rgb.txt), the rest replaces it; the
// folder is then played by FolderSource (fuzz_entries.cpp).
#include "fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hrcsense::fuzz::run_folder(data, size);
  return 0;
}

// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: any bytes as a RealSense .bag, played by BagSource (fuzz_entries.cpp).
#include "fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hrcsense::fuzz::run_bag(data, size);
  return 0;
}

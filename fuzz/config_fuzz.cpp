// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: any bytes as a YAML configuration file, read by load_config (the strict
// YAML reader, every key's typed and bounded read, robot descriptions named in it), checked by
// run_config (fuzz_entries.cpp): a ConfigError naming the file, or finite stage parameters.
#include "fuzz_entries.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  hrcsense::fuzz::run_config(data, size);
  return 0;
}

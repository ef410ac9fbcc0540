// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense devices`: the RealSense cameras connected and what they offer.
#include "commands.hpp"

#include "common/assembly.hpp"

#include <cstdio>

namespace hrcsense::app {

int devices_command() {
  // Without the SDK, list_cameras throws the ConfigError that says how to get it (exit 2).
  const std::string text = format_devices(list_cameras());
  std::fputs(text.c_str(), stdout);
  return 0;
}

}  // namespace hrcsense::app

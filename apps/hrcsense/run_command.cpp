// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense run`: configured source → pipeline → JSON Lines (+ progress on stderr).
#include "commands.hpp"
#include "common/run_session.hpp"

#include "hrcsense/config/config.hpp"

namespace hrcsense::app {

int run_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets, args.camera);
  SessionOptions options;
  options.frames = args.frames;
  options.out = args.out;
  options.record = args.record;
  options.overwrite = args.overwrite;
  return run_session(config, options);
}

}  // namespace hrcsense::app

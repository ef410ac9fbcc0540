// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense fuse`: the decision of a cell with several cameras (fuse_session.hpp).
#include "commands.hpp"
#include "common/fuse_session.hpp"

#include "hrcsense/config/config.hpp"

namespace hrcsense::app {

int fuse_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  FuseOptions options;
  options.frames = args.frames;
  options.out = args.out;
  return fuse_session(config, options);
}

}  // namespace hrcsense::app

// SPDX-License-Identifier: Apache-2.0
// hrcsense CLI — `hrcsense cell`: a cell with several cameras on one host (docs/MULTICAMERA.md):
// one `hrcsense run --camera NAME` process per configured camera and one `hrcsense fuse`, as
// children, on the same topics as a cell spread over hosts. A child's death is nothing special
// here: the fuser's stale rule stops the cell for a camera that went silent.
#include "commands.hpp"
#include "common/app_errors.hpp"
#include "common/assembly.hpp"
#include "common/stop_signals.hpp"

#include "hrcsense/config/config.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace hrcsense::app {
namespace {

struct Child {
  std::string name;  ///< the camera's, or "fuse"
  pid_t pid = -1;
  bool running = false;
  int status = 0;
};

pid_t spawn(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, "/proc/self/exe", nullptr, nullptr, argv.data(), environ);
  if (error != 0) throw std::runtime_error("hrcsense cell: cannot start " + args[1] + ": " + std::strerror(error));
  return pid;
}

// `hrcsense run`/`fuse` with the cell's configuration and overrides.
std::vector<std::string> child_args(const CommandArgs& args, const std::string& command) {
  std::vector<std::string> out = {"hrcsense", command};
  if (!args.config_path.empty()) out.insert(out.end(), {"--config", args.config_path});
  for (const std::string& set : args.sets) out.insert(out.end(), {"--set", set});
  return out;
}

// FILE.jsonl → FILE.<camera>.jsonl: each camera's own run, beside the fused output.
std::string camera_out(const std::string& out, const std::string& camera) {
  if (out.empty()) return "/dev/null";
  const std::filesystem::path path(out);
  return (path.parent_path() / (path.stem().string() + "." + camera + path.extension().string())).string();
}

void reap(std::vector<Child>& children) {
  for (Child& child : children) {
    if (!child.running) continue;
    int status = 0;
    if (waitpid(child.pid, &status, WNOHANG) == child.pid) {
      child.running = false;
      child.status = status;
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      spdlog::log(code == 0 ? spdlog::level::info : spdlog::level::warn, "cell: {} ended (exit {})", child.name, code);
    }
  }
}

// SIGTERM to every child still running, then up to `grace_s` for them to end, then SIGKILL.
void end_all(std::vector<Child>& children, double grace_s) {
  for (const Child& child : children) {
    if (child.running) kill(child.pid, SIGTERM);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(grace_s);
  while (std::chrono::steady_clock::now() < deadline) {
    reap(children);
    bool any = false;
    for (const Child& child : children) any = any || child.running;
    if (!any) return;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (Child& child : children) {
    if (!child.running) continue;
    kill(child.pid, SIGKILL);
    waitpid(child.pid, &child.status, 0);
    child.running = false;
    spdlog::warn("cell: {} did not end within {:g} s and was killed", child.name, grace_s);
  }
}

}  // namespace

int cell_command(const CommandArgs& args) {
  const Config config = load_config(args.config_path, args.sets);
  if (config.cameras.empty()) {
    return report_error(config_where(config) + ": hrcsense cell needs the cameras: list of a cell with several cameras "
                                               "(docs/MULTICAMERA.md)",
                        kExitUsage);
  }
  const StopSignals signals;
  // Every child, the fuser too: simulated cameras share a scene clock, frame 0 a second from
  // now, so that every process has started by then and all learn their background from the same
  // frames; the fuser publishes the same epoch on <ns>/cell_clock for a camera started by hand.
  std::vector<std::string> common_sets;
  bool simulated = false;
  for (const CameraEntry& entry : config.cameras) simulated = simulated || entry.source_type == SourceType::sim;
  if (simulated && !config.sim_epoch_ns) {
    timespec now{};
    clock_gettime(CLOCK_REALTIME, &now);
    char epoch[64];
    std::snprintf(epoch, sizeof epoch, "sim.epoch=%.6f", static_cast<double>(now.tv_sec + 1) + now.tv_nsec * 1e-9);
    common_sets.emplace_back(epoch);
  }
  // A live robot: the fuser owns its connection and republishes it; the cameras read that.
  const std::vector<std::string> camera_sets = camera_robot_state_sets(config);
  const auto add_sets = [](std::vector<std::string>& to, const std::vector<std::string>& sets) {
    for (const std::string& set : sets) to.insert(to.end(), {"--set", set});
  };

  std::vector<Child> children;
  // The fuser first: its readers are there when the cameras' first measurements come.
  std::vector<std::string> fuse = child_args(args, "fuse");
  add_sets(fuse, common_sets);
  if (!args.out.empty()) fuse.insert(fuse.end(), {"--out", args.out});
  children.push_back({"fuse", spawn(fuse), true, 0});
  for (const CameraEntry& entry : config.cameras) {
    std::vector<std::string> run = child_args(args, "run");
    add_sets(run, common_sets);
    add_sets(run, camera_sets);
    run.insert(run.end(), {"--camera", entry.name, "--out", camera_out(args.out, entry.name)});
    if (args.frames > 0) run.insert(run.end(), {"--frames", std::to_string(args.frames)});
    children.push_back({"camera '" + entry.name + "'", spawn(run), true, 0});
  }
  if (!camera_sets.empty()) {
    spdlog::info("cell: the fuser owns robot.state.source {}; the cameras read {}",
                 robot_state_origin_name(config.robot_state.source), camera_sets[1].substr(camera_sets[1].find('=') + 1));
  }
  spdlog::info("cell: {} cameras and the fuser started{}", config.cameras.size(),
               args.out.empty() ? "" : "; each camera's own run beside " + args.out);

  // Every camera's last measurement says its run ended, and the fuser ends on them. That
  // measurement crosses DDS best-effort like any other: if one is lost, the fuser (rightly) sees
  // a stale camera and goes on stopping. Here the cell knows its cameras have ended, so the fuser
  // gets this long to end by itself, then the signal that makes it write its final stop.
  constexpr auto kFuserEndGrace = std::chrono::seconds(2);
  std::optional<std::chrono::steady_clock::time_point> cameras_ended_at;
  while (true) {
    reap(children);
    if (!children[0].running) break;  // the fuser ended: the cell has
    bool cameras_running = false;
    for (size_t i = 1; i < children.size(); ++i) cameras_running = cameras_running || children[i].running;
    if (!cameras_running && !cameras_ended_at) cameras_ended_at = std::chrono::steady_clock::now();
    if (cameras_ended_at && std::chrono::steady_clock::now() - *cameras_ended_at > kFuserEndGrace) {
      spdlog::info("cell: every camera has ended and the fuser has not within 2 s: it is told to end");
      end_all(children, 10.0);
      break;
    }
    if (StopSignals::stop_requested()) {
      // The fuser writes its final stop when its signal comes; the cameras end theirs alike.
      end_all(children, 10.0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  end_all(children, 10.0);
  const int status = children[0].status;
  return WIFEXITED(status) ? WEXITSTATUS(status) : kExitRuntime;
}

}  // namespace hrcsense::app

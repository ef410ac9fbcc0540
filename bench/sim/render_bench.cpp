// SPDX-License-Identifier: Apache-2.0
// Sim/render/WxH: rendering one frame of config/walk.yaml (a person in the room) with the full
// D435 sensor model, the ground truth and the colour camera at the same resolution, as the
// simulator source delivers it; Sim/render_depth/WxH without the colour camera.

#include "common/assembly.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/sim/sim.hpp"

#include <benchmark/benchmark.h>

#include <string>

namespace hrcsense {
namespace {

/// config/walk.yaml, found relative to this file, so that no machine path is stored.
std::string walk_yaml() {
  const std::string here = __FILE__;
  return here.substr(0, here.rfind("/bench/")) + "/config/walk.yaml";
}

void render(benchmark::State& state, int width, int height, bool color) {
  const std::vector<std::string> sets{"sim.width=" + std::to_string(width), "sim.height=" + std::to_string(height),
                                      std::string("sim.color=") + (color ? "true" : "false")};
  const Simulator sim = make_simulator(load_config(walk_yaml(), sets));
  Frame frame;
  int64_t i = 0;
  for (auto _ : state) {
    // Frames 150-249: the person walks through the room.
    sim.render(150 + (i++ % 100), frame);
    benchmark::DoNotOptimize(frame.depth.pixels.data());
  }
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_Render848(benchmark::State& state) { render(state, 848, 480, true); }
void BM_Render1280(benchmark::State& state) { render(state, 1280, 720, true); }
void BM_RenderDepth848(benchmark::State& state) { render(state, 848, 480, false); }

BENCHMARK(BM_Render848)->Name("Sim/render/848x480")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Render1280)->Name("Sim/render/1280x720")->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RenderDepth848)->Name("Sim/render_depth/848x480")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace hrcsense

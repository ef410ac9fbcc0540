// SPDX-License-Identifier: Apache-2.0
// Monitor/per_link/ur5: the SafetyMonitor's decision of one measurement of a UR5 with a tool
// (8 links, each with a contact, as when a person stands beside the arm), in ssm mode with the
// hysteresis on (two decisions per frame: as measured and with the margin), every link's
// allowed and planned speed solved by bisection over the stopping data. Budget: 50 us
// (DESIGN.md, "per-link decision").
#include "hrcsense/safety.hpp"

#include <benchmark/benchmark.h>

namespace hrcsense {
namespace {

FrameResult ur5_measurement() {
  FrameResult m;
  m.valid = true;
  m.foreground_points = 20'000;
  for (int link = 0; link < 8; ++link) {
    LinkContact l;
    l.link = link;
    l.contact.valid = true;
    // Beyond S_p at each link's present speed (about 1.55 m + 0.56 s · v with S2's T_r), so
    // that every link's allowed and planned speeds are solved, not cut short by a stop.
    l.contact.distance_m = 1.9F + 0.1F * static_cast<float>(link);
    l.contact.robot_link = link;
    l.contact.closest_base = {l.contact.distance_m, 0.0F, 1.0F};
    l.contact.closest_robot_base = {0.0F, 0.0F, 1.0F};
    l.speed_towards_mps = 0.1F * static_cast<float>(link);  // the wrist faster than the base
    l.distance_uncertainty_m = 0.03F;
    m.links.push_back(l);
  }
  m.contact = m.links.front().contact;
  m.unknown_distance_m = 0.8F;
  return m;
}

void BM_MonitorPerLinkUr5(benchmark::State& state) {
  SafetyParams params;
  params.mode = SafetyParams::Mode::ssm;
  params.hysteresis_m = 0.05F;
  params.min_hold_s = 0.2;
  SafetyMonitor monitor(params, 30.0);  // a frame period in T_r and the scale's look-ahead
  FrameResult m = ur5_measurement();
  int64_t t_ns = 0;
  for (auto _ : state) {
    m.host_time_ns = t_ns += 33'333'333;
    monitor.decide(m, 0);
    benchmark::DoNotOptimize(m.verdict.speed_scale);
  }
}
BENCHMARK(BM_MonitorPerLinkUr5)->Name("Monitor/per_link/ur5")->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace hrcsense

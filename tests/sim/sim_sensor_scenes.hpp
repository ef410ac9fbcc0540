// SPDX-License-Identifier: Apache-2.0
// Scenes and pixel predicates shared by the simulated sensor's tests (sim_sensor_test.cpp,
// sim_dropouts_test.cpp).
#pragma once

#include "hrcsense/camera.hpp"
#include "hrcsense/sim/sim.hpp"

#include <cmath>
#include <cstddef>

namespace hrcsense::sim_test {

/// The wall z = z_m facing the camera at the origin.
inline Shape wall_shape(float z_m) { return Shape::plane({0, 0, z_m}, {0, 0, -1}); }

inline SceneObject object(const Shape& shape, bool is_static, Material material = {}) {
  SceneObject o;
  o.shapes = {shape};
  o.is_static = is_static;
  o.material = material;
  return o;
}

/// fx·B in pixel·metres for the default 848x480 camera.
inline double fxb(const Simulator& sim) { return sim.intrinsics().fx * static_cast<double>(sim.params.baseline_mm) * 1e-3; }

inline size_t at(const Frame& f, int u, int v) { return static_cast<size_t>(v) * f.depth.width + u; }

/// Noise-free disparity of pixel i from the truth (0 where nothing was hit).
inline double true_disparity(const Simulator& sim, const Frame& f, size_t i) {
  const float z = f.truth->depth_m[i];
  return z > 0.0F ? fxb(sim) / z : 0.0;
}

/// Whether pixel (u, v) has a 4-neighbour across a true-disparity step above the edge limit;
/// `far_side` receives whether the pixel is the farther of the pair with the largest step.
inline bool on_edge(const Simulator& sim, const Frame& f, int u, int v, bool* far_side) {
  const double d = true_disparity(sim, f, at(f, u, v));
  double best = sim.params.edge_jump_px;
  bool found = false;
  const int du[] = {-1, 1, 0, 0};
  const int dv[] = {0, 0, -1, 1};
  for (int k = 0; k < 4; ++k) {
    const int nu = u + du[k], nv = v + dv[k];
    if (nu < 0 || nv < 0 || nu >= f.depth.width || nv >= f.depth.height) continue;
    const double dn = true_disparity(sim, f, at(f, nu, nv));
    if (std::abs(dn - d) > best) {
      best = std::abs(dn - d);
      found = true;
      *far_side = dn > d;
    }
  }
  return found;
}

/// Whether pixel (u, v) is labelled `self` and has a 4-neighbour labelled `other`.
inline bool on_rim(const Frame& f, int u, int v, uint16_t self, uint16_t other) {
  if (f.truth->labels[at(f, u, v)] != self) return false;
  return (u > 0 && f.truth->labels[at(f, u - 1, v)] == other) ||
         (u + 1 < f.depth.width && f.truth->labels[at(f, u + 1, v)] == other) ||
         (v > 0 && f.truth->labels[at(f, u, v - 1)] == other) ||
         (v + 1 < f.depth.height && f.truth->labels[at(f, u, v + 1)] == other);
}

/// Pixels (u, v) of frame 0 of `sim` for which `is_artefact(frame, u, v)` holds.
template <typename Predicate>
size_t count_pixels(const Simulator& sim, Predicate is_artefact) {
  Frame f;
  sim.render(0, f);
  size_t n = 0;
  for (int v = 0; v < f.depth.height; ++v) {
    for (int u = 0; u < f.depth.width; ++u) n += is_artefact(f, u, v) ? 1U : 0U;
  }
  return n;
}

inline bool no_depth(const Frame& f, int u, int v) { return f.depth.at(u, v) == 0; }

/// `sim` without its random holes (edge dropouts, speckle): with or without noise, every pixel
/// without depth then has a geometric reason.
inline Simulator geometric_holes_only(Simulator sim) {
  sim.params.edge_dropout = 0.0F;
  sim.params.speckle = 0.0F;
  return sim;
}

/// A 0.2 m box whose front face is 0.6 m from the camera, centred on the optical axis (so no
/// side face is visible), in front of a wall at 1.2 m.
inline Simulator shadow_scene(bool noise) {
  Simulator sim;
  sim.params.noise = noise;
  sim.params.seed = 9;
  sim.scene.objects.push_back(object(wall_shape(1.2F), true));
  sim.scene.objects.push_back(object(Shape::box({-0.1F, -0.1F, 0.6F}, {0.1F, 0.1F, 0.7F}), false));
  return sim;
}

}  // namespace hrcsense::sim_test

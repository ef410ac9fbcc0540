// SPDX-License-Identifier: Apache-2.0
// hrcsense — the simulator's sensor models (`sim.sensor`): the D435 and a PrimeSense-class
// structured-light camera, as values of SimParams (docs/SIMULATOR.md, "Sensor models").

#include "hrcsense/camera.hpp"
#include "hrcsense/sim/sim.hpp"

#include <array>

namespace hrcsense {
namespace {

/// PrimeSense-class cameras (Kinect v1, ASUS Xtion, Carmine): focal length of the IR camera at
/// 640x480 (drivers' nominal values and calibrations lie between about 570 and 590 px; the lower
/// end), projector–camera baseline, and the disparity the chip reports in 1/8 px steps.
constexpr float kStructuredLightFxPx640 = 570.0F;
constexpr float kStructuredLightBaselineMm = 75.0F;
constexpr float kStructuredLightDisparityStepPx = 1.0F / 8.0F;

/// Depth modes the structured-light model accepts: PrimeSense's VGA, QVGA and QQVGA, plus the
/// D435's, so that every scene file runs with either sensor.
constexpr std::array<std::array<int, 2>, 8> kStructuredLightModes{{
    {640, 480}, {320, 240}, {160, 120}, {1280, 720}, {848, 480}, {640, 360}, {480, 270}, {424, 240},
}};

void set_structured_light(SimParams& p) {
  p.sensor = SimSensor::structured_light;
  p.width = 640;
  p.height = 480;
  // σ on the disparity beside the 1/8 px rounding: together about 0.07 px, so depth σ ≈ 2 mm at
  // 1 m and ≈ 15 mm at 3 m, the size of the random error reported for these cameras.
  p.disparity_noise_px = 0.06F;
  p.baseline_mm = kStructuredLightBaselineMm;
  p.depth_scale_m = 0.001F;  // the OpenNI depth stream's 1 mm units
  p.disparity_step_px = kStructuredLightDisparityStepPx;
  // The projector lights the whole view: no band where a second imager sees nothing. Its
  // shadow beside near objects stays (the projector plays the right imager's part).
  p.left_band = false;
  p.occlusion_shadows = true;
  // The working range ends both ways: 0.5 m (nearer, the pattern blurs and the disparity leaves
  // the search window) to 4.5 m (farther, too little of the pattern comes back).
  p.max_disparity_px = 0.0F;
  p.min_range_m = 0.5F;
  p.max_range_m = 4.5F;
  // Far pixels come and go: from 3 m, up to 30 % of them at 4.5 m are missing in any one frame.
  p.range_dropout = 0.3F;
  p.range_dropout_start_m = 3.0F;
  // Edge pixels flicker: each frame one in five has no depth, the others a coin toss between the
  // near and the far side (the correlation window straddles the edge); no values in between.
  p.edge_jump_px = 1.5F;
  p.edge_dropout = 0.2F;
  p.flying_pixels = 0.0F;
  p.edge_flicker = 0.5F;
  // The pattern is near infrared: dark absorbers and mirrors lose it, in blobs the size of the
  // correlation window; a featureless surface is no problem, the projector brings the texture.
  p.dark_dropout = 0.7F;
  p.shiny_dropout = 0.5F;
  p.low_texture_dropout = 0.0F;
  p.material_cell_px = 8;
  p.speckle = 0.001F;  // the chip removes most isolated matches itself
  p.correlated_noise_px = 0.0F;
  p.correlated_cell_px = 32;
}

}  // namespace

const char* sim_sensor_name(SimSensor sensor) {
  return sensor == SimSensor::structured_light ? "structured_light" : "d435";
}

void apply_sim_sensor(SimSensor sensor, SimParams& p) {
  SimParams preset;  // the D435's values
  if (sensor == SimSensor::structured_light) set_structured_light(preset);
  // What belongs to the run and the colour camera, not to the depth sensor, stays.
  preset.fps = p.fps;
  preset.frames = p.frames;
  preset.seed = p.seed;
  preset.noise = p.noise;
  preset.color = p.color;
  preset.color_width = p.color_width;
  preset.color_height = p.color_height;
  preset.color_translation_m = p.color_translation_m;
  p = preset;
}

std::optional<Intrinsics> structured_light_intrinsics(int width, int height) {
  for (const std::array<int, 2>& mode : kStructuredLightModes) {
    if (mode[0] != width || mode[1] != height) continue;
    Intrinsics in;
    in.width = width;
    in.height = height;
    in.fx = kStructuredLightFxPx640 * static_cast<float>(width) / 640.0F;
    in.fy = in.fx;  // square pixels
    // Pixel centres at integer coordinates (as the SDK's), so the centre is (size − 1) / 2.
    in.ppx = 0.5F * static_cast<float>(width - 1);
    in.ppy = 0.5F * static_cast<float>(height - 1);
    in.model = Distortion::none;  // lens distortion is not modelled, as for the D435
    return in;
  }
  return std::nullopt;
}

}  // namespace hrcsense

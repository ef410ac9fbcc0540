// SPDX-License-Identifier: Apache-2.0
// hrcsense — the processing path's parameters (PipelineParams) and the part of them that may
// change while the cell runs (LiveTuning): plain data, apart from the Pipeline itself, so that
// the configuration (config/config.hpp) can hold them without the run loop, its threads and
// mailboxes.
#pragma once

#include "hrcsense/cell_checks.hpp"
#include "hrcsense/filters.hpp"
#include "hrcsense/pose_check.hpp"
#include "hrcsense/proximity.hpp"
#include "hrcsense/robot.hpp"
#include "hrcsense/safety.hpp"
#include "hrcsense/seen_free_grid.hpp"
#include "hrcsense/segmentation.hpp"
#include "hrcsense/self_filter.hpp"
#include "hrcsense/types.hpp"

#include <string>

namespace hrcsense {

/// Everything the processing path needs, already parsed (see config.hpp).
struct PipelineParams {
  FilterChainParams filters;  ///< depth filters run before segmentation; empty order: none
  Pose T_base_camera = Pose::Identity();
  RobotParams robot;  ///< the arm (capsules from each frame's robot state) or fixed points
  BackgroundParams background;
  ForegroundParams foreground;
  /// The arm's own pixels (arms only; robot.model points have no body to render). The learner
  /// masks them whatever self_filter.enabled says.
  SelfFilterParams self_filter;
  SafetyParams safety;
  CellCheckParams checks;  ///< the image watchdogs (camera blocked or moved, robot envelope invalid)
  PoseCheckParams pose_check;  ///< the told camera pose against the arm, every frame (arms only)
  ProximityBackend backend = ProximityBackend::brute;  ///< `proximity.backend`
  ProximityParams proximity;  ///< octree height, brute threads
  /// A camera of a cell with several (`hrcsense run --camera`): the shared grid whose cubes it
  /// marks seen free each frame (Measurement::seen_free); disabled otherwise.
  SeenFreeGridSpec seen_free_grid;
};

/// What may change while the cell runs, between two frames (hrcsense-view's panels): the
/// filters' parameters, the foreground extraction and the search backend. Not the filter
/// order nor the decimation (they set the resolution the background was learnt at), and never
/// the safety distances, the robot or the camera pose: those need a new run.
struct LiveTuning {
  FilterChainParams filters;
  ForegroundParams foreground;
  ProximityBackend backend = ProximityBackend::brute;  ///< as PipelineParams::backend
};

/// The tunable part of `params`.
LiveTuning tuning_of(const PipelineParams& params);

/// Why `proposed` may not replace the tuning of a run started with `configured`, or empty when
/// it may. In `safety.mode: ssm` the configuration the run started with is what the safety case
/// was validated for, so a live change may only keep the foreground at least as sensitive:
/// `foreground.k_sigma` in (0, configured k_sigma], `min_margin_m` in [0, configured
/// min_margin_m], and `min_object_mm` in [0, kSpeckleShareOfDetection · safety.detection_mm]
/// (the rule load_config applies at start). NaN is refused. The reason names the key, the value
/// asked, the bound and why. In `zones` mode always empty. Only the foreground is judged here;
/// Pipeline::retune refuses what cannot change live at all (the filter order, the decimation).
std::string live_tuning_refusal(const PipelineParams& configured, const LiveTuning& proposed);

}  // namespace hrcsense

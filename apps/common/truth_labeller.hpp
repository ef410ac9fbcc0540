// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — `truth.contact_label` for simulated runs: which simulated object lies
// under the measured contact, asked by the JSON Lines sink for each result it writes
// (JsonLinesExtras::contact_label).
#pragma once

#include "hrcsense/sim/sim.hpp"
#include "hrcsense/sink.hpp"
#include "hrcsense/types.hpp"

#include <string>

namespace hrcsense {

/// Source pixels [u_begin, u_end) x [v_begin, v_end) of the `source` image.
struct SourceBlock {
  int u_begin = 0, u_end = 0, v_begin = 0, v_end = 0;
  bool empty() const { return u_end <= u_begin || v_end <= v_begin; }
};

/// The source pixels filtered pixel `filtered_pixel` (v * width + u) of an image with
/// intrinsics `filtered` (after decimation) was made from: from the source pixel the ray of
/// filtered pixel (u, v) meets up to, not including, the one the ray of (u + 1, v + 1) meets
/// (rounded, clamped to the image, at least one pixel). Equal sizes: the pixel itself. For the
/// SDK's decimation by d (fx/d, ppx/d) that is the d x d block from source pixel (d·u, d·v).
/// Empty for a pixel outside `filtered`.
SourceBlock source_block_of(int filtered_pixel, const Intrinsics& filtered, const Intrinsics& source);

/// The label of the surface a result's contact was measured on. Of the source pixels under the
/// contact's pixel (source_block_of, with the source's and the filtered intrinsics from the run
/// header) it takes the one whose noise-free depth lies nearest the contact's measured depth: a
/// decimated pixel on an edge mixes, say, a hand and the arm behind it, and its median depth is
/// the hand's. Labels and depths come from the simulator's own ray cast for that frame
/// (Simulator::hit_at, the same as the rendered truth). The label is computed here, beside the
/// output, because the pipeline hands on the contact but not the frame's label image, and the
/// simulator is deterministic: frame i's labels follow from (scene, i). Holds its own copy of
/// the simulator (its own scratch, so it may run on the output thread while the source renders
/// on another).
class TruthLabeller {
 public:
  TruthLabeller(Simulator simulator, const RunHeader& header);
  /// "static", "robot" or the object's name; null without a measured contact or a truth. The
  /// text is the simulator's, valid as long as the labeller.
  const char* contact_label(const FrameResult& result) const;

 private:
  Simulator sim_;
  Intrinsics source_;    ///< the source frames' intrinsics (header)
  Intrinsics filtered_;  ///< after the filters (header.filters.intrinsics)
};

}  // namespace hrcsense

// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — `truth.contact_label` for simulated runs: which simulated object lies
// under the measured contact, added to each result before it reaches the wrapped sink.
#pragma once

#include "hrcsense/sim.hpp"
#include "hrcsense/sink.hpp"

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

/// Wraps a sink and sets FrameResult::truth_contact_label on every result that has a measured
/// contact and a truth: the label of the surface the contact was measured on. Of the source
/// pixels under the contact's pixel (source_block_of, with the source's and the filtered
/// intrinsics from the run header) it takes the one whose noise-free depth lies nearest the
/// contact's measured depth: a decimated pixel on an edge mixes, say, a hand and the arm
/// behind it, and its median depth is the hand's. Labels and depths come from the simulator's
/// own ray cast for that frame (Simulator::hit_at, the same as the rendered truth). The
/// label is computed here, beside the output, because the pipeline hands on the contact but not
/// the frame's label image, and the simulator is deterministic: frame i's labels follow from
/// (scene, i). Holds its own copy of the simulator (its own scratch, so it may run on the
/// output thread while the source renders on another); `sink` must outlive it.
class TruthLabelSink final : public Sink {
 public:
  TruthLabelSink(Simulator simulator, Sink& sink) : sim_(std::move(simulator)), sink_(sink) {}
  void header(const RunHeader& header) override;
  void frame(const FrameResult& result) override;
  void summary(const RunSummary& summary) override { sink_.summary(summary); }
  bool failed() const override { return sink_.failed(); }
  std::string failure() const override { return sink_.failure(); }

 private:
  Simulator sim_;
  Sink& sink_;
  Intrinsics source_;    ///< the source frames' intrinsics (header)
  Intrinsics filtered_;  ///< after the filters (header.filters.intrinsics)
  FrameResult labelled_; ///< the result with its label; reused, so no allocation once warmed up
};

}  // namespace hrcsense

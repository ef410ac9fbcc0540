// SPDX-License-Identifier: Apache-2.0
// hrcsense assembly — `truth.contact_label` for simulated runs: which simulated object lies
// under the measured contact, added to each result before it reaches the wrapped sink.
#pragma once

#include "hrcsense/sim.hpp"
#include "hrcsense/sink.hpp"

#include <string>

namespace hrcsense {

/// The source pixel (v * width + u) under filtered pixel `filtered_pixel` of an image with
/// intrinsics `filtered` (after decimation): the pixel whose centre the filtered pixel's
/// centre ray meets in the `source` image, rounded and clamped to it. Equal sizes: the pixel
/// itself. For the SDK's decimation by d (fx/d, ppx/d) that is source pixel (d·u, d·v), the
/// first of the block the filtered pixel was made from. -1 for a pixel outside `filtered`.
int source_pixel_of(int filtered_pixel, const Intrinsics& filtered, const Intrinsics& source);

/// Wraps a sink and sets FrameResult::truth_contact_label on every result that has a measured
/// contact and a truth: the label of the source pixel under the contact (source_pixel_of, with
/// the source's and the filtered intrinsics from the run header), found by the simulator's own
/// ray cast for that frame (Simulator::label_at, the same as the rendered label image). The
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

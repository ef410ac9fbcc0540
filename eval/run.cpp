// SPDX-License-Identifier: Apache-2.0
// hrcsense — one evaluation run (eval/run.hpp).
#include "hrcsense/eval/run.hpp"

#include "common/cell.hpp"
#include "common/tee_sink.hpp"
#include "hrcsense/pipeline.hpp"
#include "hrcsense/sink.hpp"

namespace hrcsense::eval {
namespace {

std::array<double, 3> point_of(const Eigen::Vector3f& p) { return {p.x(), p.y(), p.z()}; }

// Keeps what the metrics read of every processed frame after learning.
class SampleSink : public Sink {
 public:
  SampleSink(EvalRun& run, std::atomic<int64_t>* frames_done) : run_(run), frames_done_(frames_done) {}
  void header(const RunHeader&) override {}
  void frame(const FrameResult& result) override {
    if (!result.source_frame) return;  // a watchdog's or the final stop
    ++run_.source_frames;
    if (frames_done_ != nullptr) ++*frames_done_;
    if (!result.valid) return;  // learning the background, or a frame the pipeline refused
    eval::EvalSample s;
    s.measured = result.contact.valid;
    if (s.measured) {
      s.closest_base = point_of(result.contact.closest_base);
      s.distance_m = result.contact.distance_m;
    }
    s.has_truth = result.truth.has_value() && result.truth->valid;
    if (s.has_truth) {
      s.truth_closest_base = point_of(result.truth->closest_base);
      s.truth_distance_m = result.truth->distance_m;
    }
    s.distance_uncertainty_m = result.distance_uncertainty_m;
    s.protective_distance_m = result.verdict.protective_distance_m;
    s.latency_us = result.latency_us;
    s.foreground_points = static_cast<int64_t>(result.foreground_points);
    run_.samples.push_back(s);
  }
  void summary(const RunSummary& summary) override {
    run_.error = summary.error;
    run_.wall_s = summary.wall_s;
    run_.frames_dropped = summary.frames_dropped;
  }

 private:
  EvalRun& run_;
  std::atomic<int64_t>* frames_done_;
};

}  // namespace

EvalRun run_eval(const Config& config, int64_t max_frames, std::atomic<int64_t>* frames_done) {
  EvalRun run;
  app::CellOptions options;
  options.frames = max_frames;
  options.links = false;             // an evaluation sends nothing to a controller
  options.background_files = false;  // and learns its background in the run
  const std::unique_ptr<app::Cell> cell = app::assemble_cell(config, options);
  const SourceInfo info = cell->source->info();
  if (info.frame_count > 0) run.samples.reserve(static_cast<size_t>(info.frame_count));
  SampleSink samples(run, frames_done);
  // A follow_link arm takes the scale each result asks for, as in `hrcsense run`.
  std::vector<Sink*> sinks = cell->link_sinks();
  sinks.push_back(&samples);
  app::TeeSink sink(sinks);
  run_pipeline(cell->frames(), *cell->robot_states, *cell->pipeline, sink, cell->run_options, cell->header);
  return run;
}

}  // namespace hrcsense::eval

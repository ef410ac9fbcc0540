// SPDX-License-Identifier: Apache-2.0
// hrcsense — the figures of `hrcsense eval`: PNG plots drawn by gnuplot (Debian's
// gnuplot-nox, pngcairo terminal). Each figure keeps its data (.dat) and script (.gp) beside the
// PNG, so that it can be redrawn or restyled without running the sweep again.
#pragma once

#include "hrcsense/eval/runner.hpp"

#include <string>
#include <vector>

namespace hrcsense::eval {

/// One line of a plot: y against x, or against named categories (x_labels, one per point).
struct PlotSeries {
  std::string title;
  std::vector<double> x;
  std::vector<double> y;                 ///< NaN points are left out
  std::vector<std::string> x_labels;     ///< empty, or one label per point (x then is its position)
};

struct Plot {
  std::string png_path;
  std::string title;
  std::string x_label;
  std::string y_label;
  bool log_x = false;
  bool log_y = false;
  std::vector<PlotSeries> series;
};

/// Draws `plot` into png_path (900×540), writing png_path's .dat and .gp beside it. Throws
/// std::runtime_error when gnuplot is missing (naming the package) or fails (with its message).
void draw_plot(const Plot& plot);

/// The standard figures of a sweep in `out_dir`: the mean distance error, the mis-recognised
/// frames per 1000 (0.1 m rule) and the processing rate against the first axis's values (by
/// category when they are not all numbers), one line per scene and value of the other axes,
/// the mean over seeds. Returns the PNG paths; none without an axis.
std::vector<std::string> sweep_plots(const ResultTable& table, const std::vector<eval::SweepAxis>& axes,
                                     const std::string& out_dir);

}  // namespace hrcsense::eval

// SPDX-License-Identifier: Apache-2.0
// hrcsense — the ready-made studies of `hrcsense eval --study` (docs/EVALUATION.md): each
// runs its sweep into DIR/<study>/, draws its figures there and returns its section of the
// report, our numbers beside the thesis's; the report, THESIS-REPLICATION.md, from them.
#pragma once

#include "hrcsense/eval/plots.hpp"
#include "hrcsense/eval/runner.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace hrcsense::eval {

/// One section of THESIS-REPLICATION.md.
struct StudySection {
  std::string title;                 ///< "Table 4.1", …
  std::string markdown;              ///< the table and its notes
  std::vector<std::string> figures;  ///< PNGs, relative to the study folder's parent (DIR)
  std::string recommendation;        ///< what we recommend, from this run's numbers
};

/// What the studies share: where they write and how long they run.
struct StudyContext {
  std::string out_dir;               ///< DIR: each study writes DIR/<study>/
  std::string config_dir = "config"; ///< where the scenes are
  int jobs = 1;                      ///< rows at once (rates are quotable only at 1)
  int64_t frames = -1;               ///< source frames per row; -1: the study's own
  std::vector<std::string> sets;     ///< --set KEY=VALUE for every row of every study
  SweepObserver observer;            ///< every study's sweep reports to it; notes the study begun

  /// The scene `file` in config_dir; throws std::runtime_error naming it when it is absent.
  std::string scene(const std::string& file) const;
  /// A sweep of `scene` into DIR/<study>/ with `default_frames` frames per row unless --frames
  /// was given (a simulated scene is made that long); -1: the scene's own length.
  SweepRequest sweep(const std::string& study, const std::string& scene, int64_t default_frames) const;
  /// Draws `plot` into DIR/<study>/<file>; returns "<study>/<file>".
  std::string figure(const std::string& study, const std::string& file, Plot plot) const;
};

/// The frames per row of the filter and search studies: one minute of a 30 frames/s camera,
/// about two and a half of the thesis's 740-result minutes.
inline constexpr int64_t kStudyFrames = 1800;

StudySection study_table_41(const StudyContext& ctx);  ///< persistence 0–8
StudySection study_table_42(const StudyContext& ctx);  ///< spatial α and δ
StudySection study_table_43(const StudyContext& ctx);  ///< search backends on box + person
StudySection study_table_44(const StudyContext& ctx);  ///< search rate against cloud size
StudySection study_moving_cell(const StudyContext& ctx);  ///< the moving UR5 cell with SSM

/// Whether `name` is a study: table-4.1, table-4.2, table-4.3, table-4.4, moving-cell, or thesis (all of them).
bool is_study(const std::string& name);

/// Runs study `name`, or for `thesis` every study in the report's order (noting each); returns
/// their sections. Throws std::invalid_argument when `name` is no study, and what a study throws.
std::vector<StudySection> run_studies(const std::string& name, const StudyContext& ctx);

/// Writes the report of `sections` as out_dir/THESIS-REPLICATION.md, its figures linked relative
/// to out_dir, and returns its path. `command_line` is the command that made it, quoted in it so
/// that a reader can make it again. Throws std::runtime_error when it cannot be written.
std::string write_thesis_report(const std::string& out_dir, const std::string& command_line,
                                const std::vector<StudySection>& sections);

/// The same report at `path` (e.g. docs/THESIS-REPLICATION.md), its figures copied from out_dir
/// into images/thesis/<study>-<file> beside it and linked there.
void write_thesis_report_copy(const std::string& path, const std::string& out_dir, const std::string& command_line,
                              const std::vector<StudySection>& sections);

}  // namespace hrcsense::eval

// SPDX-License-Identifier: Apache-2.0
// hrcsense — the sweep runner (eval/runner.hpp): rows on --jobs threads, one complete CSV
// line per finished row, the deterministic columns independent of the thread count and the
// rate column saying whether it was measured alone (`serial`).
#include "hrcsense/eval/runner.hpp"

#include "hrcsense/eval/run.hpp"
#include "hrcsense/config/config.hpp"
#include "hrcsense/eval/metrics.hpp"
#include "hrcsense/number_text.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <stdexcept>
#include <thread>

namespace hrcsense::eval {
namespace {

using eval::EvalSample;

// One row to run: a sweep point on one scene with one seed (0: the scene's own seed).
struct Row {
  int64_t index = 0;
  const eval::SweepPoint* point = nullptr;
  std::string scene;
  int64_t seed = 0;
  std::vector<std::string> key_fields() const {
    return {std::to_string(index), eval::settings_text(*point), scene, seed > 0 ? std::to_string(seed) : "config"};
  }
};

constexpr size_t kKeyColumns = 4;
const char* const kColumns[] = {"row",
                                "settings",
                                "scene",
                                "seed",
                                "frames",
                                "truth_frames",
                                "measured_frames",
                                "misrecognised_1m",
                                "misrecognised_1m_per_thesis_minute",
                                "misrecognised_0.1m",
                                "misrecognised_0.1m_per_1000",
                                "mse_run_m2",
                                "mse_thesis_m2",
                                "distance_error_mean_m",
                                "distance_error_median_m",
                                "distance_error_p95_m",
                                "distance_error_max_m",
                                "unsafe_share",
                                "z_d_coverage",
                                "foreground_points_mean",
                                "latency_p50_us",
                                "latency_p99_us",
                                "processing_fps",
                                "timing"};

std::string header_line() {
  std::string line;
  for (const char* column : kColumns) line += (line.empty() ? "" : ",") + std::string(column);
  return line;
}

// A number as the table writes it: enough digits to compare runs exactly; empty for NaN.
std::string number(double value) {
  if (!std::isfinite(value)) return "";
  return float_digits_text(value);
}

// The processing path's rate: frames per second of processing time (latency_us summed), the
// median over five equal blocks of the run's frames, so that one slow stretch does not decide.
double processing_fps(const std::vector<EvalSample>& samples) {
  constexpr size_t kBlocks = 5;
  if (samples.size() < kBlocks) return std::nan("");
  std::vector<double> rates;
  const size_t per_block = samples.size() / kBlocks;
  for (size_t b = 0; b < kBlocks; ++b) {
    double total_us = 0.0;
    for (size_t i = b * per_block; i < (b + 1) * per_block; ++i) total_us += samples[i].latency_us;
    rates.push_back(static_cast<double>(per_block) / (total_us * 1e-6));
  }
  std::sort(rates.begin(), rates.end());
  return rates[kBlocks / 2];
}

// The mean size of the foreground cloud over the run's frames (the thesis's "number of points
// of the target object"); NaN without frames.
double mean_foreground_points(const std::vector<EvalSample>& samples) {
  if (samples.empty()) return std::nan("");
  double sum = 0.0;
  for (const EvalSample& s : samples) sum += static_cast<double>(s.foreground_points);
  return sum / static_cast<double>(samples.size());
}

// The CSV line of a finished row. Ground-truth measures when the run has truth, else the
// stability measures against the run's median point (recordings).
std::string row_line(const Row& row, const EvalRun& run, bool serial) {
  const std::vector<EvalSample>& s = run.samples;
  const bool truth = std::any_of(s.begin(), s.end(), [](const EvalSample& e) { return e.has_truth; });
  const eval::InstabilityCount thesis = truth ? eval::instability_vs_truth(s, eval::kThesisMisrecognitionM)
                                              : eval::instability_vs_median(s, eval::kThesisMisrecognitionM);
  const eval::InstabilityCount strict = truth ? eval::instability_vs_truth(s, eval::kStrictMisrecognitionM)
                                              : eval::instability_vs_median(s, eval::kStrictMisrecognitionM);
  const std::vector<std::array<double, 3>> stable =
      truth ? eval::stable_points_vs_truth(s, eval::kThesisMisrecognitionM)
            : eval::stable_points_vs_median(s, eval::kThesisMisrecognitionM);
  const eval::DistanceError error = eval::distance_error(s);
  const eval::Percentiles latency = eval::latency_percentiles(s);
  const int64_t truth_frames = std::count_if(s.begin(), s.end(), [](const EvalSample& e) { return e.has_truth; });
  const int64_t measured = std::count_if(s.begin(), s.end(), [](const EvalSample& e) { return e.measured; });
  std::vector<std::string> fields = row.key_fields();
  for (std::string& field : fields) field = eval::csv_field(field);
  const std::vector<std::string> values = {std::to_string(s.size()),
                                           std::to_string(truth_frames),
                                           std::to_string(measured),
                                           std::to_string(thesis.mis_recognised),
                                           number(thesis.per_thesis_minute()),
                                           std::to_string(strict.mis_recognised),
                                           number(strict.per_1000_frames()),
                                           number(eval::mse_whole_run(stable)),
                                           number(eval::mse_thesis_windows(stable)),
                                           number(error.mean_abs_m),
                                           number(error.median_abs_m),
                                           number(error.p95_abs_m),
                                           number(error.max_abs_m),
                                           number(error.unsafe_share),
                                           number(eval::uncertainty_coverage(s).share()),
                                           number(mean_foreground_points(s)),
                                           number(latency.p50),
                                           number(latency.p99),
                                           number(processing_fps(s)),
                                           serial ? "serial" : "parallel"};
  fields.insert(fields.end(), values.begin(), values.end());
  std::string line;
  for (const std::string& field : fields) line += (line.empty() ? "" : ",") + field;
  return line;
}

// What the progress reports count, updated by the workers.
struct Progress {
  std::atomic<int64_t> frames{0};
  std::atomic<int64_t> rows_done{0};
  int64_t rows_total = 0;
  int64_t frames_per_row = 0;  ///< for the estimate; 0: unknown
};

// DIR/results.md: every row of results.csv in row order, with the columns a reader compares
// (the rest are in the CSV).
void write_results_md(const ResultTable& table, const std::string& md) {
  const std::vector<std::string>& header = table.header;
  const std::vector<std::vector<std::string>>& rows = table.rows;  // in row order
  const std::vector<std::string> shown = {
      "row", "settings", "scene", "seed", "frames", "misrecognised_1m_per_thesis_minute",
      "misrecognised_0.1m_per_1000", "mse_thesis_m2", "mse_run_m2", "distance_error_mean_m", "distance_error_p95_m",
      "unsafe_share", "z_d_coverage", "foreground_points_mean", "processing_fps", "timing"};
  std::vector<size_t> columns;
  for (const std::string& name : shown) {
    columns.push_back(static_cast<size_t>(std::find(header.begin(), header.end(), name) - header.begin()));
  }
  std::ofstream out(md, std::ios::binary);
  out << "# hrcsense eval\n\nThe measures are defined in docs/EVALUATION.md: misrecognised frames per thesis minute "
         "(1 m rule) and per 1000 frames (0.1 m rule); MSE the thesis's way (5 windows of 10 results) and over the "
         "whole run, m²; the mean and p95 distance error, m; the share measured farther than true; the share where "
         "Z_d covers the truth; the processing rate, frames/s (`serial`: measured alone).\n\n";
  for (const std::string& name : shown) out << "| " << name << " ";
  out << "|\n";
  for (size_t i = 0; i < shown.size(); ++i) out << "| --- ";
  out << "|\n";
  for (const std::vector<std::string>& row : rows) {
    for (size_t c = 0; c < columns.size(); ++c) {
      std::string cell = columns[c] < row.size() ? row[columns[c]] : "";
      if (shown[c] == "scene") cell = std::filesystem::path(cell).filename().string();
      for (size_t k = cell.find('|'); k != std::string::npos; k = cell.find('|', k + 2)) cell.replace(k, 1, "\\|");
      out << "| " << cell << " ";
    }
    out << "|\n";
  }
  if (!out.flush()) throw std::runtime_error(md + ": cannot write");
}

// What every row of a sweep shares and its rows do not show: --frames and the --set applied to
// all rows, one line each ("frames N", "set KEY=VALUE"), kept in DIR/sweep-settings.txt beside
// results.csv. Rows made with other ones would be merged into one table as if comparable.
std::vector<std::string> sweep_settings(const SweepRequest& request) {
  std::vector<std::string> lines{"frames " + std::to_string(request.frames)};
  for (const std::string& set : request.sets) lines.push_back("set " + set);
  return lines;
}

// A fresh table: writes the settings. A resumed one: they must be the ones it was started with,
// else std::runtime_error naming what differs.
void check_sweep_settings(const SweepRequest& request, const std::string& csv, bool resuming) {
  const std::string path = (std::filesystem::path(request.out_dir) / "sweep-settings.txt").string();
  const std::vector<std::string> now = sweep_settings(request);
  if (resuming && std::filesystem::exists(path)) {
    std::ifstream in(path, std::ios::binary);
    std::vector<std::string> before;
    for (std::string line; std::getline(in, line);) before.push_back(line);
    if (before == now) return;
    std::string differs;
    const auto note = [&](const std::string& text) { differs += (differs.empty() ? "" : "; ") + text; };
    for (const std::string& line : now) {
      if (std::find(before.begin(), before.end(), line) == before.end()) note("now " + line);
    }
    for (const std::string& line : before) {
      if (std::find(now.begin(), now.end(), line) == now.end()) note("started with " + line);
    }
    if (differs.empty()) differs = "the --set order";
    throw std::runtime_error(csv + ": its rows were made with other settings (" + differs +
                             "); resume with the same --frames and --set, or use another --out");
  }
  // A table from before the settings were kept, or a new one: what is run now is written down.
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  for (const std::string& line : now) out << line << '\n';
  if (!out.flush()) throw std::runtime_error(path + ": cannot write");
}

// The sweep's rows in row order: each point on each scene with each seed (1..seeds, or only the
// scene's own seed when seeds is 0).
std::vector<Row> sweep_rows(const SweepRequest& request) {
  std::vector<Row> rows;
  for (const eval::SweepPoint& point : request.points) {
    for (const std::string& scene : request.scenes) {
      for (int64_t seed = request.seeds > 0 ? 1 : 0; seed <= std::max<int64_t>(0, request.seeds); ++seed) {
        rows.push_back({static_cast<int64_t>(rows.size()), &point, scene, seed});
      }
    }
  }
  return rows;
}

// Every row's configuration (the scene with the sweep's --set, then the point's settings, then
// the seed), loaded before any row runs: a bad key fails now, naming it, not after hours of rows.
std::vector<Config> row_configs(const SweepRequest& request, const std::vector<Row>& rows) {
  std::vector<Config> configs;
  for (const Row& row : rows) {
    std::vector<std::string> sets = request.sets;
    sets.insert(sets.end(), row.point->settings.begin(), row.point->settings.end());
    if (row.seed > 0) sets.push_back("source.seed=" + std::to_string(row.seed));
    configs.push_back(load_config(row.scene, sets));
  }
  return configs;
}

// The indices of the rows results.csv does not hold yet (all of them in a fresh table).
std::vector<size_t> rows_not_done(const std::vector<Row>& rows, const eval::ResumeState& resumed) {
  std::vector<size_t> pending;
  for (size_t i = 0; i < rows.size(); ++i) {
    if (resumed.done.count(eval::row_key(rows[i].key_fields())) == 0) pending.push_back(i);
  }
  return pending;
}

// What the workers share: `mutex` guards the table, the error, the next row and the label of
// the row being run; `progress` is atomic.
struct SweepWork {
  const SweepRequest& request;
  const std::vector<Row>& rows;
  const std::vector<Config>& configs;
  const std::vector<size_t>& pending;
  std::ofstream& out;
  bool serial;  ///< one job: the rate column says the row was measured alone
  Progress progress{};
  std::mutex mutex{};
  size_t next = 0;
  std::string first_error{};
  std::string current{};
};

// One worker: takes the next pending row, runs it and appends its line, until none is left or
// any row has failed (the first failure is kept; later rows are not started).
void run_rows_worker(SweepWork& work) {
  for (;;) {
    size_t i = 0;
    {
      std::lock_guard<std::mutex> lock(work.mutex);
      if (work.next >= work.pending.size() || !work.first_error.empty()) return;
      i = work.pending[work.next++];
      work.current = work.request.label + (work.request.label.empty() ? "" : ": ") + work.rows[i].key_fields()[1] +
                     " " + std::filesystem::path(work.rows[i].scene).filename().string();
    }
    const EvalRun run = run_eval(work.configs[i], work.request.frames, &work.progress.frames);
    std::lock_guard<std::mutex> lock(work.mutex);
    if (!run.error.empty()) {
      work.first_error = work.rows[i].scene + " (" + work.rows[i].key_fields()[1] + "): " + run.error;
      return;
    }
    work.out << row_line(work.rows[i], run, work.serial) << '\n';
    work.out.flush();
    ++work.progress.rows_done;
  }
}

// The observer's report of `work` at `elapsed_s`. work.current is the workers': read it under
// work.mutex while they run.
SweepProgress progress_of(const SweepWork& work, double elapsed_s, bool finished) {
  SweepProgress p;
  p.rows_done = work.progress.rows_done.load();
  p.rows_total = work.progress.rows_total;
  p.frames_done = work.progress.frames.load();
  p.frames_total = work.progress.rows_total * work.progress.frames_per_row;
  p.elapsed_s = elapsed_s;
  p.current = work.current;
  p.finished = finished;
  return p;
}

// Runs the pending rows on `jobs` threads, reporting progress to the observer every 200 ms
// and once at the end; throws std::runtime_error naming the first row that failed.
void run_pending_rows(SweepWork& work, int jobs) {
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed_s = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const std::function<void(const SweepProgress&)>& report = work.request.observer.progress;
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j) threads.emplace_back(run_rows_worker, std::ref(work));
  while (work.progress.rows_done.load() < work.progress.rows_total) {
    {
      std::lock_guard<std::mutex> lock(work.mutex);
      if (!work.first_error.empty()) break;
      if (report) report(progress_of(work, elapsed_s(), false));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  for (std::thread& t : threads) t.join();
  if (report) report(progress_of(work, elapsed_s(), true));
  if (!work.first_error.empty()) throw std::runtime_error("eval: " + work.first_error);
}

}  // namespace

size_t ResultTable::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  if (it == header.end()) throw std::out_of_range("results.csv has no column '" + name + "'");
  return static_cast<size_t>(it - header.begin());
}

const std::string& ResultTable::text(size_t row, const std::string& name) const {
  return rows.at(row).at(column(name));
}

double ResultTable::number(size_t row, const std::string& name) const {
  const std::string& cell = text(row, name);
  return cell.empty() ? std::nan("") : std::stod(cell);
}

ResultTable read_results(const std::string& csv_path) {
  std::ifstream in(csv_path, std::ios::binary);
  if (!in) throw std::runtime_error(csv_path + ": cannot read");
  ResultTable table;
  std::string line;
  std::getline(in, line);
  table.header = eval::split_csv_line(line);
  while (std::getline(in, line)) {
    table.rows.push_back(eval::split_csv_line(line));
    if (table.rows.back().size() != table.header.size()) {
      throw std::runtime_error(csv_path + ": line " + std::to_string(table.rows.size() + 1) + " has " +
                               std::to_string(table.rows.back().size()) + " fields, the header " +
                               std::to_string(table.header.size()));
    }
  }
  std::sort(table.rows.begin(), table.rows.end(),
            [](const auto& a, const auto& b) { return std::stoll(a.at(0)) < std::stoll(b.at(0)); });
  return table;
}

ResultTable run_sweep(const SweepRequest& request) {
  if (request.points.empty() || request.scenes.empty()) {
    throw std::invalid_argument("eval: a sweep needs at least one point and one scene");
  }
  const std::vector<Row> rows = sweep_rows(request);
  const std::vector<Config> configs = row_configs(request, rows);

  std::filesystem::create_directories(request.out_dir);
  const std::string csv = (std::filesystem::path(request.out_dir) / "results.csv").string();
  const eval::ResumeState resumed = eval::resume_results(csv, header_line(), kKeyColumns);
  check_sweep_settings(request, csv, resumed.existed);
  const std::vector<size_t> pending = rows_not_done(rows, resumed);
  const std::function<void(const std::string&)>& note = request.observer.note;
  if (resumed.existed && note) {
    note("resuming " + csv + ": " + std::to_string(rows.size() - pending.size()) + " of " +
         std::to_string(rows.size()) + " rows already there" +
         (resumed.dropped_partial ? " (a row cut off by the interruption was removed)" : ""));
  }

  const int jobs = std::max(1, std::min<int>(request.jobs, static_cast<int>(pending.size())));
  std::ofstream out(csv, std::ios::app | std::ios::binary);
  SweepWork work{request, rows, configs, pending, out, jobs == 1};
  work.progress.rows_total = static_cast<int64_t>(pending.size());
  work.progress.frames_per_row = request.frames > 0 ? request.frames : (configs.empty() ? 0 : configs[0].sim.frames);
  run_pending_rows(work, jobs);
  if (!out) throw std::runtime_error("eval: cannot write " + csv);
  out.close();
  const std::string md = (std::filesystem::path(request.out_dir) / "results.md").string();
  ResultTable table = read_results(csv);  // read once: the rows resumed and the rows run now
  write_results_md(table, md);
  if (note) {
    note(std::to_string(rows.size()) + " rows in " + csv + " and " + md + " (" + std::to_string(pending.size()) +
         " run now)");
  }
  return table;
}

}  // namespace hrcsense::eval

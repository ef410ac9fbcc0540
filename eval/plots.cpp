// SPDX-License-Identifier: Apache-2.0
// hrcsense — eval's figures through gnuplot (eval/plots.hpp).
#include "hrcsense/eval/plots.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace hrcsense::eval {
namespace {

// Text inside a gnuplot double-quoted string: no double quotes, no backslashes.
std::string quoted(std::string text) {
  for (char& c : text) {
    if (c == '"' || c == '\\') c = '\'';
  }
  return "\"" + text + "\"";
}

// Runs `gnuplot SCRIPT` in `dir` (the script names its files relative to it), its messages
// into `log_path`; throws with them when it fails.
void run_gnuplot(const std::filesystem::path& dir, const std::string& script, const std::string& log_path) {
  const pid_t child = ::fork();
  if (child < 0) throw std::runtime_error("eval: cannot start gnuplot (fork failed)");
  if (child == 0) {
    const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (log >= 0) {
      ::dup2(log, STDOUT_FILENO);
      ::dup2(log, STDERR_FILENO);
    }
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    ::execlp("gnuplot", "gnuplot", script.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(child, &status, 0) < 0) {
  }
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  if (code == 127) {
    throw std::runtime_error("eval: gnuplot not found: install Debian's gnuplot-nox (scripts/setup does)");
  }
  if (code != 0) {
    std::ifstream in(log_path);
    std::stringstream text;
    text << in.rdbuf();
    throw std::runtime_error("eval: gnuplot failed on " + (dir / script).string() + ": " + text.str());
  }
  std::filesystem::remove(log_path);
}

bool all_numbers(const std::vector<std::string>& values) {
  for (const std::string& v : values) {
    char* end = nullptr;
    std::strtod(v.c_str(), &end);
    if (v.empty() || end != v.c_str() + v.size()) return false;
  }
  return true;
}

// "k1=v1;k2=v2" into its pairs.
std::map<std::string, std::string> settings_of(const std::string& text) {
  std::map<std::string, std::string> settings;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ';')) {
    const size_t eq = item.find('=');
    if (eq != std::string::npos) settings[item.substr(0, eq)] = item.substr(eq + 1);
  }
  return settings;
}

}  // namespace

void draw_plot(const Plot& plot) {
  const std::filesystem::path png(plot.png_path);
  const std::filesystem::path dir = png.parent_path().empty() ? std::filesystem::path(".") : png.parent_path();
  const std::string stem = png.stem().string();
  std::ofstream dat(dir / (stem + ".dat"));
  std::ofstream gp(dir / (stem + ".gp"));
  gp << "# Drawn by hrcsense eval: gnuplot " << stem << ".gp\n"
     << "set terminal pngcairo size 900,540 enhanced font 'sans,11'\n"
     << "set output " << quoted(png.filename().string()) << "\n"
     << "set title " << quoted(plot.title) << "\n"
     << "set xlabel " << quoted(plot.x_label) << "\n"
     << "set ylabel " << quoted(plot.y_label) << "\n"
     << "set grid\nset key below\nset datafile missing 'NaN'\n";
  if (plot.log_x) gp << "set logscale x\n";
  if (plot.log_y) gp << "set logscale y\n";
  const bool categories = !plot.series.empty() && !plot.series.front().x_labels.empty();
  if (categories) gp << "set xtics rotate by 30 right\nset offsets 0.3, 0.3, 0, 0\n";
  std::string command;
  int index = 0;
  for (const PlotSeries& s : plot.series) {
    const bool labelled = !s.x_labels.empty();
    dat << "# " << s.title << "\n";
    for (size_t i = 0; i < s.x.size(); ++i) {
      dat << s.x[i] << ' ' << (std::isfinite(s.y[i]) ? std::to_string(s.y[i]) : "NaN");
      if (labelled) dat << ' ' << quoted(s.x_labels[i]);
      dat << '\n';
    }
    dat << "\n\n";  // gnuplot's index separator
    command += std::string(command.empty() ? "plot " : ", \\\n     ") + quoted(stem + ".dat") + " index " +
               std::to_string(index++) + " using 1:2" + (labelled ? ":xtic(3)" : "") + " with linespoints lw 2 pt 7 title " +
               quoted(s.title);
  }
  if (command.empty()) throw std::invalid_argument("eval: a plot without data: " + plot.png_path);
  gp << command << "\n";
  dat.close();
  gp.close();
  if (!dat || !gp) throw std::runtime_error("eval: cannot write the plot's files in " + dir.string());
  run_gnuplot(dir, stem + ".gp", (dir / (stem + ".log")).string());
}

std::vector<std::string> sweep_plots(const ResultTable& table, const std::vector<eval::SweepAxis>& axes,
                                     const std::string& out_dir) {
  if (axes.empty() || table.rows.empty()) return {};
  const eval::SweepAxis& axis = axes.front();
  const bool numeric = all_numbers(axis.values);
  // One series per scene and value of the other axes; per x, the mean over its rows (seeds).
  struct Sums {
    std::map<size_t, std::pair<double, int>> by_measure_x[3];
  };
  const char* const measures[3] = {"distance_error_mean_m", "misrecognised_0.1m_per_1000", "processing_fps"};
  std::map<std::string, Sums> series;
  for (size_t r = 0; r < table.rows.size(); ++r) {
    std::map<std::string, std::string> settings = settings_of(table.text(r, "settings"));
    const auto at = std::find(axis.values.begin(), axis.values.end(), settings[axis.key]);
    if (at == axis.values.end()) continue;
    const size_t x = static_cast<size_t>(at - axis.values.begin());
    std::string name = std::filesystem::path(table.text(r, "scene")).stem().string();
    for (const auto& [key, value] : settings) {
      if (key != axis.key) name += " " + key.substr(key.rfind('.') + 1) + "=" + value;
    }
    for (int m = 0; m < 3; ++m) {
      const double v = table.number(r, measures[m]);
      if (!std::isfinite(v)) continue;
      auto& [sum, count] = series[name].by_measure_x[m][x];
      sum += v;
      ++count;
    }
  }
  const char* const files[3] = {"distance_error.png", "instability.png", "processing_fps.png"};
  const char* const titles[3] = {"mean |measured - true| closest distance", "mis-recognised frames (0.1 m rule)",
                                 "processing rate"};
  const char* const units[3] = {"distance error (m)", "frames per 1000", "frames/s"};
  std::vector<std::string> written;
  for (int m = 0; m < 3; ++m) {
    Plot plot;
    plot.png_path = (std::filesystem::path(out_dir) / files[m]).string();
    plot.title = std::string(titles[m]) + " against " + axis.key;
    plot.x_label = axis.key;
    plot.y_label = units[m];
    for (const auto& [name, sums] : series) {
      PlotSeries s;
      s.title = name;
      for (const auto& [x, sum_count] : sums.by_measure_x[m]) {
        s.x.push_back(numeric ? std::stod(axis.values[x]) : static_cast<double>(x));
        s.y.push_back(sum_count.first / sum_count.second);
        if (!numeric) s.x_labels.push_back(axis.values[x]);
      }
      if (!s.x.empty()) plot.series.push_back(std::move(s));
    }
    if (plot.series.empty()) continue;  // no frames with this measure (a recording has no truth)
    draw_plot(plot);
    written.push_back(plot.png_path);
  }
  return written;
}

}  // namespace hrcsense::eval

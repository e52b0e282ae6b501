#include "elo/eval/plot.hpp"

#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <utility>

namespace elo {
namespace {

constexpr int kPanelWidthPx = 640;
constexpr int kPanelHeightPx = 600;

bool gnuplotInstalled() { return std::system("command -v gnuplot > /dev/null 2>&1") == 0; }

// A gnuplot single-quoted string: a quote inside is written twice.
std::string gnuplotString(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    quoted += c == '\'' ? std::string("''") : std::string(1, c);
  }
  return quoted + "'";
}

std::string shellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  }
  return quoted + "'";
}

std::pair<int, int> topViewAxes(TopView view, const std::vector<Eigen::Isometry3d>& ground_truth) {
  if (view == TopView::camera_xz) return {0, 2};
  if (view == TopView::lidar_xy) return {0, 1};
  Eigen::Vector3d low = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d high = -low;
  for (const Eigen::Isometry3d& pose : ground_truth) {
    low = low.cwiseMin(pose.translation());
    high = high.cwiseMax(pose.translation());
  }
  const Eigen::Vector3d spread = high - low;
  int narrowest = 0;
  spread.minCoeff(&narrowest);
  return narrowest == 0 ? std::pair{1, 2} : narrowest == 1 ? std::pair{0, 2} : std::pair{0, 1};
}

void writeTrajectoryBlock(std::ostream& script, const std::string& block, const std::vector<Eigen::Isometry3d>& poses,
                          std::pair<int, int> axes) {
  script << block << " << EOD\n";
  for (const Eigen::Isometry3d& pose : poses) {
    script << pose.translation()[axes.first] << ' ' << pose.translation()[axes.second] << '\n';
  }
  script << "EOD\n";
}

void writeTrajectoryPanel(std::ostream& script, const std::vector<Eigen::Isometry3d>& ground_truth,
                          const std::vector<Eigen::Isometry3d>& estimate, TopView view) {
  const std::pair<int, int> axes = topViewAxes(view, ground_truth);
  const std::array<const char*, 3> axis_names = {"x", "y", "z"};
  writeTrajectoryBlock(script, "$gt", ground_truth, axes);
  writeTrajectoryBlock(script, "$est", estimate, axes);
  script << "set size ratio -1\n"
         << "set key below\n"
         << "set xlabel '" << axis_names[axes.first] << " (m)'\n"
         << "set ylabel '" << axis_names[axes.second] << " (m)'\n"
         << "set title 'trajectory (top view)'\n"
         << "plot $gt using 1:2 with lines lw 2 lc rgb '#d62728' title 'ground truth', "
            "$est using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'estimate'\n"
         << "set size noratio\n";
}

void writeDriftPanels(std::ostream& script, const std::vector<LengthDriftError>& drift_by_length) {
  script << "$drift << EOD\n";
  for (const LengthDriftError& entry : drift_by_length) {
    script << entry.length << ' ' << entry.error.t_rel_percent << ' ' << entry.error.r_rel_deg_per_100m << '\n';
  }
  script << "EOD\n"
         << "set xlabel 'segment length (m)'\n"
         << "set yrange [0:*]\n"
         << "set ylabel 'translation error (%)'\n"
         << "set title 't_rel'\n"
         << "plot $drift using 1:2 with linespoints lw 2 pt 7 lc rgb '#1f77b4' notitle\n"
         << "set ylabel 'rotation error (deg/100 m)'\n"
         << "set title 'r_rel'\n"
         << "plot $drift using 1:3 with linespoints lw 2 pt 7 lc rgb '#1f77b4' notitle\n";
}

std::string gnuplotScript(const std::string& png_path, const std::vector<Eigen::Isometry3d>& ground_truth,
                          const std::vector<Eigen::Isometry3d>& estimate,
                          const std::vector<LengthDriftError>& drift_by_length, TopView view, const std::string& title) {
  const bool has_trajectory = !ground_truth.empty();
  const bool has_drift = !drift_by_length.empty();
  const int panels = (has_trajectory ? 1 : 0) + (has_drift ? 2 : 0);
  const std::string size = std::to_string(panels * kPanelWidthPx) + "," + std::to_string(kPanelHeightPx);
  std::ostringstream script;
  script.precision(10);
  // pngcairo draws better; the libgd `png` terminal is the fallback of a gnuplot built without cairo.
  script << "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
         << "  set terminal pngcairo noenhanced size " << size << "\n"
         << "} else {\n"
         << "  set terminal png noenhanced size " << size << "\n"
         << "}\n"
         << "set output " << gnuplotString(png_path) << "\n"
         << "set grid\n"
         << "set multiplot layout 1," << panels << " title " << gnuplotString(title) << "\n";
  if (has_trajectory) {
    writeTrajectoryPanel(script, ground_truth, estimate, view);
  }
  if (has_drift) {
    writeDriftPanels(script, drift_by_length);
  }
  script << "unset multiplot\n";
  return script.str();
}

// Runs a script through gnuplot from a temporary file, which is removed afterwards.
bool runGnuplot(const std::string& script) {
  std::string script_path = (std::filesystem::temp_directory_path() / "elo_plot_XXXXXX").string();
  const int descriptor = mkstemp(script_path.data());
  if (descriptor < 0) {
    std::cerr << "warning: cannot create a temporary gnuplot script in " << std::filesystem::temp_directory_path()
              << "\n";
    return false;
  }
  close(descriptor);
  std::ofstream(script_path) << script;
  const int status = std::system(("gnuplot " + shellQuoted(script_path)).c_str());
  std::filesystem::remove(script_path);
  return status == 0;
}

}  // namespace

bool plotEvaluation(const std::string& png_path, const std::vector<Eigen::Isometry3d>& ground_truth,
                    const std::vector<Eigen::Isometry3d>& estimate,
                    const std::vector<LengthDriftError>& drift_by_length, TopView view, const std::string& title) {
  if (ground_truth.empty() && drift_by_length.empty()) {
    std::cerr << "warning: nothing to plot into '" << png_path << "' (no trajectory and no segment errors)\n";
    return false;
  }
  if (!gnuplotInstalled()) {
    std::cerr << "warning: gnuplot is not installed (Debian: apt-get install gnuplot-nox); no plot written to '"
              << png_path << "'\n";
    return false;
  }
  if (!runGnuplot(gnuplotScript(png_path, ground_truth, estimate, drift_by_length, view, title))) {
    std::cerr << "warning: gnuplot failed to write '" << png_path << "'\n";
    return false;
  }
  return true;
}

}  // namespace elo

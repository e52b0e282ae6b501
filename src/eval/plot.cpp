#include "elo/eval/plot.hpp"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>
#include <utility>

namespace elo {
namespace {

// The canvas: two error panels side by side, and the top view above them across the whole width.
constexpr int kCanvasWidthPx = 1280;
constexpr int kErrorPanelHeightPx = 480;
constexpr int kTitleHeightPx = 30;
// Pixels around the top view's plot area: tic labels, axis labels and the panel's title.
constexpr int kTopViewMarginWidthPx = 140;
constexpr int kTopViewMarginHeightPx = 110;
constexpr int kMinTopViewHeightPx = 360;
constexpr int kMaxTopViewHeightPx = 900;
constexpr double kMinTopViewAspect = 0.3;  // the narrower range over the wider
constexpr double kTopViewMargin = 0.04;    // of each range, on either side
constexpr int kKeyHeightPx = 40;           // above the trajectories

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
                          const std::vector<Eigen::Isometry3d>& estimate, const TopViewFrame& frame) {
  const std::array<const char*, 3> axis_names = {"x", "y", "z"};
  writeTrajectoryBlock(script, "$gt", ground_truth, frame.axes);
  writeTrajectoryBlock(script, "$est", estimate, frame.axes);
  script << "set size ratio -1\n"
         << "set key inside top right horizontal opaque box\n"
         << "set xrange [" << frame.low.x() << ":" << frame.high.x() << "]\n"
         << "set yrange [" << frame.low.y() << ":" << frame.high.y() << "]\n"
         << "set xlabel '" << axis_names[frame.axes.first] << " (m)'\n"
         << "set ylabel '" << axis_names[frame.axes.second] << " (m)'\n"
         << "set title 'trajectory (top view)'\n"
         // The ground truth drawn wider, under the estimate: it still shows where the two coincide.
         << "plot $gt using 1:2 with lines lw 5 lc rgb '#d62728' title 'ground truth', "
            "$est using 1:2 with lines lw 1.5 lc rgb '#1f77b4' title 'estimate'\n"
         << "set size noratio\n"
         << "set autoscale\n"
         << "unset key\n";  // the error panels plot one curve each
}

// Writes the segment errors as the data block both error panels plot, and the first of them.
void writeTranslationDriftPanel(std::ostream& script, const std::vector<LengthDriftError>& drift_by_length) {
  script << "$drift << EOD\n";
  for (const LengthDriftError& entry : drift_by_length) {
    script << entry.length << ' ' << entry.error.t_rel_percent << ' ' << entry.error.r_rel_deg_per_100m << '\n';
  }
  script << "EOD\n"
         << "set xlabel 'segment length (m)'\n"
         << "set yrange [0:*]\n"
         << "set ylabel 'translation error (%)'\n"
         << "set title 't_rel'\n"
         << "plot $drift using 1:2 with linespoints lw 2 pt 7 lc rgb '#1f77b4' notitle\n";
}

void writeRotationDriftPanel(std::ostream& script) {
  script << "set ylabel 'rotation error (deg/100 m)'\n"
         << "set title 'r_rel'\n"
         << "plot $drift using 1:3 with linespoints lw 2 pt 7 lc rgb '#1f77b4' notitle\n";
}

// Places a panel at (`x`, `y`) pixels from the canvas's top left, `width` by `height` pixels.
void placePanel(std::ostream& script, int x, int y, int width, int height, int canvas_height) {
  script << "set origin " << static_cast<double>(x) / kCanvasWidthPx << ","
         << static_cast<double>(canvas_height - y - height) / canvas_height << "\n"
         << "set size " << static_cast<double>(width) / kCanvasWidthPx << ","
         << static_cast<double>(height) / canvas_height << "\n";
}

std::string gnuplotScript(const std::string& png_path, const std::vector<Eigen::Isometry3d>& ground_truth,
                          const std::vector<Eigen::Isometry3d>& estimate,
                          const std::vector<LengthDriftError>& drift_by_length, TopView view, const std::string& title) {
  const bool has_trajectory = !ground_truth.empty();
  const bool has_drift = !drift_by_length.empty();
  const TopViewFrame frame = has_trajectory ? topViewFrame(ground_truth, estimate, view) : TopViewFrame{};
  const int top_view_height = has_trajectory ? frame.height_px : 0;
  const int canvas_height = kTitleHeightPx + top_view_height + (has_drift ? kErrorPanelHeightPx : 0);
  const std::string size = std::to_string(kCanvasWidthPx) + "," + std::to_string(canvas_height);
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
         << "set multiplot title " << gnuplotString(title) << "\n";
  if (has_trajectory) {
    placePanel(script, 0, kTitleHeightPx, kCanvasWidthPx, top_view_height, canvas_height);
    writeTrajectoryPanel(script, ground_truth, estimate, frame);
  }
  if (has_drift) {
    const int top = kTitleHeightPx + top_view_height;
    placePanel(script, 0, top, kCanvasWidthPx / 2, kErrorPanelHeightPx, canvas_height);
    writeTranslationDriftPanel(script, drift_by_length);
    placePanel(script, kCanvasWidthPx / 2, top, kCanvasWidthPx / 2, kErrorPanelHeightPx, canvas_height);
    writeRotationDriftPanel(script);
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

TopViewFrame topViewFrame(const std::vector<Eigen::Isometry3d>& ground_truth,
                          const std::vector<Eigen::Isometry3d>& estimate, TopView view) {
  TopViewFrame frame;
  frame.axes = topViewAxes(view, ground_truth);
  Eigen::Vector2d low = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d high = -low;
  for (const auto* poses : {&ground_truth, &estimate}) {
    for (const Eigen::Isometry3d& pose : *poses) {
      const Eigen::Vector2d point(pose.translation()[frame.axes.first], pose.translation()[frame.axes.second]);
      low = low.cwiseMin(point);
      high = high.cwiseMax(point);
    }
  }
  Eigen::Vector2d span = (high - low).cwiseMax(1.0);  // a sensor standing still gets a metre
  span = span.cwiseMax(kMinTopViewAspect * span.maxCoeff());
  span *= 1.0 + 2.0 * kTopViewMargin;
  // One scale (metres per pixel) for both axes, as large as the width or the tallest panel needs.
  const int plot_width = kCanvasWidthPx - kTopViewMarginWidthPx;
  const int max_plot_height = kMaxTopViewHeightPx - kTopViewMarginHeightPx - kKeyHeightPx;
  const double scale = std::max(span.x() / plot_width, span.y() / max_plot_height);
  const Eigen::Vector2d center = (low + high) / 2.0;
  frame.low = center - span / 2.0;
  frame.high = center + span / 2.0;
  frame.high.y() += kKeyHeightPx * scale;
  const int plot_height = static_cast<int>(std::lround(span.y() / scale)) + kKeyHeightPx;
  frame.height_px = std::max(kMinTopViewHeightPx, plot_height + kTopViewMarginHeightPx);
  return frame;
}

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

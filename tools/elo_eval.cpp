// elo_eval: KITTI drift, RPE and ATE of estimated trajectories against ground truth and, where there is
// no ground truth, the map entropy of a trajectory over its scans or the gap between a forward and a
// reverse run.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "elo/eval/evaluation.hpp"
#include "elo/eval/map_entropy.hpp"
#include "elo/eval/plot.hpp"
#include "elo/eval/trajectory_error.hpp"
#include "elo/eval/uniform_instants.hpp"
#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/sequence.hpp"
#include "command_line.hpp"

namespace fs = std::filesystem;

namespace {

constexpr int kExitBadInput = 2;

const char* const kUsage =
    "usage: elo_eval --gt GT --est EST [--segments L,...] [--segment-step N] [--breakdown] [--start S] [--pose-errors K,...]\n"
    "                [--gt-times TIMES] [--exclude-frames A-B,...] [--plot PNG] [--tum]\n"
    "       elo_eval --est EST --map-entropy SCANS [--gt GT ...]\n"
    "       elo_eval --est EST --reverse REV\n"
    "\n"
    "Evaluates estimated trajectories against ground truth with the KITTI odometry metric (t_rel, r_rel over\n"
    "segments of 100..800 m or --segments; t_rel_xy: t_rel's horizontal part, the error's x-y in the LiDAR frame), the\n"
    "relative pose error between consecutive frames and the absolute trajectory error after a rigid alignment. Without ground truth, --map-entropy scores one trajectory by the sharpness\n"
    "of the map its scans make, and --reverse by how far it and a run over the same scans in reverse fail to\n"
    "close.\n"
    "\n"
    "  --gt GT      a KITTI pose file (12 numbers a line), or a directory of NN.txt pose files\n"
    "  --est EST    the estimate: a file when GT is a file, a directory when GT is one; every NN.txt present\n"
    "               in both directories is evaluated, followed by an 'overall' row pooling all of them\n"
    "  --plot PNG   also draw the trajectories and the error against segment length (needs gnuplot); with\n"
    "               directories, sequence NN goes to PNG with _NN before the extension and the pooled errors\n"
    "               to PNG itself\n"
    "  --tum        the files are TUM trajectories (t x y z qx qy qz qw) instead of KITTI poses\n"
    "  --segments L,...\n"
    "               the segment lengths in metres (default the devkit's 100,200,...,800); short drives are\n"
    "               scored with --segments 10,20,50,100 (docs/real_drives.md)\n"
    "  --segment-step N\n"
    "               frames between segment starts (default the devkit's 10); 1 starts a segment at every\n"
    "               frame, as the short real drives are scored\n"
    "  --breakdown  also print each sequence's segment error split into what is wrong: heading, pitch and\n"
    "               roll (deg/100m, mean absolute), along-track (%, signed: + when the estimate travels too\n"
    "               far, a scale error), cross-track and height (%, mean absolute), in the frame of each\n"
    "               segment's last ground-truth pose (x forward, y left, z up)\n"
    "  --start S    the estimate's pose 0 is the ground truth's pose S (elo_run --start S): the ground\n"
    "               truth is read from pose S on, as many poses as the estimate has\n"
    "  --pose-errors K,...\n"
    "               also print the error of each estimate pose K in the frame of its pose 0, against the\n"
    "               ground truth's likewise (m, deg): what a run started in motion gets wrong at first\n"
    "  --gt-times TIMES\n"
    "               the ground truth's stamps (a times.txt, one a pose): score against the ground truth\n"
    "               interpolated to the instants of the line fitted to them, the instants of a sensor turning\n"
    "               at a steady rate. KITTI-raw's stamps are OXTS's, rounded to 10 ms, up to 0.1 m of travel\n"
    "               off the scans' (docs/real_drives.md). GT must be a KITTI pose file\n"
    "  --exclude-frames A-B,...\n"
    "               leave out of t_rel, r_rel and the breakdown every segment holding one of these frames of\n"
    "               GT (ranges A-B, both ends included, or single frames; RPE and ATE keep every frame): the\n"
    "               stretches where the ground truth strays (tools/oxts_consistency.py --strays). GT must be\n"
    "               one file; with --start the frames are still GT's\n"
    "  --map-entropy SCANS\n"
    "               the scans EST was estimated from (a directory as elo_run reads, one pose per scan): builds\n"
    "               the map of their points at 3..30 m and prints its mean map entropy (nats, lower is\n"
    "               sharper) and the mean spread off the local planes within 0.3 m of every 50th map point.\n"
    "               Holds every other point of every scan in memory (about 40 MB per 60 HDL-64E scans)\n"
    "  --reverse REV\n"
    "               the trajectory of the same scans played last to first (elo_run --reverse): prints the\n"
    "               translation and rotation of EST's last pose times REV's last pose, which is the identity\n"
    "               for a perfect odometry: with a gap g, at least one run ends g/2 or more off\n"
    "  --help       this text\n"
    "\n"
    "Exit status: 0 on success, 2 on bad arguments or unreadable or mismatched inputs.\n";

struct Options {
  std::string ground_truth;
  std::string estimate;
  std::optional<std::string> plot;
  std::optional<std::string> map_entropy_scans;
  std::optional<std::string> reverse;
  bool tum = false;
  std::vector<double> segment_lengths = elo::kittiSegmentLengths();
  size_t segment_step = elo::kKittiStartFrameStep;
  bool breakdown = false;
  std::optional<size_t> start;  // --start: the estimate covers the ground truth from this pose on
  std::vector<size_t> pose_errors;
  std::optional<std::string> ground_truth_times;  // --gt-times
  std::vector<elo::FrameRange> excluded_frames;   // of the ground-truth file
};

using elo::tools::UsageError;

// --exclude-frames must name frames of the ground truth: a range past its end is another drive's.
void requireFramesOf(const std::vector<elo::FrameRange>& ranges, size_t poses, const std::string& path) {
  for (const elo::FrameRange& range : ranges) {
    if (range.last >= poses) {
      throw elo::IoError("--exclude-frames " + std::to_string(range.first) + "-" + std::to_string(range.last) +
                         ": '" + path + "' has " + std::to_string(poses) + " poses");
    }
  }
}

// Frame ranges of the ground-truth file as frames of its part from `start` on (--start).
std::vector<elo::FrameRange> rangesFrom(const std::vector<elo::FrameRange>& ranges, size_t start) {
  std::vector<elo::FrameRange> shifted;
  for (const elo::FrameRange& range : ranges) {
    if (range.last >= start) shifted.push_back({std::max(range.first, start) - start, range.last - start});
  }
  return shifted;
}

Options parseArguments(int argc, char** argv) {
  Options options;
  elo::tools::Arguments arguments(argc, argv);
  while (arguments.next()) {
    if (arguments.is("--gt")) {
      options.ground_truth = arguments.value();
    } else if (arguments.is("--est")) {
      options.estimate = arguments.value();
    } else if (arguments.is("--plot")) {
      options.plot = arguments.value();
    } else if (arguments.is("--tum")) {
      options.tum = true;
    } else if (arguments.is("--map-entropy")) {
      options.map_entropy_scans = arguments.value();
    } else if (arguments.is("--reverse")) {
      options.reverse = arguments.value();
    } else if (arguments.is("--segments")) {
      options.segment_lengths = elo::tools::parseNumberList<double>("--segments", arguments.value());
      const auto not_positive = [](double length) { return !(length > 0.0); };
      if (std::any_of(options.segment_lengths.begin(), options.segment_lengths.end(), not_positive)) {
        throw UsageError("--segments expects lengths above 0 m");
      }
    } else if (arguments.is("--segment-step")) {
      options.segment_step = arguments.number<size_t>();
      if (options.segment_step == 0) throw UsageError("--segment-step must be at least 1");
    } else if (arguments.is("--breakdown")) {
      options.breakdown = true;
    } else if (arguments.is("--start")) {
      options.start = arguments.number<size_t>();
    } else if (arguments.is("--pose-errors")) {
      options.pose_errors = elo::tools::parseNumberList<size_t>("--pose-errors", arguments.value());
    } else if (arguments.is("--gt-times")) {
      options.ground_truth_times = arguments.value();
    } else if (arguments.is("--exclude-frames")) {
      try {
        options.excluded_frames = elo::parseFrameRanges(arguments.value());
      } catch (const std::invalid_argument& error) {
        throw UsageError(std::string("--exclude-frames ") + error.what());
      }
    } else {
      arguments.rejectFlag();
    }
  }
  if (options.estimate.empty()) throw UsageError("--est is required");
  if (options.ground_truth.empty() && !options.map_entropy_scans && !options.reverse) {
    throw UsageError("--gt is required unless --map-entropy or --reverse is given");
  }
  if (options.ground_truth.empty() && (options.breakdown || options.start || !options.pose_errors.empty())) {
    throw UsageError("--breakdown, --start and --pose-errors compare with the ground truth: --gt is required");
  }
  if (options.ground_truth_times && (options.tum || fs::is_directory(options.ground_truth))) {
    throw UsageError("--gt-times gives the stamps of one KITTI pose file: --gt must be one, without --tum");
  }
  if (!options.excluded_frames.empty() && (options.ground_truth.empty() || fs::is_directory(options.ground_truth))) {
    throw UsageError("--exclude-frames gives frames of one ground-truth file: --gt must be one");
  }
  if ((options.map_entropy_scans || options.reverse) && fs::is_directory(options.estimate)) {
    throw UsageError("--map-entropy and --reverse score one trajectory: --est must be a file");
  }
  return options;
}

std::vector<Eigen::Isometry3d> readTrajectory(const std::string& path, bool tum) {
  if (!fs::is_regular_file(path)) {
    throw elo::IoError("'" + path + "' is not a readable file");
  }
  std::vector<Eigen::Isometry3d> poses = tum ? elo::readTumPoses(path) : elo::readKittiPoses(path);
  if (poses.empty()) {
    throw elo::IoError("'" + path + "' holds no poses");
  }
  return poses;
}

// One sequence to evaluate: its name and its two files.
struct SequenceFiles {
  std::string name;
  std::string ground_truth;
  std::string estimate;
};

std::vector<SequenceFiles> pairSequenceFiles(const Options& options) {
  const bool gt_is_directory = fs::is_directory(options.ground_truth);
  if (gt_is_directory != fs::is_directory(options.estimate)) {
    throw UsageError("--gt and --est must both be files or both be directories");
  }
  if (!gt_is_directory) {
    return {{fs::path(options.estimate).stem().string(), options.ground_truth, options.estimate}};
  }
  std::vector<SequenceFiles> pairs;
  for (const fs::directory_entry& entry : fs::directory_iterator(options.ground_truth)) {
    const fs::path estimate = fs::path(options.estimate) / entry.path().filename();
    if (entry.path().extension() == ".txt" && fs::exists(estimate)) {
      pairs.push_back({entry.path().stem().string(), entry.path().string(), estimate.string()});
    }
  }
  if (pairs.empty()) {
    throw elo::IoError("no NN.txt file is present in both '" + options.ground_truth + "' and '" + options.estimate +
                       "'");
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.name < b.name; });
  return pairs;
}

std::string plotPathFor(const std::string& png, const std::string& sequence) {
  const fs::path path(png);
  return (path.parent_path() / (path.stem().string() + "_" + sequence + path.extension().string())).string();
}

// The ground truth of a run started at scan `start` (elo_run --start): its poses from `start` on, as many
// as the estimate has.
std::vector<Eigen::Isometry3d> groundTruthFrom(const std::vector<Eigen::Isometry3d>& ground_truth, size_t start,
                                               size_t poses, const std::string& path) {
  if (start + poses > ground_truth.size()) {
    throw elo::IoError("'" + path + "' has " + std::to_string(ground_truth.size()) + " poses, too few for " +
                       std::to_string(poses) + " estimated poses from pose " + std::to_string(start) + " on");
  }
  return {ground_truth.begin() + static_cast<std::ptrdiff_t>(start),
          ground_truth.begin() + static_cast<std::ptrdiff_t>(start + poses)};
}

// The ground truth in `path`, sampled at the stamps in `times_path`, at the uniform instants fitted to
// them (--gt-times).
std::vector<Eigen::Isometry3d> atUniformInstants(const std::vector<Eigen::Isometry3d>& ground_truth,
                                                 const std::string& path, const std::string& times_path) {
  try {
    const std::vector<double> stamps = elo::readTimes(times_path);
    const elo::UniformInstants fit = elo::fitUniformInstants(stamps);
    std::cerr << "elo_eval: the ground truth interpolated to uniform instants, a scan every " << fit.period_s
              << " s; its stamps were up to " << 1000.0 * fit.largest_offset_s << " ms off them\n";
    return elo::interpolatePoses(ground_truth, stamps, fit.instants);
  } catch (const std::invalid_argument& error) {
    throw elo::IoError("'" + path + "' at the stamps of '" + times_path + "': " + error.what());
  }
}

void printHeader() {
  std::printf("%-10s %8s %11s %9s %16s %12s %11s %9s %12s\n", "sequence", "frames", "length(m)", "t_rel(%)",
              "r_rel(deg/100m)", "RPE_trans(m)", "RPE_rot(deg)", "ATE(m)", "t_rel_xy(%)");
}

void printRow(const elo::TrajectoryEvaluation& evaluation) {
  std::printf("%-10s %8zu %11.1f %9.4f %16.4f %12.5f %11.5f %9.4f %12.4f\n", evaluation.name.c_str(),
              evaluation.frames, evaluation.length_m, evaluation.drift.t_rel_percent,
              evaluation.drift.r_rel_deg_per_100m, evaluation.rpe.translation_rmse_m, evaluation.rpe.rotation_rmse_deg,
              evaluation.ate.translation_rmse_m, evaluation.drift.t_rel_horizontal_percent);
}

void printBreakdownHeader() {
  std::printf("%-10s %18s %16s %15s %9s %9s %10s\n", "sequence", "heading(deg/100m)", "pitch(deg/100m)",
              "roll(deg/100m)", "along(%)", "cross(%)", "height(%)");
}

void printBreakdownRow(const elo::TrajectoryEvaluation& evaluation) {
  const elo::ErrorBreakdown& breakdown = evaluation.breakdown;
  std::printf("%-10s %18.4f %16.4f %15.4f %+9.4f %9.4f %10.4f\n", evaluation.name.c_str(),
              breakdown.heading_deg_per_100m, breakdown.pitch_deg_per_100m, breakdown.roll_deg_per_100m,
              breakdown.along_track_percent, breakdown.cross_track_percent, breakdown.height_percent);
}

// One row of --pose-errors.
struct PoseErrorRow {
  std::string sequence;
  size_t pose = 0;
  elo::PoseError error;
};

void printPoseErrors(const std::vector<PoseErrorRow>& rows) {
  std::printf("%-10s %6s %15s %14s\n", "sequence", "pose", "translation(m)", "rotation(deg)");
  for (const PoseErrorRow& row : rows) {
    std::printf("%-10s %6zu %15.4f %14.4f\n", row.sequence.c_str(), row.pose, row.error.translation_m,
                row.error.rotation_deg);
  }
}

elo::TrajectoryEvaluation evaluateFiles(const SequenceFiles& files, const Options& options, bool plot_per_sequence,
                                        std::vector<PoseErrorRow>& pose_errors) {
  const std::vector<Eigen::Isometry3d> estimate = readTrajectory(files.estimate, options.tum);
  std::vector<Eigen::Isometry3d> ground_truth = readTrajectory(files.ground_truth, options.tum);
  requireFramesOf(options.excluded_frames, ground_truth.size(), files.ground_truth);
  if (options.ground_truth_times) {
    ground_truth = atUniformInstants(ground_truth, files.ground_truth, *options.ground_truth_times);
  }
  if (options.start) ground_truth = groundTruthFrom(ground_truth, *options.start, estimate.size(), files.ground_truth);
  elo::TrajectoryEvaluation evaluation;
  try {
    evaluation = elo::evaluateTrajectory(files.name, ground_truth, estimate, options.segment_lengths,
                                         options.segment_step,
                                         rangesFrom(options.excluded_frames, options.start.value_or(0)));
    for (size_t pose : options.pose_errors) {
      pose_errors.push_back({files.name, pose, elo::poseErrorFromFirst(ground_truth, estimate, pose)});
    }
  } catch (const std::invalid_argument& error) {
    throw elo::IoError("'" + files.ground_truth + "' against '" + files.estimate + "': " + error.what());
  }
  if (options.plot) {
    const std::string png = plot_per_sequence ? plotPathFor(*options.plot, files.name) : *options.plot;
    elo::plotEvaluation(png, ground_truth, estimate, elo::driftByLength(evaluation.segments),
                        elo::TopView::widest_spread, "sequence " + files.name);
  }
  return evaluation;
}

// The map entropy of the trajectory in options.estimate over the scans in options.map_entropy_scans.
void printMapEntropy(const Options& options) {
  const std::vector<Eigen::Isometry3d> poses = readTrajectory(options.estimate, options.tum);
  const elo::Sequence scans(*options.map_entropy_scans);
  if (scans.size() != poses.size()) {
    throw elo::IoError("'" + options.estimate + "' holds " + std::to_string(poses.size()) + " poses for the " +
                       std::to_string(scans.size()) + " scans of '" + *options.map_entropy_scans + "'");
  }
  const elo::MapEntropyOptions settings;
  std::vector<Eigen::Vector3f> map;
  for (size_t i = 0; i < scans.size(); ++i) elo::addScanToMap(scans.load(i).points, poses[i], settings, map);
  elo::MapEntropy entropy;
  try {
    entropy = elo::mapEntropy(map, settings);
  } catch (const std::invalid_argument& error) {
    throw elo::IoError("the map of '" + *options.map_entropy_scans + "': " + error.what());
  }
  std::printf("map entropy %.4f nats, plane deviation %.2f mm (%zu neighbourhoods of %zu map points)\n",
              entropy.mean_entropy, 1000.0 * entropy.mean_plane_deviation_m, entropy.scored_points,
              entropy.map_points);
}

// The gap between the forward run in options.estimate and the reverse run in options.reverse.
void printForwardBackwardGap(const Options& options) {
  elo::ForwardBackwardGap gap;
  try {
    gap = elo::forwardBackwardGap(readTrajectory(options.estimate, options.tum),
                                  readTrajectory(*options.reverse, options.tum));
  } catch (const std::invalid_argument& error) {
    throw elo::IoError("'" + options.estimate + "' against '" + *options.reverse + "': " + error.what());
  }
  std::printf("forward-backward gap %.4f m, %.4f deg over %zu scans and %.1f m", gap.translation_m, gap.rotation_deg,
              gap.frames, gap.length_m);
  if (gap.length_m > 0.0) std::printf(" (%.3f %% of the length)", 100.0 * gap.translation_m / gap.length_m);
  std::printf("\n");
}

int run(const Options& options) {
  if (options.map_entropy_scans) printMapEntropy(options);
  if (options.reverse) printForwardBackwardGap(options);
  if (options.ground_truth.empty()) return 0;
  const std::vector<SequenceFiles> sequences = pairSequenceFiles(options);
  const bool directories = fs::is_directory(options.ground_truth);
  std::vector<elo::TrajectoryEvaluation> evaluations;
  std::vector<PoseErrorRow> pose_errors;
  for (const SequenceFiles& files : sequences) {
    evaluations.push_back(evaluateFiles(files, options, directories, pose_errors));
  }
  if (!options.excluded_frames.empty()) {
    const elo::TrajectoryEvaluation& evaluation = evaluations.front();
    std::cerr << "elo_eval: " << evaluation.segments_left_out << " of "
              << evaluation.segments_left_out + evaluation.segments.size()
              << " segments hold an excluded frame and are left out\n";
  }
  if (directories) {
    evaluations.push_back(elo::poolEvaluations("overall", evaluations));
    if (options.plot) {
      elo::plotEvaluation(*options.plot, {}, {}, elo::driftByLength(evaluations.back().segments),
                          elo::TopView::widest_spread, "all sequences");
    }
  }
  // The tables only once every input has been read, so that an error leaves no partial table.
  printHeader();
  for (const elo::TrajectoryEvaluation& evaluation : evaluations) {
    printRow(evaluation);
  }
  if (options.breakdown) {
    printBreakdownHeader();
    for (const elo::TrajectoryEvaluation& evaluation : evaluations) printBreakdownRow(evaluation);
  }
  if (!pose_errors.empty()) printPoseErrors(pose_errors);
  return 0;
}

// Reports an unreadable or mismatched input: the caller's mistake as much as a wrong flag, so exit 2.
int badInput(const char* message) {
  std::cerr << "elo_eval: " << message << '\n';
  return kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
  return elo::tools::runTool("elo_eval", kUsage, argc, argv, [&] {
    try {
      return run(parseArguments(argc, argv));
    } catch (const elo::IoError& error) {
      return badInput(error.what());
    } catch (const fs::filesystem_error& error) {
      return badInput(error.what());
    }
  });
}

// elo_run: runs the odometry over a sequence on disk (KITTI layout or a directory of PCD/BIN scans) or a
// ROS 1 or ROS 2 bag, and writes the trajectory. Thin: parse flags, read scans, call elo::Odometry, report.
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/elapsed_time.hpp"
#include "elo/io/config_yaml.hpp"
#include "elo/io/io_error.hpp"
#include "elo/io/kitti.hpp"
#include "elo/io/map_pcd.hpp"
#include "elo/io/scan_source.hpp"
#include "elo/map_builder.hpp"
#include "elo/odometry.hpp"
#include "elo/sensor_fit.hpp"
#include "command_line.hpp"
#include "scan_sources.hpp"
#include "localization_run.hpp"

namespace {

constexpr char kUsage[] = R"(usage: elo_run --input DIR|BAG --output POSES [options]

Runs ELO odometry over DIR (KITTI layout: DIR/velodyne/*.bin with optional times.txt and calib.txt;
or a directory of .pcd / .bin scans) or over the sensor_msgs/PointCloud2 clouds of a bag (a ROS 1
DRIVE.bag, or a ROS 2 bag directory: metadata.yaml and *.db3) in header-stamp order, and writes one
KITTI pose line per scan (sensor frame, scan 0 at the origin). With DIR/calib.txt it also writes the
camera-frame trajectory the KITTI devkit scores. A scan that cannot be read (missing, truncated,
malformed file or message) or used is skipped and counted like a scan the odometry cannot use: its pose
line repeats the last pose, and the summary says how many and why. A run that fails part-way still
writes the poses of the scans before the failure.

options:
  --topic NAME         the bag's cloud topic (default: its only PointCloud2 topic)
  --config FILE        YAML overrides of the defaults (see config/*.yaml, --dump-config)
  --mode f2m|f2f       frame-to-model (default) or frame-to-frame
  --threads N          CPU threads (default: all)
  --backend cpu|cuda   compute backend (runtime.backend; default cpu)
  --set KEY=VALUE      override one parameter, e.g. --set ground.sensor_height=1.8 (repeatable)
  --frames N           process only the first N scans (of those --start, --stride and --reverse play)
  --start N            play the scans from scan N on, the first of them at the origin: a bag cut
                       mid-drive, or a node started on a moving car (default 0; not with --reverse);
                       the poses written are those of scans N, N+K, ... (K: --stride)
  --stride K           play every K-th scan from the first: a faster drive, or dropped frames
                       (default 1); score it against every K-th ground-truth pose
  --reverse            play the scans last to first, the route driven backwards (stamps mirrored
                       so time still advances); elo_eval --reverse compares it with a forward run
  --timing CSV         per-frame stage times, iterations, deskew rounds, inlier counts and degeneracy
  --tum FILE           also write the trajectory in TUM format (stamp x y z qx qy qz qw; a bag's
                       stamps are its clouds' header stamps)
  --map FILE.pcd       write the drive's map (docs/map.md): binary PCD, x y z intensity normal_x
                       normal_y normal_z, one point per voxel, in the first scan's sensor frame; also
                       when the run fails part-way
  --map-voxel METERS   the map's voxel edge (map.voxel_size; default 0.2)
  --camera-output FILE camera-frame poses (default: POSES with _camera before the extension)
  --strict             stop at the first scan that cannot be read and exit 1 (after writing the
                       poses of the scans before it), instead of skipping it
  --no-prefetch        upload each scan to the GPU only when it is processed, as the node does, not
                       while the scan before it is (the poses are the same)
  --quiet              no progress bar
  --localize MAP.pcd   localize in a saved map (PCD: x y z [intensity] [normal_x normal_y normal_z], in
                       the map frame; normals estimated at load when absent): POSES are then the
                       sensor's poses in the map frame (docs/localization.md)
  --initial-pose "x y z yaw_deg"
                       with --localize: the sensor's pose in the map at the first scan, searched
                       around (localization.search_*); default the map's origin, as a map made by
                       elo_run --map of a drive that started where this one does
  --dump-config        print the effective configuration as YAML and exit
  --help
)";

struct Options {
  std::string input;
  std::string topic;
  std::string output;
  std::string config_file;
  std::string timing_csv;
  std::string tum_output;
  std::string camera_output;
  std::string map_output;
  std::string localize_map;
  Eigen::Isometry3d initial_pose = Eigen::Isometry3d::Identity();
  std::vector<std::pair<std::string, std::string>> overrides;
  size_t max_frames = 0;
  size_t stride = 1;
  size_t start = 0;
  bool reverse = false;
  bool strict = false;
  bool prefetch = true;
  bool quiet = false;
  bool dump_config = false;
};

using elo::tools::UsageError;

Options parseArguments(int argc, char** argv) {
  Options options;
  elo::tools::Arguments arguments(argc, argv);
  while (arguments.next()) {
    if (arguments.is("--input")) {
      options.input = arguments.value();
    } else if (arguments.is("--topic")) {
      options.topic = arguments.value();
    } else if (arguments.is("--output")) {
      options.output = arguments.value();
    } else if (arguments.is("--config")) {
      options.config_file = arguments.value();
    } else if (arguments.is("--mode")) {
      const std::string mode = arguments.value();
      if (mode != "f2m" && mode != "f2f") throw UsageError("--mode must be f2m or f2f, got '" + mode + "'");
      options.overrides.emplace_back("model.mode", mode == "f2m" ? "frame_to_model" : "frame_to_frame");
    } else if (arguments.is("--backend")) {
      options.overrides.emplace_back("runtime.backend", arguments.value());
    } else if (arguments.is("--threads")) {
      options.overrides.emplace_back("runtime.threads", std::to_string(arguments.number<int>()));
    } else if (arguments.is("--set")) {
      const std::string assignment = arguments.value();
      const size_t equals = assignment.find('=');
      if (equals == std::string::npos) throw UsageError("--set expects KEY=VALUE, got '" + assignment + "'");
      options.overrides.emplace_back(assignment.substr(0, equals), assignment.substr(equals + 1));
    } else if (arguments.is("--frames")) {
      options.max_frames = arguments.number<size_t>();
    } else if (arguments.is("--stride")) {
      options.stride = arguments.number<size_t>();
      if (options.stride == 0) throw UsageError("--stride must be at least 1");
    } else if (arguments.is("--start")) {
      options.start = arguments.number<size_t>();
    } else if (arguments.is("--reverse")) {
      options.reverse = true;
    } else if (arguments.is("--timing")) {
      options.timing_csv = arguments.value();
    } else if (arguments.is("--tum")) {
      options.tum_output = arguments.value();
    } else if (arguments.is("--map")) {
      options.map_output = arguments.value();
    } else if (arguments.is("--map-voxel")) {
      options.overrides.emplace_back("map.voxel_size", arguments.value());
    } else if (arguments.is("--camera-output")) {
      options.camera_output = arguments.value();
    } else if (arguments.is("--strict")) {
      options.strict = true;
    } else if (arguments.is("--no-prefetch")) {
      options.prefetch = false;
    } else if (arguments.is("--quiet")) {
      options.quiet = true;
    } else if (arguments.is("--localize")) {
      options.localize_map = arguments.value();
    } else if (arguments.is("--initial-pose")) {
      options.initial_pose = elo::tools::parseInitialPose(arguments.value());
    } else if (arguments.is("--dump-config")) {
      options.dump_config = true;
    } else {
      arguments.rejectFlag();
    }
  }
  if (!options.dump_config && (options.input.empty() || options.output.empty())) {
    throw UsageError("--input and --output are required");
  }
  // A reverse run from scan N would play N, N-1, ..., 0: the drive's start driven backwards, which no
  // recording holds; the reverse of a cut drive is --reverse over the cut itself.
  if (options.reverse && options.start > 0) throw UsageError("--start and --reverse cannot be combined");
  return options;
}

elo::Config loadConfig(const Options& options) {
  elo::Config config;
  if (!options.config_file.empty()) elo::loadConfigYaml(options.config_file, config);
  std::vector<elo::Parameter> table = elo::parameters(config);
  for (const auto& [key, text] : options.overrides) {
    const auto parameter = std::find_if(table.begin(), table.end(), [&](const auto& p) { return p.key == key; });
    if (parameter == table.end()) throw elo::ConfigError("unknown parameter '" + key + "'");
    elo::setFromString(*parameter, text);
  }
  elo::validate(config);
  return config;
}

std::string cameraOutputPath(const Options& options) {
  if (!options.camera_output.empty()) return options.camera_output;
  const size_t dot = options.output.rfind('.');
  const size_t slash = options.output.rfind('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return options.output + "_camera";
  return options.output.substr(0, dot) + "_camera" + options.output.substr(dot);
}

// Median and mean of one stage's times.
struct StageSummary {
  double mean = 0.0;
  double median = 0.0;
};

StageSummary summarise(std::vector<double> values) {
  StageSummary summary;
  if (values.empty()) return summary;
  summary.mean = std::accumulate(values.begin(), values.end(), 0.0) / values.size();
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  summary.median = values[values.size() / 2];
  return summary;
}

// A scan that was read, or why it could not be read or used: the counted reason and the reader's
// message (a missing, truncated or malformed file or message).
struct ScanRead {
  std::optional<elo::LoadedScan> scan;
  std::string reason;
  std::string detail;
};

ScanRead readScan(const elo::ScanSource& source, size_t index) {
  try {
    return {source.read(index), "", ""};
  } catch (const elo::UnusableScan& error) {
    return {std::nullopt, error.reason(), error.what()};
  }
}

class Report {
 public:
  // `prefetching`: each scan went up to a device while the one before it was processed.
  explicit Report(bool prefetching) : prefetching_(prefetching) {}

  // `upload_ms`: how long the frame waited for scans to reach a device (Backend::lastUploadMilliseconds();
  // 0 on the CPU backend).
  void add(const elo::FrameResult& result, double upload_ms) {
    if (!result.processed) return;
    projection_.push_back(result.times.projection);
    upload_.push_back(upload_ms);
    features_.push_back(result.times.feature_extraction);
    registration_.push_back(result.times.registration);
    model_update_.push_back(result.times.model_update);
    total_.push_back(result.times.total);
  }
  void addUnreadable(const std::string& reason) { ++unreadable_[reason]; }
  // How long reading one scan took (file or message, decoded and converted): outside the pipeline's total.
  void addReading(double milliseconds) { reading_.push_back(milliseconds); }
  double meanTotalMilliseconds() const { return summarise(total_).mean; }

  // Refused registrations by reason, recoveries, restarts, and whether the run ended lost.
  static void printTrackingHealth(const elo::Odometry& odometry) {
    for (const auto& [reason, count] : odometry.refusalCounts()) {
      std::printf(", %zu registration%s refused (%s)", count, count > 1 ? "s" : "", reason.c_str());
    }
    if (odometry.recoveryCount() > 0) std::printf(", %zu recovered", odometry.recoveryCount());
    if (odometry.trackingRestartCount() > 0) {
      std::printf(", %zu model restart%s after refusals in a row", odometry.trackingRestartCount(),
                  odometry.trackingRestartCount() > 1 ? "s" : "");
    }
    if (odometry.lost()) std::printf(", LOST at the end (the last registration was refused)");
  }

  void print(elo::Odometry& odometry, size_t scans, size_t non_finite_points, double wall_seconds) const {
    if (non_finite_points > 0) std::printf("non-finite points skipped while reading: %zu\n", non_finite_points);
    std::printf("\nframes: %zu scans, %zu processed", scans, odometry.processedCount());
    size_t skipped = 0;
    for (const auto* counts : {&unreadable_, &odometry.skippedCounts()}) {
      for (const auto& [reason, count] : *counts) {
        std::printf(", %zu skipped (%s)", count, reason.c_str());
        skipped += count;
      }
    }
    if (skipped > 0) std::printf("; a skipped scan's pose line repeats the last pose");
    if (odometry.degenerateCount() > 0) {
      std::printf(", %zu degenerate (the motion prior kept along what the scan did not constrain)",
                  odometry.degenerateCount());
    }
    if (odometry.startSearchCount() > 0) {
      std::printf(", %zu start%s in motion searched", odometry.startSearchCount(), odometry.startSearchCount() > 1 ? "s" : "");
      if (odometry.ambiguousStartCount() > 0) {
        std::printf(" (%zu ambiguous: another motion fit about as well)", odometry.ambiguousStartCount());
      }
    }
    printTrackingHealth(odometry);
    if (odometry.sensorMisfitCount() > 0) {
      std::printf(", %zu not fitting the sensor model (the warning above)", odometry.sensorMisfitCount());
    }
    std::printf("\n%-22s %10s %10s\n", "stage (ms)", "mean", "median");
    const std::pair<const char*, const std::vector<double>*> rows[] = {
        {"spherical projection", &projection_}, {"feature extraction", &features_},
        {"ICP optimization", &registration_},   {"model update", &model_update_},
        {"total", &total_}};
    for (const auto& [name, values] : rows) {
      const StageSummary s = summarise(*values);
      std::printf("%-22s %10.2f %10.2f\n", name, s.mean, s.median);
    }
    const double mean_total = summarise(total_).mean;
    const StageSummary reading = summarise(reading_);
    std::printf("%-22s %10.2f %10.2f   (not in the total: %.1f %% of it)\n", "reading scans", reading.mean, reading.median,
                mean_total > 0.0 ? 100.0 * reading.mean / mean_total : 0.0);
    const StageSummary upload = summarise(upload_);
    if (upload.mean > 0.0) {
      std::printf("%-22s %10.3f %10.3f   (%s)\n", "scan upload to GPU", upload.mean, upload.median,
                  prefetching_ ? "what the frames still waited for; the rest ran beside the frame before"
                               : "part of the projection");
      std::printf("FPS without the upload: %.1f\n", 1000.0 / (mean_total - upload.mean));
    }
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const int threads = odometry.config().runtime.threads;
    std::printf("FPS: %.1f (pipeline), %.1f (wall, with reading scans); backend: %s; threads: %s; peak memory: %.0f MiB\n",
                mean_total > 0.0 ? 1000.0 / mean_total : 0.0, wall_seconds > 0.0 ? total_.size() / wall_seconds : 0.0,
                odometry.backend().name(), threads > 0 ? std::to_string(threads).c_str() : "all",
                usage.ru_maxrss / 1024.0);
  }

 private:
  bool prefetching_;
  std::vector<double> projection_, upload_, features_, registration_, model_update_, total_, reading_;
  std::map<std::string, size_t> unreadable_;
};

// The scans the run plays (playOrder), each at its recorded stamp: the odometry starts at the first scan
// it is given, whatever its stamp.
std::vector<elo::PlayedScan> playedScans(const elo::ScanSource& source, const Options& options) {
  if (options.start > 0 && options.start >= source.size()) {
    throw UsageError("--start " + std::to_string(options.start) + ": the input has " + std::to_string(source.size()) +
                     " scans");
  }
  return elo::playOrder(source, options.stride, options.reverse, options.max_frames, options.start);
}

void writeTimingRow(std::ofstream& csv, size_t index, double stamp, const elo::FrameResult& r) {
  csv << index << ',' << stamp << ',' << (r.processed ? 1 : 0) << ',' << r.times.projection << ','
      << r.times.feature_extraction << ',' << r.times.registration << ',' << r.times.model_update << ','
      << r.times.total << ',' << r.registration.iterations << ',' << r.deskew_rounds << ','
      << r.registration.last.nonground.inliers << ',' << r.registration.last.ground.inliers << ','
      << r.registration.weight << ',' << r.registration.degeneracy.eigenvalues[0] << ','
      << r.registration.degeneracy.describe() << '\n';
}

void showProgress(size_t done, size_t total) {
  constexpr int kWidth = 40;
  const int filled = static_cast<int>(kWidth * done / std::max<size_t>(total, 1));
  std::fprintf(stderr, "\r[%s%s] %zu/%zu", std::string(filled, '#').c_str(), std::string(kWidth - filled, ' ').c_str(),
               done, total);
  if (done == total) std::fprintf(stderr, "\n");
}

// One pose per played scan, at the scan's stamp: what the run writes.
struct Trajectory {
  std::vector<Eigen::Isometry3d> poses;
  std::vector<double> stamps;
};

void writeTrajectory(const Options& options, const elo::ScanSource& source, const Trajectory& trajectory) {
  elo::writeKittiPoses(options.output, trajectory.poses);
  if (source.hasCalibration()) {
    elo::writeKittiPoses(cameraOutputPath(options), elo::lidarToCamera(trajectory.poses, source.calibration()));
  }
  if (!options.tum_output.empty()) elo::writeTumPoses(options.tum_output, trajectory.stamps, trajectory.poses);
}

// The drive's map (--map): of the processed scans that registered in every direction, those the map
// takes (map.scan_stride) are handed to the map's thread; the map is written when the run ends, or
// fails part-way.
class MapOutput {
 public:
  MapOutput(const std::string& path, const elo::MapConfig& config)
      : path_(path), builder_(config, kMaxQueued) {}

  void add(elo::Odometry& odometry, const elo::FrameResult& result, const elo::PointCloud& cloud) {
    if (result.reset) builder_.clear();  // the poses before the reset lie in another frame
    if (!result.processed || !result.refusal.empty()) return;  // a refused scan's pose is the prior's
    ++processed_;
    if (result.registration.degeneracy.any()) {
      ++degenerate_;
      return;
    }
    if (!builder_.takesNextScan()) return;
    const double start = elo::threadCpuSeconds();
    elo::MapScan scan = elo::mapScanOf(odometry.backend().scan(), cloud, odometry.modelPose(), cloud.stamp,
                                       odometry.config().map.voxel_size);
    copy_seconds_ += elo::threadCpuSeconds() - start;
    if (!builder_.add(std::move(scan))) std::fprintf(stderr, "\nwarning: the map's thread fell behind: a scan left out of the map\n");
  }

  // Writes the map; returns what was written, for the summary.
  std::string write() {
    const elo::MapCloud map = builder_.points();
    elo::writeMapPcd(path_, map);
    const elo::MapBuilder::Statistics statistics = builder_.statistics();
    char text[400];
    std::snprintf(text, sizeof(text),
                  "map: %zu points of %zu voxels from %zu scans (%zu degenerate scans left out, %zu dropped) in %.0f MiB, "
                  "written to %s",
                  map.size(), statistics.voxels, statistics.scans, degenerate_, statistics.dropped,
                  statistics.memory_bytes / 1048576.0, path_.c_str());
    return text;
  }

  // CPU milliseconds a processed scan, taken by the map or not: copying points on the odometry's thread,
  // and adding them on the map's.
  std::pair<double, double> costPerScan() {
    const elo::MapBuilder::Statistics statistics = builder_.statistics();
    const double scans = std::max<double>(processed_, 1.0);
    return {1000.0 * copy_seconds_ / scans, 1000.0 * statistics.busy_seconds / scans};
  }

 private:
  // Scans waiting for the map's thread; it adds a scan in a tenth of the time the odometry takes.
  static constexpr size_t kMaxQueued = 32;
  std::string path_;
  elo::MapBuilder builder_;
  size_t processed_ = 0;
  size_t degenerate_ = 0;
  double copy_seconds_ = 0.0;
};

// Reads and processes every played scan, appending its pose to `trajectory` as it goes, so that the
// caller can write the poses computed before any failure. A scan that cannot be read is skipped (its
// line repeats the last pose) or, with --strict, ends the run with an IoError.
class ScanLoop {
 public:
  // With a `localizer`, each scan is localized after the odometry processed it, and its pose is the map's.
  ScanLoop(const Options& options, const elo::ScanSource& source, elo::Odometry& odometry, MapOutput* map,
           elo::Localizer* localizer)
      : options_(options), source_(source), odometry_(odometry), map_(map), localizer_(localizer),
        report_(options.prefetch) {
    if (options.timing_csv.empty()) return;
    timing_.open(options.timing_csv);
    if (!timing_) throw elo::IoError("cannot write " + options.timing_csv);
    timing_ << "frame,stamp,processed,projection_ms,features_ms,registration_ms,model_update_ms,total_ms,"
               "iterations,deskew_rounds,nonground_inliers,ground_inliers,weight,smallest_eigenvalue,degenerate\n";
  }

  // Reads each scan one ahead and prefetches it before processing the one before it, so that a device
  // backend uploads it meanwhile (elo::Odometry::prefetch()).
  void run(const std::vector<elo::PlayedScan>& played, Trajectory& trajectory) {
    const bool progress = !options_.quiet && isatty(STDERR_FILENO);
    ScanRead next = played.empty() ? ScanRead{} : readPlayed(played[0]);
    for (size_t i = 0; i < played.size(); ++i) {
      const ScanRead current = std::move(next);
      if (i + 1 < played.size()) next = readPlayed(played[i + 1]);
      const elo::FrameResult result = processScan(played[i].index, current);
      // A skipped scan repeats the last pose, keeping lines aligned.
      if (localizer_) {
        waiting_poses_.add(localize(played[i].index, result), trajectory.poses);
      } else {
        trajectory.poses.push_back(result.pose);
      }
      trajectory.stamps.push_back(played[i].stamp);
      if (timing_.is_open()) writeTimingRow(timing_, i, played[i].stamp, result);
      if (progress) showProgress(i + 1, played.size());
    }
  }

  const Report& report() const { return report_; }
  const elo::tools::LocalizationReport& localizationReport() const { return localization_report_; }
  const elo::tools::PosesBeforeTheFirstMatch& posesBeforeTheFirstMatch() const { return waiting_poses_; }
  size_t nonFinitePoints() const { return non_finite_points_; }

 private:
  elo::LocalizationResult localize(size_t scan, const elo::FrameResult& result) {
    const elo::LocalizationState before = localizer_->state();
    const elo::LocalizationResult localized = localizer_->update(result);
    localization_report_.add(localized, result.times.total);
    if (localized.state != before || (localized.searched && !localized.matched)) {
      std::fprintf(stderr, "\nscan %zu: localization %s%s%s\n", scan, elo::stateName(localized.state),
                   localized.refusal.empty() ? "" : ": ", localized.refusal.c_str());
    }
    return localized;
  }

  // Reads the scan, stamped as played, and prefetches it unless --no-prefetch.
  ScanRead readPlayed(const elo::PlayedScan& played) {
    const auto start = std::chrono::steady_clock::now();
    ScanRead read = readScan(source_, played.index);
    report_.addReading(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    if (read.scan) {
      non_finite_points_ += read.scan->non_finite_points;
      read.scan->cloud.stamp = played.stamp;
      if (options_.prefetch) odometry_.prefetch(read.scan->cloud);
    }
    return read;
  }

  elo::FrameResult processScan(size_t scan, const ScanRead& read) {
    if (!read.scan) return skipUnreadable(scan, read);
    warnOnce(scan, read.scan->warning);
    const elo::FrameResult result = odometry_.process(read.scan->cloud);
    if (!result.sensor_warning.empty() && odometry_.sensorMisfitCount() == 1) {  // the first; the summary counts them
      std::fprintf(stderr, "\nscan %zu: warning: %s\n", scan, result.sensor_warning.c_str());
    }
    if (!result.sensor_height_warning.empty()) {
      std::fprintf(stderr, "\nscan %zu: warning: %s\n", scan, result.sensor_height_warning.c_str());
    }
    if (!result.refusal.empty()) {
      std::fprintf(stderr, "\nscan %zu: registration refused (%s)%s\n", scan, result.refusal.c_str(),
                   result.tracking_restart ? "; model restarted from this scan" : "");
    }
    if (result.recovered) std::fprintf(stderr, "\nscan %zu: tracking recovered\n", scan);
    if (!result.processed) std::fprintf(stderr, "\nscan %zu skipped: %s\n", scan, result.skip_reason.c_str());
    if (result.reset) std::fprintf(stderr, "\nscan %zu: time went backwards, odometry restarted\n", scan);
    if (result.gap_restart) {
      std::fprintf(stderr, "\nscan %zu: gap longer than model.time_window, model restarted at the last pose\n", scan);
    }
    report_.add(result, odometry_.backend().lastUploadMilliseconds());
    if (map_ != nullptr) map_->add(odometry_, result, read.scan->cloud);
    return result;
  }

  elo::FrameResult skipUnreadable(size_t scan, const ScanRead& read) {
    if (options_.strict) {
      throw elo::IoError("scan " + std::to_string(scan) + ": " + read.detail + " (--strict stops at a scan that cannot be read)");
    }
    std::fprintf(stderr, "\nscan %zu skipped: %s: %s\n", scan, read.reason.c_str(), read.detail.c_str());
    report_.addUnreadable(read.reason);
    elo::FrameResult skipped;
    skipped.skip_reason = read.reason;
    skipped.pose = odometry_.pose();
    return skipped;
  }

  const Options& options_;
  // Each warning a reader gave, said once: a driver's fields are the same in every cloud.
  void warnOnce(size_t scan, const std::string& warning) {
    if (!warning.empty() && warned_.insert(warning).second) std::fprintf(stderr, "\nscan %zu: warning: %s\n", scan, warning.c_str());
  }

  const elo::ScanSource& source_;
  elo::Odometry& odometry_;
  MapOutput* map_;
  elo::Localizer* localizer_;
  std::ofstream timing_;
  Report report_;
  elo::tools::LocalizationReport localization_report_;
  elo::tools::PosesBeforeTheFirstMatch waiting_poses_;
  size_t non_finite_points_ = 0;
  std::set<std::string> warned_;
};

// A failed run still writes the map of the scans before the failure; a map that cannot be written then
// is reported, and the run's own failure is the one that ends it.
void writeMapAfterFailure(MapOutput& map) {
  try {
    std::fprintf(stderr, "elo_run: %s\n", map.write().c_str());
  } catch (const std::exception& error) {
    std::fprintf(stderr, "elo_run: cannot write the map: %s\n", error.what());
  }
}

int run(const Options& options) {
  const elo::Config config = loadConfig(options);
  if (options.dump_config) {
    std::cout << elo::dumpConfigYaml(config);
    return 0;
  }
  const auto opening = std::chrono::steady_clock::now();
  const std::unique_ptr<elo::ScanSource> source = elo_ros::openScanSource(options.input, options.topic);
  std::printf("input: %s, %zu scans, listed in %.2f s\n", source->describe().c_str(), source->size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - opening).count());
  if (!source->warning().empty()) std::fprintf(stderr, "warning: %s\n", source->warning().c_str());
  const std::vector<elo::PlayedScan> played = playedScans(*source, options);
  elo::Odometry odometry(config);
  if (!odometry.backendWarning().empty()) std::fprintf(stderr, "warning: %s\n", odometry.backendWarning().c_str());
  const std::string normal_reach = elo::normalReachWarning(config);
  if (!normal_reach.empty()) std::fprintf(stderr, "warning: %s\n", normal_reach.c_str());
  std::optional<MapOutput> map;
  if (!options.map_output.empty()) map.emplace(options.map_output, config.map);
  std::unique_ptr<elo::Localizer> localizer;
  if (!options.localize_map.empty()) {
    localizer = std::make_unique<elo::Localizer>(odometry, elo::tools::loadMap(options.localize_map, config));
    localizer->setInitialPose(options.initial_pose);
  }
  ScanLoop loop(options, *source, odometry, map ? &*map : nullptr, localizer.get());
  Trajectory trajectory;
  const auto start = std::chrono::steady_clock::now();
  try {
    loop.run(played, trajectory);
  } catch (const std::exception&) {
    writeTrajectory(options, *source, trajectory);
    if (localizer) loop.posesBeforeTheFirstMatch().print();
    std::fprintf(stderr, "\nelo_run: stopped after %zu of %zu scans; their poses are in %s\n", trajectory.poses.size(),
                 played.size(), options.output.c_str());
    if (map) writeMapAfterFailure(*map);
    throw;
  }
  const double wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  writeTrajectory(options, *source, trajectory);
  loop.report().print(odometry, played.size(), loop.nonFinitePoints(), wall_seconds);
  if (map) {
    std::printf("%s\n", map->write().c_str());
    const auto [copy_ms, add_ms] = map->costPerScan();
    const double pipeline_ms = loop.report().meanTotalMilliseconds();
    std::printf("map cost a processed scan (CPU time): %.2f ms copying points (odometry's thread), %.2f ms adding "
                "them (map's thread); the pipeline took %.1f ms (wall)\n", copy_ms, add_ms, pipeline_ms);
  }
  if (localizer) {
    loop.localizationReport().print(*localizer);
    loop.posesBeforeTheFirstMatch().print();
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  return elo::tools::runTool("elo_run", kUsage, argc, argv, [&] { return run(parseArguments(argc, argv)); });
}

// soak_monitor: watches the odometry nodelet through a soak (tools/soak.sh). It samples the resident
// memory of the nodelet's manager, reads the nodelet's diagnostics, and times every scan from the
// cloud's arrival to its odometry. Once every published scan is accounted for by the nodelet's counters
// it prints the report and exits: 0 when memory stayed flat after warm-up and no scan went unexplained.
#include <diagnostic_msgs/DiagnosticArray.h>
#include <nav_msgs/Odometry.h>
#include <ros/master.h>
#include <ros/network.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <xmlrpcpp/XmlRpcClient.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "command_line.hpp"

namespace {

constexpr char kUsage[] = R"(usage: soak_monitor --scans N [options]

Watches the odometry nodelet while a player publishes N scans: samples the resident memory (VmRSS) of
its manager process every second, reads its diagnostics, and times each scan from the cloud's arrival
to its odometry. When the nodelet's counters account for all N scans (processed, skipped, rejected or
dropped), it prints per block of scans the processing time (the nodelet's, from its diagnostics), the
latency (mean and 99th percentile) and the memory, then the totals and the throughput (first cloud's
arrival to last odometry). It exits 0 when, after warm-up,
the memory grew by at most the tolerance and the nodelet kept up (at most --backlog scans waiting), and
no scan is unexplained; 1 otherwise. A nodelet that falls behind queues every scan it has not yet
processed, so its memory then says nothing about leaks: lower the rate.

options:
  --scans N             scans the player publishes (required)
  --manager NAME        the nodelet manager whose memory is sampled (default /elo/elo_manager)
  --points TOPIC        the clouds (default /points)
  --odom TOPIC          the odometry (default /elo/odom)
  --block K             scans per row of the table (default 1000)
  --warmup K            processed scans after which the memory baseline is taken (default 1000)
  --rss-tolerance MIB   growth allowed after warm-up (default 16)
  --backlog N           scans allowed to wait for the nodelet after warm-up (default 10)
  --idle-timeout S      fail when no scan was accounted for this long (default 60)
  --help
)";

using elo::tools::UsageError;

struct Options {
  size_t scans = 0;
  std::string manager = "/elo/elo_manager";
  std::string points = "/points";
  std::string odom = "/elo/odom";
  size_t block = 1000;
  size_t warmup = 1000;
  double rss_tolerance_mib = 16.0;
  size_t backlog = 10;
  double idle_timeout = 60.0;
};

Options parseArguments(int argc, char** argv) {
  Options options;
  elo::tools::Arguments arguments(argc, argv);
  while (arguments.next()) {
    const std::string& flag = arguments.flag();
    if (flag == "--scans") {
      options.scans = arguments.number<size_t>();
    } else if (flag == "--manager") {
      options.manager = arguments.value();
    } else if (flag == "--points") {
      options.points = arguments.value();
    } else if (flag == "--odom") {
      options.odom = arguments.value();
    } else if (flag == "--block") {
      options.block = arguments.number<size_t>();
    } else if (flag == "--warmup") {
      options.warmup = arguments.number<size_t>();
    } else if (flag == "--rss-tolerance") {
      options.rss_tolerance_mib = arguments.number<double>();
    } else if (flag == "--backlog") {
      options.backlog = arguments.number<size_t>();
    } else if (flag == "--idle-timeout") {
      options.idle_timeout = arguments.number<double>();
    } else {
      arguments.rejectFlag();
    }
  }
  if (options.scans == 0) throw UsageError("--scans is required");
  if (options.block == 0) throw UsageError("--block must be positive");
  return options;
}

constexpr double kNodeTimeout = 60.0;  // s to wait for the manager to register, and for the odometry

// The URI of a ROS node, waiting up to kNodeTimeout for it to register.
std::string nodeUri(const std::string& node_name) {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  request[1] = node_name;
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kNodeTimeout);
  while (!ros::master::execute("lookupNode", request, response, payload, true)) {
    if (!ros::ok() || ros::WallTime::now() > deadline) {
      throw std::runtime_error("no node " + node_name + " registered with the master");
    }
    ros::WallDuration(0.2).sleep();
  }
  return payload;
}

// The process id of a ROS node, asked of the node itself (getPid of the ROS slave API).
int nodePid(const std::string& node_name) {
  XmlRpc::XmlRpcValue response;
  std::string host;
  uint32_t port = 0;
  if (!ros::network::splitURI(nodeUri(node_name), host, port)) {
    throw std::runtime_error("cannot read the URI of " + node_name);
  }
  XmlRpc::XmlRpcClient client(host.c_str(), static_cast<int>(port), "/");
  XmlRpc::XmlRpcValue caller;
  caller[0] = ros::this_node::getName();
  if (!client.execute("getPid", caller, response) || response.getType() != XmlRpc::XmlRpcValue::TypeArray ||
      response.size() < 3) {
    throw std::runtime_error("cannot ask " + node_name + " for its process id");
  }
  return static_cast<int>(response[2]);
}

// VmRSS of `pid` in MiB, or nothing once the process is gone.
std::optional<double> residentMib(int pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (status >> key) {
    if (key == "VmRSS:") {
      double kib = 0.0;
      status >> kib;
      return kib / 1024.0;
    }
    status.ignore(1 << 20, '\n');
  }
  return std::nullopt;
}

double percentile(std::vector<double> values, double fraction) {
  if (values.empty()) return 0.0;
  const size_t rank = static_cast<size_t>(std::ceil(fraction * values.size())) - 1;
  std::nth_element(values.begin(), values.begin() + rank, values.end());
  return values[rank];
}

// The nodelet's totals, as its latest diagnostics state them.
struct NodeCounters {
  size_t received = 0;
  size_t processed = 0;
  size_t dropped = 0;
  size_t failed_registrations = 0;
  std::map<std::string, size_t> skipped, rejected, restarts;  // by reason

  static size_t sum(const std::map<std::string, size_t>& counts) {
    return std::accumulate(counts.begin(), counts.end(), size_t{0}, [](size_t total, const auto& entry) {
      return total + entry.second;
    });
  }
  size_t accounted() const { return processed + sum(skipped) + sum(rejected) + dropped; }
};

// One row of the table: `block` scans, by the order the nodelet processed them.
struct Block {
  double processing_ms_sum = 0.0;  // the diagnostics' window means times their scan counts
  size_t processing_scans = 0;
  double processing_ms_max = 0.0;
  std::vector<double> latencies_ms;
  double rss_mib = 0.0;  // the latest sample while the block was processed
};

class SoakMonitor {
 public:
  // Listens to the clouds only once the odometry reaches it: the player waits for that, so that no
  // odometry message goes unseen.
  SoakMonitor(const Options& options, int pid)
      : options_(options),
        pid_(pid),
        odometry_(node_.subscribe(options.odom, 1000, &SoakMonitor::onOdometry, this)),
        diagnostics_(node_.subscribe("/diagnostics", 100, &SoakMonitor::onDiagnostics, this)) {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kNodeTimeout);
    while (ros::ok() && odometry_.getNumPublishers() == 0 && ros::WallTime::now() < deadline) {
      ros::WallDuration(0.05).sleep();
    }
    points_ = node_.subscribe(options.points, 100, &SoakMonitor::onCloud, this);
  }

  // Spins until every scan is accounted for or nothing happens for the idle timeout; true when done.
  bool watch() {
    ros::WallTime last_progress = ros::WallTime::now();
    ros::WallTime next_sample = last_progress;
    size_t last_accounted = 0;
    while (ros::ok()) {
      ros::spinOnce();
      const ros::WallTime now = ros::WallTime::now();
      if (now >= next_sample) {
        sampleMemory();
        next_sample = now + ros::WallDuration(1.0);
      }
      if (counters_.accounted() != last_accounted) {
        last_accounted = counters_.accounted();
        last_progress = now;
      }
      if (last_accounted >= options_.scans) {
        finish();
        return true;
      }
      if ((now - last_progress).toSec() > options_.idle_timeout) return false;
      ros::WallDuration(0.01).sleep();
    }
    return false;
  }

  // Gives the last odometry messages a moment to arrive, and takes the last memory sample.
  void finish() {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(1.0);
    while (ros::ok() && ros::WallTime::now() < deadline) {
      ros::spinOnce();
      ros::WallDuration(0.01).sleep();
    }
    sampleMemory();
  }

  // Prints the table and the totals; returns the exit status.
  int report(bool complete) const {
    printTable();
    const bool memory_flat = reportMemory();
    const bool kept_up = reportBacklog();
    reportThroughput();
    const size_t unexplained = reportScans();
    const bool passed = complete && memory_flat && kept_up && unexplained == 0;
    if (!complete) {
      std::printf("incomplete: %zu of %zu scans accounted for when nothing more came for %.0f s\n",
                  counters_.accounted(), options_.scans, options_.idle_timeout);
    }
    std::printf("result: %s\n", passed ? "PASS" : "FAIL");
    return passed ? 0 : 1;
  }

 private:
  void onCloud(const sensor_msgs::PointCloud2ConstPtr& cloud) {
    const ros::WallTime now = ros::WallTime::now();
    arrivals_[cloud->header.stamp] = now;
    if (first_arrival_.isZero()) first_arrival_ = now;
  }

  void onOdometry(const nav_msgs::OdometryConstPtr& odometry) {
    const ros::WallTime now = ros::WallTime::now();
    const auto arrival = arrivals_.find(odometry->header.stamp);
    if (arrival != arrivals_.end()) {
      blockAt(odometry_count_).latencies_ms.push_back((now - arrival->second).toSec() * 1000.0);
      // Skipped scans never get odometry: forget every arrival up to this one.
      arrivals_.erase(arrivals_.begin(), std::next(arrival));
    }
    ++odometry_count_;
    last_odometry_ = now;
  }

  void onDiagnostics(const diagnostic_msgs::DiagnosticArrayConstPtr& array) {
    for (const auto& status : array->status) {
      std::map<std::string, std::string> values;
      for (const auto& entry : status.values) values[entry.key] = entry.value;
      if (values.count("scans processed") == 0) continue;  // another node's status
      readWindow(values);
    }
  }

  void readWindow(const std::map<std::string, std::string>& values) {
    NodeCounters counters;
    for (const auto& [key, value] : values) {
      const auto count = [&value] { return static_cast<size_t>(std::stoull(value)); };
      if (key == "clouds received") counters.received = count();
      if (key == "scans processed") counters.processed = count();
      if (key == "scans dropped") counters.dropped = count();
      if (key == "registrations failed") counters.failed_registrations = count();
      using ByReason = std::pair<std::string, std::map<std::string, size_t>*>;
      for (const auto& [prefix, counts] : {ByReason{"scans skipped: ", &counters.skipped},
                                           ByReason{"clouds rejected: ", &counters.rejected},
                                           ByReason{"odometry restarts: ", &counters.restarts}}) {
        if (key.rfind(prefix, 0) == 0) (*counts)[key.substr(prefix.size())] = count();
      }
    }
    const size_t window_scans = counters.processed - counters_.processed;
    if (window_scans > 0) {
      Block& block = blockAt(counters_.processed);
      block.processing_ms_sum += std::stod(values.at("processing time mean (ms)")) * window_scans;
      block.processing_scans += window_scans;
      block.processing_ms_max = std::max(block.processing_ms_max, std::stod(values.at("processing time max (ms)")));
    }
    counters_ = counters;
    // Received and not yet accounted for: waiting in the nodelet's queue.
    if (counters.processed >= options_.warmup) {
      max_backlog_ = std::max(max_backlog_, counters.received - std::min(counters.received, counters.accounted()));
    }
  }

  void sampleMemory() {
    const std::optional<double> rss = residentMib(pid_);
    if (!rss) return;
    blockAt(odometry_count_ > 0 ? odometry_count_ - 1 : 0).rss_mib = *rss;
    if (odometry_count_ < options_.warmup) return;
    if (!baseline_mib_) baseline_mib_ = lowest_mib_ = *rss;
    latest_mib_ = *rss;
    lowest_mib_ = std::min(lowest_mib_, *rss);
    peak_mib_ = std::max(peak_mib_, *rss);
  }

  Block& blockAt(size_t scan) {
    const size_t index = scan / options_.block;
    if (blocks_.size() <= index) blocks_.resize(index + 1);
    return blocks_[index];
  }

  void printTable() const {
    std::printf("%-13s %28s %34s %10s\n", "scans", "processing ms (nodelet)", "latency ms (arrival -> odometry)",
                "RSS MiB");
    std::printf("%-13s %14s %13s %17s %16s\n", "", "mean", "max", "mean", "p99");
    for (size_t i = 0; i < blocks_.size(); ++i) {
      const Block& block = blocks_[i];
      const std::vector<double>& latencies = block.latencies_ms;
      const double latency_mean =
          latencies.empty() ? 0.0 : std::accumulate(latencies.begin(), latencies.end(), 0.0) / latencies.size();
      const std::string range = std::to_string(i * options_.block + 1) + "-" + std::to_string((i + 1) * options_.block);
      std::printf("%-13s %14.1f %13.1f %17.1f %16.1f %10.1f\n", range.c_str(),
                  block.processing_scans > 0 ? block.processing_ms_sum / block.processing_scans : 0.0,
                  block.processing_ms_max, latency_mean, percentile(latencies, 0.99), block.rss_mib);
    }
  }

  bool reportMemory() const {
    if (!baseline_mib_) {
      std::printf("memory: no sample after the %zu warm-up scans\n", options_.warmup);
      return false;
    }
    // Measured from the lowest sample after warm-up: a queue still draining at the first sample would
    // otherwise hide growth.
    const double growth = latest_mib_ - lowest_mib_;
    const bool flat = growth <= options_.rss_tolerance_mib;
    std::printf("memory (manager pid %d): RSS after warm-up (%zu scans) %.1f MiB, lowest since %.1f MiB, at the end "
                "%.1f MiB (%+.1f from the lowest), max %.1f MiB; tolerance %+.1f MiB: %s\n",
                pid_, options_.warmup, *baseline_mib_, lowest_mib_, latest_mib_, growth, peak_mib_,
                options_.rss_tolerance_mib, flat ? "flat" : "GREW");
    return flat;
  }

  bool reportBacklog() const {
    const bool kept_up = max_backlog_ <= options_.backlog;
    std::printf("backlog after warm-up: at most %zu scans waiting (limit %zu): %s\n", max_backlog_, options_.backlog,
                kept_up ? "kept up" : "FELL BEHIND (the memory figures include the queued scans; lower the rate)");
    return kept_up;
  }

  // With the player faster than the nodelet, this is the nodelet's throughput, ROS layer included.
  void reportThroughput() const {
    const double seconds = (last_odometry_ - first_arrival_).toSec();
    if (odometry_count_ == 0 || seconds <= 0.0) return;
    std::printf("throughput: %zu odometry messages in %.2f s from the first cloud's arrival to the last odometry "
                "(%.1f scans/s)\n",
                odometry_count_, seconds, odometry_count_ / seconds);
  }

  // Prints where every scan went; returns how many are unexplained.
  size_t reportScans() const {
    const auto by_reason = [](const std::map<std::string, size_t>& counts) {
      std::string text;
      for (const auto& [reason, count] : counts) {
        text += (text.empty() ? " (" : ", ") + reason + ": " + std::to_string(count);
      }
      return text.empty() ? text : text + ")";
    };
    // Lost in transport (published, never received), or received and in no counter.
    const size_t lost = options_.scans > counters_.received ? options_.scans - counters_.received : 0;
    const size_t accounted = counters_.accounted();
    const size_t uncounted = counters_.received > accounted ? counters_.received - accounted : 0;
    std::printf("scans: published %zu, received %zu, processed %zu, skipped %zu%s, rejected %zu%s, dropped %zu "
                "(processing slower than input); unexplained %zu\n",
                options_.scans, counters_.received, counters_.processed, NodeCounters::sum(counters_.skipped),
                by_reason(counters_.skipped).c_str(), NodeCounters::sum(counters_.rejected),
                by_reason(counters_.rejected).c_str(), counters_.dropped, lost + uncounted);
    std::printf("odometry messages received %zu; registrations failed %zu; odometry restarts %zu%s\n",
                odometry_count_, counters_.failed_registrations, NodeCounters::sum(counters_.restarts),
                by_reason(counters_.restarts).c_str());
    return lost + uncounted;
  }

  const Options options_;
  const int pid_;
  ros::NodeHandle node_;
  ros::Subscriber odometry_, diagnostics_, points_;
  std::map<ros::Time, ros::WallTime> arrivals_;  // of clouds not yet answered by odometry, by stamp
  ros::WallTime first_arrival_, last_odometry_;
  size_t odometry_count_ = 0;
  NodeCounters counters_;
  std::vector<Block> blocks_;
  std::optional<double> baseline_mib_;
  double latest_mib_ = 0.0;
  double lowest_mib_ = 0.0;
  double peak_mib_ = 0.0;
  size_t max_backlog_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
  return elo::tools::runTool("soak_monitor", kUsage, argc, argv, [&] {
    const Options options = parseArguments(argc, argv);
    ros::init(argc, argv, "soak_monitor", ros::init_options::AnonymousName);
    ros::NodeHandle node;
    const int pid = nodePid(options.manager);
    std::printf("watching %s (pid %d) for %zu scans\n", options.manager.c_str(), pid, options.scans);
    std::fflush(stdout);
    SoakMonitor monitor(options, pid);
    const bool complete = monitor.watch();
    return monitor.report(complete);
  });
}

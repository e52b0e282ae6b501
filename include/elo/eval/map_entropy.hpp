// The sharpness of a map built from scans at their estimated poses: a measure of odometry for drives
// without ground truth. Mean map entropy (MME, Razlaff et al. 2013; Droeschel and Behnke 2018): around a
// sample of the map's points, the covariance S of the map points within a radius gives the entropy
// 0.5 ln det(2 pi e S). A pose error smears each surface over the scans that saw it, which spreads the
// points and raises the entropy, so the lower mean belongs to the better trajectory. Compare MMEs only
// between trajectories of the same scans under the same options.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace elo {

struct MapEntropyOptions {
  double radius = 0.3;      // m: the neighbourhood of a scored point
  double min_range = 3.0;   // m: closer points (the vehicle, the noisy near field) stay out of the map
  double max_range = 30.0;  // m: farther points are too sparse for a neighbourhood of `radius`
  int point_stride = 2;     // every n-th point of a scan joins the map
  int query_stride = 50;    // every n-th map point is scored
  int min_neighbours = 10;  // a point with fewer map points within `radius` is not scored
};

struct MapEntropy {
  double mean_entropy = 0.0;            // nats; lower is sharper
  double mean_plane_deviation_m = 0.0;  // mean of sqrt(smallest eigenvalue of S): the spread off the local plane
  size_t scored_points = 0;
  size_t map_points = 0;
};

// Moves the points of one scan, kept as the options say, into the map frame by `pose` and appends them.
void addScanToMap(const std::vector<Eigen::Vector3f>& scan, const Eigen::Isometry3d& pose,
                  const MapEntropyOptions& options, std::vector<Eigen::Vector3f>& map);

// The MME of `map`. Throws std::invalid_argument when no point has enough neighbours.
MapEntropy mapEntropy(const std::vector<Eigen::Vector3f>& map, const MapEntropyOptions& options);

}  // namespace elo

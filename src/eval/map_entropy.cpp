#include "elo/eval/map_entropy.hpp"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <stdexcept>

namespace elo {

void addScanToMap(const std::vector<Eigen::Vector3f>& scan, const Eigen::Isometry3d& pose,
                  const MapEntropyOptions& options, std::vector<Eigen::Vector3f>& map) {
  const Eigen::Isometry3f to_map = pose.cast<float>();
  for (size_t i = 0; i < scan.size(); i += static_cast<size_t>(options.point_stride)) {
    const float range = scan[i].norm();
    if (range >= options.min_range && range <= options.max_range) map.push_back(to_map * scan[i]);
  }
}

namespace {

// The covariance of the points `indices` of `cloud`, in double: a neighbourhood of a few hundred points
// of a surface a few centimetres thick loses its smallest eigenvalue to float round-off.
Eigen::Matrix3d covarianceOf(const pcl::PointCloud<pcl::PointXYZ>& cloud, const std::vector<int>& indices) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int index : indices) mean += cloud[index].getVector3fMap().cast<double>();
  mean /= static_cast<double>(indices.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const int index : indices) {
    const Eigen::Vector3d offset = cloud[index].getVector3fMap().cast<double>() - mean;
    covariance += offset * offset.transpose();
  }
  return covariance / static_cast<double>(indices.size());
}

}  // namespace

MapEntropy mapEntropy(const std::vector<Eigen::Vector3f>& map, const MapEntropyOptions& options) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(map.size());
  for (const Eigen::Vector3f& point : map) cloud->push_back(pcl::PointXYZ(point.x(), point.y(), point.z()));
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  if (!cloud->empty()) tree.setInputCloud(cloud);

  MapEntropy result;
  result.map_points = map.size();
  double entropy_sum = 0.0;
  double deviation_sum = 0.0;
  std::vector<int> indices;
  std::vector<float> squared_distances;
  for (size_t i = 0; i < cloud->size(); i += static_cast<size_t>(options.query_stride)) {
    if (tree.radiusSearch((*cloud)[i], options.radius, indices, squared_distances) < options.min_neighbours) continue;
    const Eigen::Matrix3d covariance = covarianceOf(*cloud, indices);
    const double determinant = (2.0 * M_PI * M_E * covariance).determinant();
    if (!(determinant > 0.0)) continue;  // collinear or repeated points: no volume to measure
    entropy_sum += 0.5 * std::log(determinant);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(covariance, Eigen::EigenvaluesOnly);
    deviation_sum += std::sqrt(std::max(0.0, eigen.eigenvalues()[0]));
    ++result.scored_points;
  }
  if (result.scored_points == 0) {
    throw std::invalid_argument("no map point has " + std::to_string(options.min_neighbours) + " neighbours within " +
                                std::to_string(options.radius) + " m");
  }
  result.mean_entropy = entropy_sum / static_cast<double>(result.scored_points);
  result.mean_plane_deviation_m = deviation_sum / static_cast<double>(result.scored_points);
  return result;
}

}  // namespace elo

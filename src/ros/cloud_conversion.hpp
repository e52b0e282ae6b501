// sensor_msgs/PointCloud2 <-> elo::PointCloud. Reading is elo::convertPointCloud2 (elo/io/point_cloud2.hpp),
// ROS-free and shared with elo_run's bag readers: this file only describes a ROS 1 message to it, without
// copying the points.
#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <string>

#include "elo/io/point_cloud2.hpp"
#include "elo/types.hpp"

namespace elo_ros {

using elo::CloudProblem;
using elo::ConvertedCloud;

// The message as elo::convertPointCloud2 reads it; the view borrows the message's data.
elo::PointCloud2View viewOf(const sensor_msgs::PointCloud2& message);

// elo::convertPointCloud2 of the message (its fields, per-point time conventions and rejections).
ConvertedCloud fromPointCloud2(const sensor_msgs::PointCloud2& message);

// Appends a float32 or uint16 field (sensor_msgs::PointField's datatype) to `message`'s point layout, at
// the next offset aligned to its size, as a C struct would; point_step grows to hold it. Every
// PointCloud2 the package writes lays its points out with it.
void addField(sensor_msgs::PointCloud2& message, const char* name, uint8_t datatype);

// Packs a cloud as x y z [intensity] [ring] [time]: float32, ring uint16, each field naturally aligned;
// optional fields only when the cloud has them. The header stamp is the cloud's stamp.
sensor_msgs::PointCloud2 toPointCloud2(const elo::PointCloud& cloud, const std::string& frame_id);

}  // namespace elo_ros

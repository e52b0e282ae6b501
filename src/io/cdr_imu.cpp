#include "elo/io/cdr_imu.hpp"

#include "cdr_reader.hpp"

namespace elo {
namespace {

using io_detail::CdrReader;

Eigen::Vector3d readVector3(CdrReader& reader, const char* what) {
  Eigen::Vector3d vector;
  for (int axis = 0; axis < 3; ++axis) vector[axis] = reader.read<double>(what);
  return vector;
}

// A float64[9] covariance: a fixed array, serialized without a length. Returns its first element, the
// only one REP-145 gives a meaning of its own (-1: the quantity is not given).
double readCovariance(CdrReader& reader, const char* what) {
  const double first = reader.read<double>(what);
  for (int i = 1; i < 9; ++i) reader.read<double>(what);
  return first;
}

}  // namespace

CdrImu decodeCdrImu(const uint8_t* data, size_t size) {
  CdrReader reader(data, size, "Imu");
  CdrImu imu;
  imu.stamp = reader.readStamp();
  reader.readString("header.frame_id");
  for (int i = 0; i < 4; ++i) reader.read<double>("orientation");
  readCovariance(reader, "orientation_covariance");
  imu.angular_velocity = readVector3(reader, "angular_velocity");
  imu.has_angular_velocity = readCovariance(reader, "angular_velocity_covariance") != -1.0;
  imu.linear_acceleration = readVector3(reader, "linear_acceleration");
  readCovariance(reader, "linear_acceleration_covariance");
  return imu;
}

}  // namespace elo

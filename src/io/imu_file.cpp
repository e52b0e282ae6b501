#include "elo/io/imu_file.hpp"

#include <fstream>

#include "text_format.hpp"

namespace elo {

std::vector<ImuSample> readImuFile(const std::string& path) {
  std::ifstream stream = io_detail::openForReading(path);
  return readImuFile(stream, path);
}

std::vector<ImuSample> readImuFile(std::istream& stream, const std::string& name) {
  std::vector<ImuSample> samples;
  for (const std::vector<double>& row : io_detail::readNumberRows(stream, name, 7)) {
    ImuSample sample;
    sample.stamp = row[0];
    sample.angular_velocity = {row[1], row[2], row[3]};
    sample.specific_force = {row[4], row[5], row[6]};
    samples.push_back(sample);
  }
  return samples;
}

void writeImuFile(const std::string& path, const std::vector<ImuSample>& samples) {
  std::ofstream stream = io_detail::openForWriting(path);
  for (const ImuSample& s : samples) {
    stream << io_detail::formatDoubles({s.stamp, s.angular_velocity.x(), s.angular_velocity.y(), s.angular_velocity.z(),
                                        s.specific_force.x(), s.specific_force.y(), s.specific_force.z()})
           << '\n';
  }
  io_detail::finishWriting(stream, path);
}

}  // namespace elo

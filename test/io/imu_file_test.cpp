// imu.txt (docs/imu.md): `t wx wy wz ax ay az` a line, written and read back to the bit; a malformed line
// is an error naming the file and the line.
#include <gtest/gtest.h>

#include <sstream>

#include "elo/io/imu_file.hpp"
#include "elo/io/io_error.hpp"
#include "temp_directory.hpp"

namespace elo {
namespace {

TEST(ImuFile, WriteThenReadIsExact) {
  const test::TempDirectory directory;
  ImuSample sample;
  sample.stamp = 1317385412.123456789;
  sample.angular_velocity = {0.1, -2.0 / 3.0, 1e-9};
  sample.specific_force = {0.05, -0.3, 9.80665};
  const std::string path = directory.file("imu.txt");
  writeImuFile(path, {sample, sample});
  const std::vector<ImuSample> read = readImuFile(path);
  ASSERT_EQ(read.size(), 2u);
  EXPECT_EQ(read[1].stamp, sample.stamp);
  EXPECT_EQ(read[1].angular_velocity, sample.angular_velocity);
  EXPECT_EQ(read[1].specific_force, sample.specific_force);
}

TEST(ImuFile, BlankLinesAreSkipped) {
  std::istringstream text("0.000 0 0 0.5 0 0 9.81\n\n0.005 0 0 0.5 0 0 9.81\n");
  EXPECT_EQ(readImuFile(text, "imu.txt").size(), 2u);
}

TEST(ImuFile, AMalformedLineThrowsNamingItsLine) {
  std::istringstream short_line("0.000 0 0 0.5 0 0 9.81\n0.005 0 0 0.5 0 9.81\n");
  try {
    readImuFile(short_line, "imu.txt");
    FAIL() << "a line of six numbers was read";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find("imu.txt"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("2"), std::string::npos) << error.what();
  }
  std::istringstream word("0.000 0 0 x 0 0 9.81\n");
  EXPECT_THROW(readImuFile(word, "imu.txt"), IoError);
}

}  // namespace
}  // namespace elo

// The elo_sim command line: help, clear errors with exit code 2, and a small run.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>

#include "../io/temp_directory.hpp"

namespace {

int runTool(const std::string& arguments) {
  const std::string command = std::string(ELO_SIM_TOOL) + " " + arguments + " >/dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(EloSimCli, HelpSucceeds) { EXPECT_EQ(runTool("--help"), 0); }

TEST(EloSimCli, BadArgumentsExitWithTwo) {
  const elo::test::TempDirectory directory;
  const std::string out = " --output " + directory.file("seq");
  EXPECT_EQ(runTool("--trajectory straight --frames 2" + out), 2);                       // no world
  EXPECT_EQ(runTool("--world moon --trajectory straight --frames 2" + out), 2);          // unknown world
  EXPECT_EQ(runTool("--world urban --trajectory spiral --frames 2" + out), 2);           // unknown trajectory
  EXPECT_EQ(runTool("--world urban --frames 2" + out), 2);                               // no trajectory
  EXPECT_EQ(runTool("--world urban --trajectory straight --poses x.txt --frames 2" + out), 2);  // both
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames two" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 0" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight" + out), 2);                    // no frame count
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --sensor hdl32" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --dropout 1.5" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --deskewed yes" + out), 2);
  EXPECT_EQ(runTool("--world urban --poses /nonexistent/poses.txt" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2 --bag x.bag" + out), 2);
  EXPECT_EQ(runTool("--world urban --trajectory straight --frames 2"), 2);               // no output
  EXPECT_FALSE(std::filesystem::exists(directory.file("seq")));
}

TEST(EloSimCli, WritesASequence) {
  const elo::test::TempDirectory directory;
  EXPECT_EQ(runTool("--world parking --trajectory uturn --frames 3 --sensor vlp16 --seed 9 --noise 0.01 "
                    "--dropout 0.05 --deskewed 0 --moving-cars 2 --threads 2 --output " + directory.file("seq")),
            0);
  for (const std::string file : {"velodyne/000000.bin", "velodyne/000002.bin", "poses.txt", "times.txt", "calib.txt"}) {
    EXPECT_TRUE(std::filesystem::exists(directory.file("seq/" + file))) << file;
  }
}

}  // namespace

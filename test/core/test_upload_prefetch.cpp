// What a prefetched upload (Backend::prefetch(), docs/cuda.md) rests on, on the host: the thread that
// stages it, and which cloud it holds. The CUDA backend's prefetching itself is tested against its
// uploads without prefetching in test_backend_agreement.cpp.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <thread>
#include <vector>

#include "core/background_task.hpp"
#include "core/cloud_identity.hpp"

namespace elo {
namespace {

TEST(BackgroundTask, RunsTheJobsInTheOrderHandedOverAndWaitSeesTheirWork) {
  std::vector<int> done;  // written by the jobs only, read here only after wait()
  BackgroundTask task;
  for (int job = 0; job < 100; ++job) task.run([&done, job] { done.push_back(job); });
  task.wait();
  ASSERT_EQ(done.size(), 100u);
  for (int job = 0; job < 100; ++job) EXPECT_EQ(done[job], job);
}

TEST(BackgroundTask, RunsBesideTheCallerAndRunWaitsForTheJobBefore) {
  std::atomic<bool> release{false};
  std::atomic<int> finished{0};
  BackgroundTask task;
  task.run([&] {
    while (!release) std::this_thread::yield();
    ++finished;
  });
  // The job is blocked on this thread, so it must be running elsewhere: run() returned while it waits.
  EXPECT_EQ(finished, 0);
  std::thread releaser([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    release = true;
  });
  int finished_before_second = -1;
  task.run([&] { finished_before_second = finished; });
  task.wait();
  releaser.join();
  EXPECT_EQ(finished_before_second, 1);
}

TEST(BackgroundTask, FinishesTheJobHandedOverBeforeItStops) {
  bool done = false;
  {
    BackgroundTask task;
    task.run([&done] {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      done = true;
    });
  }
  EXPECT_TRUE(done);
}

PointCloud cloudOf(size_t points, double stamp) {
  PointCloud cloud;
  cloud.points.assign(points, Vec3f(1.0f, 2.0f, 3.0f));
  cloud.ring.assign(points, 4);
  cloud.time.assign(points, 0.01f);
  cloud.stamp = stamp;
  return cloud;
}

TEST(CloudIdentity, AMovedCloudIsTheSameCloud) {
  PointCloud cloud = cloudOf(10, 1.0);
  const CloudIdentity before = CloudIdentity::of(cloud);
  const PointCloud moved = std::move(cloud);
  EXPECT_TRUE(CloudIdentity::of(moved) == before);
  PointCloud assigned;
  assigned = PointCloud(moved);
  EXPECT_FALSE(CloudIdentity::of(assigned) == before) << "a copy has arrays of its own";
}

TEST(CloudIdentity, AnotherCloudOrAChangedOneIsNot) {
  PointCloud cloud = cloudOf(10, 1.0);
  const CloudIdentity original = CloudIdentity::of(cloud);
  EXPECT_TRUE(CloudIdentity::of(cloud) == original);
  EXPECT_FALSE(CloudIdentity::of(cloudOf(10, 1.0)) == original) << "equal values, other arrays";

  PointCloud restamped = cloud;
  const CloudIdentity copied = CloudIdentity::of(restamped);
  restamped.stamp = 1.1;
  EXPECT_FALSE(CloudIdentity::of(restamped) == copied);

  // A copy of the points into a new array (allocated while the old one lives, so elsewhere), and
  // arrays of another length.
  const std::vector<void (*)(PointCloud&)> changes = {
      [](PointCloud& c) { c.points = std::vector<Vec3f>(c.points); }, [](PointCloud& c) { c.points.resize(11); },
      [](PointCloud& c) { c.ring.clear(); }, [](PointCloud& c) { c.time.clear(); }};
  for (const auto change : changes) {
    PointCloud changed = cloud;
    const CloudIdentity unchanged = CloudIdentity::of(changed);
    change(changed);
    EXPECT_FALSE(CloudIdentity::of(changed) == unchanged);
  }
}

TEST(CloudIdentity, AStampThatIsNotANumberMatchesNothing) {
  PointCloud cloud = cloudOf(3, std::nan(""));
  EXPECT_FALSE(CloudIdentity::of(cloud) == CloudIdentity::of(cloud));
}

}  // namespace
}  // namespace elo

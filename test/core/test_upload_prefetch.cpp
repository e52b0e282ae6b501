// Prefetched uploads (Backend::prefetch(), docs/cuda.md) on the host: the thread that stages them, which
// cloud an upload holds, and the two upload buffers' hand-over between the caller and that thread, over
// host buffers that stand in for the CUDA backend's (run under ThreadSanitizer by make test-sanitize).
// The CUDA backend's prefetching itself is tested against its uploads without prefetching in
// test_backend_agreement.cpp.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/background_task.hpp"
#include "core/cloud_identity.hpp"
#include "core/double_buffered_upload.hpp"

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

// The arrays a staging reads, as the CUDA backend hands them to its staging thread: not the PointCloud,
// which the caller may move meanwhile.
struct CloudArrays {
  const Vec3f* points;
  const float* times;
  size_t count;
};

CloudArrays arraysOf(const PointCloud& cloud) { return {cloud.points.data(), cloud.time.data(), cloud.size()}; }

// Host buffers standing in for a device backend's: an upload copies the cloud's x coordinates, then its
// times when it takes them.
struct HostBuffers {
  std::vector<float> values;
};

void uploadInto(HostBuffers& buffers, const CloudArrays& cloud, bool with_times) {
  buffers.values.clear();
  for (size_t i = 0; i < cloud.count; ++i) buffers.values.push_back(cloud.points[i].x());
  if (with_times) buffers.values.insert(buffers.values.end(), cloud.times, cloud.times + cloud.count);
}

// A backend's prefetch() and projection over the two buffers, as the CUDA backend's.
struct HostBackend {
  DoubleBufferedUpload<HostBuffers> uploads;
  int prefetched_projections = 0;

  void prefetch(const PointCloud& cloud, bool with_times = true) {
    const CloudArrays arrays = arraysOf(cloud);
    uploads.prefetch(CloudIdentity::of(cloud), with_times,
                     [arrays, with_times](HostBuffers& buffers) { uploadInto(buffers, arrays, with_times); });
  }
  // What the projection of `cloud` reads.
  std::vector<float> project(const PointCloud& cloud, bool with_times = true) {
    const auto taken = uploads.take(CloudIdentity::of(cloud), with_times);
    if (taken.prefetched) {
      ++prefetched_projections;
    } else {
      uploadInto(taken.buffers, arraysOf(cloud), with_times);
    }
    return taken.buffers.values;
  }
};

// A cloud of `points` points whose values tell it from every other cloud of the test.
PointCloud numberedCloud(int number, size_t points = 1000) {
  PointCloud cloud;
  for (size_t i = 0; i < points; ++i) {
    cloud.points.emplace_back(static_cast<float>(number * 100000 + static_cast<int>(i)), 0.0f, 0.0f);
    cloud.time.push_back(static_cast<float>(-number));
  }
  cloud.stamp = 0.1 * number;
  return cloud;
}

std::vector<float> valuesOf(const PointCloud& cloud) {
  HostBuffers buffers;
  uploadInto(buffers, arraysOf(cloud), true);
  return buffers.values;
}

// elo_run's order: each cloud read one ahead and prefetched before the one before it is projected, then
// moved to where it is projected from, and freed after; the clouds grow and shrink.
TEST(DoubleBufferedUpload, EachCloudPrefetchedAheadIsProjectedFromItsOwnUpload) {
  HostBackend backend;
  constexpr int kClouds = 200;
  const auto points = [](int number) { return static_cast<size_t>(500 + (number * 37) % 700); };
  PointCloud next = numberedCloud(0, points(0));
  backend.prefetch(next);
  for (int number = 0; number < kClouds; ++number) {
    const PointCloud current = std::move(next);
    if (number + 1 < kClouds) {
      next = numberedCloud(number + 1, points(number + 1));
      backend.prefetch(next);
    }
    EXPECT_EQ(backend.project(current), valuesOf(current)) << "cloud " << number;
    backend.uploads.finish();  // as Odometry::process() before it returns: `current` is freed next
  }
  EXPECT_EQ(backend.prefetched_projections, kClouds);
}

// Out of order, the projection still reads the cloud it is given: another cloud than the one
// prefetched, clouds prefetched two and three ahead (the first two are dropped), a cloud prefetched
// without the times its projection needs, the same cloud twice, a copy of a prefetched cloud.
TEST(DoubleBufferedUpload, AProjectionTakesAPrefetchedUploadOnlyForItsOwnCloud) {
  HostBackend backend;
  std::vector<PointCloud> clouds;
  for (int number = 0; number < 4; ++number) clouds.push_back(numberedCloud(number));
  const auto expectProjected = [&](const PointCloud& cloud, bool from_prefetch, const std::string& what) {
    const int before = backend.prefetched_projections;
    EXPECT_EQ(backend.project(cloud), valuesOf(cloud)) << what;
    EXPECT_EQ(backend.prefetched_projections - before, from_prefetch ? 1 : 0) << what;
  };
  backend.prefetch(clouds[0]);
  expectProjected(clouds[1], false, "another cloud than the one prefetched");
  expectProjected(clouds[0], true, "the prefetched cloud after another");
  expectProjected(clouds[0], false, "the same cloud again");
  for (int ahead = 1; ahead < 4; ++ahead) backend.prefetch(clouds[ahead]);
  expectProjected(clouds[1], false, "prefetched 1 ahead, then dropped");
  expectProjected(clouds[2], false, "prefetched 2 ahead, then dropped");
  expectProjected(clouds[3], true, "prefetched 3 ahead");
  backend.prefetch(clouds[2], false);
  expectProjected(clouds[2], false, "prefetched without the times it needs");
  backend.prefetch(clouds[1]);
  const PointCloud copy = clouds[1];
  expectProjected(copy, false, "a copy of the prefetched cloud");
  expectProjected(clouds[1], true, "the prefetched cloud after its copy");
}

// The caller projects the cloud before while the next one is still being staged: it does not wait for it.
TEST(DoubleBufferedUpload, TheCloudBeforeIsProjectedWhileTheNextIsStaged) {
  DoubleBufferedUpload<HostBuffers> uploads;
  const PointCloud first = numberedCloud(1);
  const PointCloud second = numberedCloud(2);
  uploads.prefetch(CloudIdentity::of(first), true, [](HostBuffers& buffers) { buffers.values = {1.0f}; });
  std::atomic<bool> first_taken{false};
  bool waited_in_vain = false;  // written by the staging job, read after finish()
  uploads.prefetch(CloudIdentity::of(second), true, [&](HostBuffers& buffers) {
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(5);
    while (!first_taken && std::chrono::steady_clock::now() < give_up) std::this_thread::yield();
    waited_in_vain = !first_taken;
    buffers.values = {2.0f};
  });
  const auto taken = uploads.take(CloudIdentity::of(first), true);
  first_taken = true;
  EXPECT_TRUE(taken.prefetched);
  EXPECT_EQ(taken.buffers.values, std::vector<float>{1.0f});
  uploads.finish();
  EXPECT_FALSE(waited_in_vain) << "take() waited for the staging of the next cloud";
  EXPECT_EQ(uploads.take(CloudIdentity::of(second), true).buffers.values, std::vector<float>{2.0f});
}

TEST(DoubleBufferedUpload, AFailedStagingIsReportedByTheProjectionOfItsCloudOnly) {
  DoubleBufferedUpload<HostBuffers> uploads;
  const PointCloud failing = numberedCloud(1);
  uploads.prefetch(CloudIdentity::of(failing), true, [](HostBuffers&) { throw std::runtime_error("no memory"); });
  uploads.finish();
  EXPECT_FALSE(uploads.take(CloudIdentity::of(numberedCloud(2)), true).prefetched);
  EXPECT_THROW(uploads.take(CloudIdentity::of(failing), true), std::runtime_error);
  EXPECT_FALSE(uploads.take(CloudIdentity::of(failing), true).prefetched) << "reported once, then uploaded as usual";
}

}  // namespace
}  // namespace elo

// The queue between the subscriber and the worker: every scan, or only the latest with drops counted.
#include <gtest/gtest.h>

#include <boost/make_shared.hpp>

#include <thread>

#include "scan_queue.hpp"

namespace {

elo_ros::QueuedCloud cloudStamped(uint32_t seconds) {
  auto message = boost::make_shared<sensor_msgs::PointCloud2>();
  message->header.stamp = ros::Time(seconds, 0);
  return {message, std::chrono::steady_clock::now()};
}

uint32_t secondsOf(const std::optional<elo_ros::QueuedCloud>& cloud) { return cloud->message->header.stamp.sec; }

TEST(RosScanQueue, UnboundedQueueKeepsEveryScanInOrder) {
  elo_ros::ScanQueue queue(0);
  for (uint32_t i = 1; i <= 5; ++i) EXPECT_EQ(queue.push(cloudStamped(i)), 0u);
  for (uint32_t i = 1; i <= 5; ++i) EXPECT_EQ(secondsOf(queue.pop()), i);
}

TEST(RosScanQueue, LatestOnlyQueueDropsTheOlderScan) {
  elo_ros::ScanQueue queue(1);
  EXPECT_EQ(queue.push(cloudStamped(1)), 0u);
  EXPECT_EQ(queue.push(cloudStamped(2)), 1u);
  EXPECT_EQ(queue.size(), 1u);
  EXPECT_EQ(secondsOf(queue.pop()), 2u);
}

TEST(RosScanQueue, CloseLetsTheWorkerFinishThenStop) {
  elo_ros::ScanQueue queue(0);
  queue.push(cloudStamped(1));
  queue.close();
  EXPECT_EQ(queue.push(cloudStamped(2)), 0u);  // refused
  EXPECT_EQ(secondsOf(queue.pop()), 1u);
  EXPECT_FALSE(queue.pop().has_value());
}

TEST(RosScanQueue, PopWaitsForAPush) {
  elo_ros::ScanQueue queue(0);
  std::thread producer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    queue.push(cloudStamped(9));
  });
  EXPECT_EQ(secondsOf(queue.pop()), 9u);
  producer.join();
}

}  // namespace

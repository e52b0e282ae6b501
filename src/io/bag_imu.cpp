#include "elo/io/bag_imu.hpp"

#include <algorithm>

namespace elo {

void BagImu::skip(const std::string& reason, const std::string& detail) {
  ++skipped[reason];
  if (reason == imu_message::kUnreadable && unreadable_detail.empty()) unreadable_detail = detail;
}

void BagImu::sortByStamp() {
  std::stable_sort(samples.begin(), samples.end(),
                   [](const ImuSample& a, const ImuSample& b) { return a.stamp < b.stamp; });
}

}  // namespace elo

// Threading helpers of the CPU backend.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <vector>

namespace elo::cpu {

// Sums `body(begin, end, partial)` over [0, count) in fixed blocks and adds the block results in block
// order. The result is therefore the same bit for bit whatever the number of threads, so trajectories
// are reproducible across machines, thread counts and runs.
template <typename Sum, typename Body>
Sum deterministicSum(size_t count, const Body& body) {
  constexpr size_t kBlock = 4096;
  const size_t blocks = (count + kBlock - 1) / kBlock;
  std::vector<Sum> partials(blocks);
  tbb::parallel_for(size_t{0}, blocks, [&](size_t block) {
    body(block * kBlock, std::min(count, (block + 1) * kBlock), partials[block]);
  });
  Sum total;
  for (const Sum& partial : partials) total += partial;
  return total;
}

// Runs `body(i)` for every i in [0, count) across the threads of the current arena.
template <typename Body>
void parallelFor(size_t count, const Body& body) {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) body(i);
  });
}

}  // namespace elo::cpu

// A device backend's two upload buffers (Backend::prefetch(), docs/cuda.md): which cloud each holds, and
// who may touch which when. prefetch() stages a cloud into the buffers the latest prefetch did not use, on
// a thread of its own, while the caller goes on with the cloud before it. The staging thread touches only
// the buffers of the latest prefetch; the caller's thread touches the other buffers at any time, and
// those too once their staging is done. `Buffers` is the backend's own (on the CUDA backend pinned
// memory, its device copy and the events that order their reuse on the GPU).
#pragma once

#include <exception>
#include <functional>
#include <optional>
#include <utility>

#include "core/background_task.hpp"
#include "core/cloud_identity.hpp"

namespace elo {

template <typename Buffers>
class DoubleBufferedUpload {
 public:
  // What take() gives: the buffers to project the cloud from, and whether a prefetch already staged it
  // there. When not, the caller uploads the cloud into them itself.
  struct Taken {
    Buffers& buffers;
    bool prefetched;
  };

  // Hands `stage` the buffers the latest prefetch did not use, to run on the staging thread once the
  // staging before it is done; `cloud` names what it stages (its times too when `with_times`). What
  // `stage` throws is rethrown by the take() of that cloud. The buffers given to `stage` may still hold
  // a cloud prefetched before and not taken; it is dropped.
  void prefetch(const CloudIdentity& cloud, bool with_times, std::function<void(Buffers&)> stage) {
    const int target = 1 - prefetching_;
    Slot& slot = slots_[target];
    // The staging thread's last job on these buffers ended before its job on the others began.
    slot.prefetched = cloud;
    slot.with_times = with_times;
    slot.error = nullptr;
    prefetching_ = target;
    stager_.run([&slot, stage = std::move(stage)] {
      try {
        stage(slot.buffers);
      } catch (...) {
        slot.error = std::current_exception();
      }
    });
  }

  // The buffers a prefetch staged `cloud` into (with its times when `with_times`), once staged; or, when
  // none did, the buffers the staging thread is not using, dropping a cloud prefetched into them and not
  // taken. Either way the buffers are the caller's until the next prefetch() hands them to the stager.
  Taken take(const CloudIdentity& cloud, bool with_times) {
    for (int buffers = 0; buffers < 2; ++buffers) {
      Slot& slot = slots_[buffers];
      if (!(slot.prefetched == cloud) || (with_times && !slot.with_times)) continue;
      // The staging thread finished every job before the latest one.
      if (buffers == prefetching_) stager_.wait();
      slot.prefetched.reset();
      if (slot.error) std::rethrow_exception(std::exchange(slot.error, nullptr));
      return {slot.buffers, true};
    }
    Slot& free = slots_[1 - prefetching_];
    free.prefetched.reset();
    free.error = nullptr;
    return {free.buffers, false};
  }

  // Runs `prepare` on both buffers (to size them); before the first prefetch, when the caller owns both.
  void prepareBoth(const std::function<void(Buffers&)>& prepare) {
    for (Slot& slot : slots_) prepare(slot.buffers);
  }

  // Waits until the staging thread is done: it no longer reads the cloud last prefetched.
  void finish() noexcept { stager_.wait(); }

 private:
  struct Slot {
    Buffers buffers;
    // The cloud staged here by a prefetch that no take() took yet; with its times or not.
    std::optional<CloudIdentity> prefetched;
    bool with_times = false;
    std::exception_ptr error;  // what its staging threw
  };

  Slot slots_[2];
  int prefetching_ = 1;  // the buffers of the latest prefetch (the first goes into slots_[0])
  // Last: it stops, finishing its job, before the buffers that job writes go.
  BackgroundTask stager_;
};

}  // namespace elo

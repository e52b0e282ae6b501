// One thread beside the caller's that runs the jobs handed to it, one at a time and in order. The CUDA
// backend stages the next scan's upload on it while the current scan is processed (docs/cuda.md).
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace elo {

class BackgroundTask {
 public:
  BackgroundTask() : thread_([this] { work(); }) {}
  // Finishes the job handed over, then stops the thread.
  ~BackgroundTask() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }
  BackgroundTask(const BackgroundTask&) = delete;
  BackgroundTask& operator=(const BackgroundTask&) = delete;

  // Waits until the job handed over before has finished, then hands over `job`. A job must not throw
  // (one that does ends the program): it reports its failures itself.
  void run(std::function<void()> job) {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !job_; });
    job_ = std::move(job);
    lock.unlock();
    changed_.notify_all();
  }

  // Waits until the job handed over last has finished. Everything it did happens before this returns.
  void wait() noexcept {
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [this] { return !job_; });
  }

 private:
  void work() {
    std::unique_lock<std::mutex> lock(mutex_);
    while (true) {
      changed_.wait(lock, [this] { return stopping_ || job_; });
      if (!job_) return;
      // run() and wait() leave job_ alone while it is set: it runs unlocked.
      lock.unlock();
      job_();
      lock.lock();
      job_ = nullptr;
      changed_.notify_all();
    }
  }

  std::mutex mutex_;
  std::condition_variable changed_;
  std::function<void()> job_;  // the job handed over and not finished; empty when idle
  bool stopping_ = false;
  std::thread thread_;  // last: it starts once the members above exist
};

}  // namespace elo

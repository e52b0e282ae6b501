// RAII owners of the CUDA backend's memory, stream and events, and the error check every CUDA call
// goes through. Host code only (the CUDA runtime API, no device code).
#pragma once

#include <cuda_runtime_api.h>

#include <algorithm>
#include <cstddef>
#include <stdexcept>
#include <string>

namespace elo::cuda {

// Throws std::runtime_error naming `what` when `status` is an error.
inline void check(cudaError_t status, const char* what) {
  if (status != cudaSuccess) {
    throw std::runtime_error(std::string("CUDA backend: ") + what + " failed: " + cudaGetErrorString(status));
  }
}

// What an array holding `capacity` elements and asked for `count` more than that grows to: by half at
// least. Arrays sized per scan or per render (the upload, a map render's points) are asked for a little
// more than ever before many times over a drive's first scans; each reallocation costs a free that waits
// for the device and an allocation, together longer than a frame (pinned memory most), so they happen a
// few times rather than at each new largest scan.
inline size_t grownCapacity(size_t capacity, size_t count) { return std::max(count, capacity + capacity / 2); }

// An array in device memory. It is allocated up front and grows only when asked for more than ever
// before, so the frames themselves never allocate.
template <typename T>
class DeviceArray {
 public:
  DeviceArray() = default;
  explicit DeviceArray(size_t count) { reserve(count); }
  ~DeviceArray() { cudaFree(data_); }
  DeviceArray(const DeviceArray&) = delete;
  DeviceArray& operator=(const DeviceArray&) = delete;

  // Makes room for `count` elements (grownCapacity()); the contents are lost when it has to reallocate.
  void reserve(size_t count) {
    if (count <= capacity_) return;
    const size_t capacity = grownCapacity(capacity_, count);
    cudaFree(data_);
    data_ = nullptr;
    capacity_ = 0;
    void* memory = nullptr;
    check(cudaMalloc(&memory, capacity * sizeof(T)), "cudaMalloc");
    data_ = static_cast<T*>(memory);
    capacity_ = capacity;
  }

  T* data() const { return data_; }
  size_t capacity() const { return capacity_; }

 private:
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

// Page-locked host memory: the scan upload and the small results copied back each frame.
template <typename T>
class PinnedArray {
 public:
  PinnedArray() = default;
  explicit PinnedArray(size_t count) { reserve(count); }
  ~PinnedArray() { cudaFreeHost(data_); }
  PinnedArray(const PinnedArray&) = delete;
  PinnedArray& operator=(const PinnedArray&) = delete;

  // Makes room for `count` elements (grownCapacity()); the contents are lost when it has to reallocate.
  void reserve(size_t count) {
    if (count <= capacity_) return;
    const size_t capacity = grownCapacity(capacity_, count);
    cudaFreeHost(data_);
    data_ = nullptr;
    capacity_ = 0;
    void* memory = nullptr;
    check(cudaMallocHost(&memory, capacity * sizeof(T)), "cudaMallocHost");
    data_ = static_cast<T*>(memory);
    capacity_ = capacity;
  }

  T* data() const { return data_; }
  T& operator[](size_t i) const { return data_[i]; }

 private:
  T* data_ = nullptr;
  size_t capacity_ = 0;
};

class Stream {
 public:
  Stream() { check(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking), "cudaStreamCreate"); }
  ~Stream() { cudaStreamDestroy(stream_); }
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;
  cudaStream_t get() const { return stream_; }

 private:
  cudaStream_t stream_ = nullptr;
};

class Event {
 public:
  // cudaEventDisableTiming for an event only waited on: it costs less to record and to wait for.
  explicit Event(unsigned flags = cudaEventDefault) {
    check(cudaEventCreateWithFlags(&event_, flags), "cudaEventCreate");
  }
  ~Event() { cudaEventDestroy(event_); }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
  cudaEvent_t get() const { return event_; }

 private:
  cudaEvent_t event_ = nullptr;
};

}  // namespace elo::cuda

#pragma once
// Hands the latest frame from the one thread that makes frames to every connected page: each
// client waits for a frame newer than the one it sent last. A slow client skips frames rather
// than queueing them, so the producer never waits on a client.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>

namespace sedbridge::view {

class FrameHub {
 public:
  void Publish(std::string frame);
  /// The latest frame and its number (0: none yet).
  std::string Latest(uint64_t* number) const;
  /// Waits up to `timeout` for a frame newer than `*seen`; on one, stores it and its number and
  /// returns true. False on timeout or once Close() was called.
  bool WaitNewer(uint64_t* seen, std::string* frame, std::chrono::milliseconds timeout);
  /// Wakes every waiting client for good (the server is stopping).
  void Close();
  bool closed() const;

  std::atomic<int> clients{0};            ///< streams open now
  std::atomic<int64_t> clients_total{0};  ///< streams opened since start
  std::atomic<int64_t> frames_sent{0};    ///< frames written to any stream

 private:
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::string frame_;
  uint64_t number_ = 0;
  bool closed_ = false;
};

}  // namespace sedbridge::view

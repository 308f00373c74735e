#pragma once
// Keeps the frames of one CAN interface from a source that carries several, e.g. a log
// recorded with `candump -l any` (lines from can0, can1, ... interleaved). Without a name it
// passes everything and only notes which interfaces it saw, so a caller can warn that a log
// mixes buses.

#include <cstdint>
#include <memory>
#include <set>
#include <string>

#include "sensors/frame_source.h"

namespace sedbridge::sensors {

class InterfaceFilterSource final : public FrameSource {
 public:
  /// @param[in] inner      the source to read (not owned; must outlive this)
  /// @param[in] interface  keep only frames whose interface is this name (e.g. "can1");
  ///                       "" keeps every frame
  InterfaceFilterSource(FrameSource& inner, std::string interface);

  /// Next frame of the chosen interface; frames of other interfaces are skipped and counted.
  std::optional<Frame> Next(int64_t timeout_us) override;
  bool Done() const override { return inner_.Done(); }
  void Close() override { inner_.Close(); }
  /// The inner source's counters, with `frames` counting only the frames handed out here.
  FrameSourceStats Stats() const override;
  std::string Describe() const override;

  /// Every interface name seen so far (kept or skipped), sorted.
  const std::set<std::string>& interfaces_seen() const { return seen_; }
  int64_t frames_skipped() const { return skipped_; }

 private:
  FrameSource& inner_;
  std::string interface_;
  std::set<std::string> seen_;
  int64_t passed_ = 0, skipped_ = 0;
};

}  // namespace sedbridge::sensors

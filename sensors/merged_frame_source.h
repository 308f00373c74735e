#pragma once
// Several frame sources as one, in time order: each source's next frame waits in a slot,
// and Next hands out the earliest (a tie goes to the source listed first), as a
// `candump -l any` log of several buses interleaves them. For the simulated sensors of a
// hand (`sedbridge simulate` with `fingers:`): one simulated sensor per finger on its own
// bus and ids, read by the hand's one frame router as a recording of the hand would be.
// Sources that are not paced (a log at speed max, a simulation); each must hand out its own
// frames in time order.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sensors/frame_source.h"

namespace sedbridge::sensors {

class MergedFrameSource final : public FrameSource {
 public:
  /// Throws std::invalid_argument for no source or a null one.
  explicit MergedFrameSource(std::vector<std::unique_ptr<FrameSource>> sources);

  /// The earliest waiting frame (timeout_us is passed to each source that has none waiting).
  std::optional<Frame> Next(int64_t timeout_us) override;
  /// Every source done and no frame waiting.
  bool Done() const override;
  void Close() override;
  /// The sources' counters summed.
  FrameSourceStats Stats() const override;
  /// "merged: <first>; <second>; ..."
  std::string Describe() const override;

 private:
  std::vector<std::unique_ptr<FrameSource>> sources_;
  std::vector<std::optional<Frame>> waiting_;
  bool closed_ = false;
};

}  // namespace sedbridge::sensors

#pragma once
// Decoder and encoder of a sensor profile's frame layout. Both directions are driven by the
// same FrameLayout, so what the simulated sensor encodes is exactly what the decoder reads.

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "sensors/can_frame.h"
#include "sensors/sensor_profile.h"

namespace sedbridge::sensors {

/// Why a frame could not be decoded (kOk when it could).
enum class DecodeStatus {
  kOk,
  kUnknownId,       ///< id not in the profile (or wrong 11/29-bit kind)
  kWrongLength,     ///< payload length differs from the profile's
  kWrongFrameType,  ///< classic frame where FD is expected or vice versa
  kRemoteFrame,     ///< remote request, carries no data
  kErrorFrame,      ///< controller error frame
  kBadFrameIndex,   ///< frame_index field names a slot the profile does not have
};

const char* ToString(DecodeStatus status);

/// The samples of one frame.
struct DecodedFrame {
  static constexpr int kMaxSamples = kCanFdMaxLen * 8;
  int slot = -1;               ///< frame slot within the scan
  int64_t scan_counter = -1;   ///< value of the scan_counter field, -1 if the profile has none
  int first_channel = 0;       ///< channel of samples[0]
  int channel_count = 0;       ///< samples that are real channels (excludes padding)
  std::array<int32_t, kMaxSamples> samples;
};

class TaxelCodec {
 public:
  /// Keeps a copy of the layout; `profile` must pass ValidateProfile.
  explicit TaxelCodec(const SensorProfile& profile);

  /// Decodes `frame`; on kOk fills `out`. Never reads past frame.data.
  DecodeStatus Decode(const Frame& frame, DecodedFrame* out) const;

  /// Slot of a frame from its id alone (-1 if unknown); with frame_index it is the shared
  /// id's "slot unknown until the payload is read" marker 0.
  int SlotForId(uint32_t id, bool extended) const;

  /// Encodes one slot. `channels` holds all channel_count() raw readings of the scan;
  /// values outside the sample range are clamped (that is what a saturated ADC sends).
  /// `scan_counter` is written modulo 2^bits when the profile has a counter.
  Frame EncodeSlot(int slot, const std::vector<int32_t>& channels, int64_t scan_counter,
                   int64_t utime) const;
  /// All slots of one scan, in slot order, all stamped `utime`.
  std::vector<Frame> EncodeScan(const std::vector<int32_t>& channels, int64_t scan_counter,
                                int64_t utime) const;

  int frame_count() const { return layout_.frame_count; }
  int channel_count() const { return channel_count_; }
  const FrameLayout& layout() const { return layout_; }

  /// Bit-field access in the profile's numbering (exposed for tests and the fuzzer).
  static uint32_t ReadBits(const uint8_t* data, int first_bit, int bits, ByteOrder order);
  static void WriteBits(uint8_t* data, int first_bit, int bits, ByteOrder order, uint32_t value);

 private:
  FrameLayout layout_;
  int channel_count_ = 0;
  int64_t raw_min_ = 0, raw_max_ = 0;
  std::array<int16_t, kCanStdIdMask + 1> std_slots_;      // 11-bit id -> slot, -1 unknown
  std::unordered_map<uint32_t, int> ext_slots_;           // 29-bit id -> slot
};

}  // namespace sedbridge::sensors

#include "sensors/taxel_codec.h"

#include <algorithm>

namespace sedbridge::sensors {

const char* ToString(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::kOk: return "ok";
    case DecodeStatus::kUnknownId: return "unknown id";
    case DecodeStatus::kWrongLength: return "wrong length";
    case DecodeStatus::kWrongFrameType: return "wrong frame type (classic/FD)";
    case DecodeStatus::kRemoteFrame: return "remote frame";
    case DecodeStatus::kErrorFrame: return "error frame";
    case DecodeStatus::kBadFrameIndex: return "bad frame index";
  }
  return "?";
}

uint32_t TaxelCodec::ReadBits(const uint8_t* data, int first_bit, int bits, ByteOrder order) {
  // Gather the (at most 4) bytes covering the field into one word, then shift out the field.
  const int first_byte = first_bit / 8, last_byte = (first_bit + bits - 1) / 8;
  uint64_t acc = 0;
  if (order == ByteOrder::kBig) {
    for (int b = first_byte; b <= last_byte; ++b) acc = acc << 8 | data[b];
    const int shift = (last_byte + 1) * 8 - (first_bit + bits);
    acc >>= shift;
  } else {
    for (int b = last_byte; b >= first_byte; --b) acc = acc << 8 | data[b];
    acc >>= (first_bit % 8);
  }
  return static_cast<uint32_t>(acc & ((uint64_t{1} << bits) - 1));
}

void TaxelCodec::WriteBits(uint8_t* data, int first_bit, int bits, ByteOrder order, uint32_t value) {
  const uint64_t mask = (uint64_t{1} << bits) - 1;
  const int first_byte = first_bit / 8, last_byte = (first_bit + bits - 1) / 8;
  const int nbytes = last_byte - first_byte + 1;
  uint64_t acc = 0;
  int shift;
  if (order == ByteOrder::kBig) {
    for (int b = first_byte; b <= last_byte; ++b) acc = acc << 8 | data[b];
    shift = (last_byte + 1) * 8 - (first_bit + bits);
  } else {
    for (int b = last_byte; b >= first_byte; --b) acc = acc << 8 | data[b];
    shift = first_bit % 8;
  }
  acc = (acc & ~(mask << shift)) | ((value & mask) << shift);
  if (order == ByteOrder::kBig) {
    for (int i = nbytes - 1; i >= 0; --i, acc >>= 8) data[first_byte + i] = static_cast<uint8_t>(acc);
  } else {
    for (int i = 0; i < nbytes; ++i, acc >>= 8) data[first_byte + i] = static_cast<uint8_t>(acc);
  }
}

TaxelCodec::TaxelCodec(const SensorProfile& profile)
    : layout_(profile.layout),
      channel_count_(profile.channel_count()),
      raw_min_(profile.RawMin()),
      raw_max_(profile.RawMax()) {
  std_slots_.fill(-1);
  for (size_t k = 0; k < layout_.ids.size(); ++k) {
    const int slot = layout_.frame_index.present() ? 0 : static_cast<int>(k);
    if (layout_.extended_ids)
      ext_slots_[layout_.ids[k]] = slot;
    else
      std_slots_[layout_.ids[k] & kCanStdIdMask] = static_cast<int16_t>(slot);
  }
}

int TaxelCodec::SlotForId(uint32_t id, bool extended) const {
  if (extended != layout_.extended_ids) return -1;
  if (!extended) return id <= kCanStdIdMask ? std_slots_[id] : -1;
  auto it = ext_slots_.find(id);
  return it == ext_slots_.end() ? -1 : it->second;
}

DecodeStatus TaxelCodec::Decode(const Frame& f, DecodedFrame* out) const {
  if (f.error) return DecodeStatus::kErrorFrame;
  int slot = SlotForId(f.id, f.extended);
  if (slot < 0) return DecodeStatus::kUnknownId;
  if (f.remote) return DecodeStatus::kRemoteFrame;
  if (f.fd != layout_.fd) return DecodeStatus::kWrongFrameType;
  if (f.len != layout_.length) return DecodeStatus::kWrongLength;
  const uint8_t* d = f.data.data();
  if (layout_.frame_index.present()) {
    slot = static_cast<int>(ReadBits(d, layout_.frame_index.first_bit, layout_.frame_index.bits,
                                     layout_.byte_order));
    if (slot >= layout_.frame_count) return DecodeStatus::kBadFrameIndex;
  }
  out->slot = slot;
  out->scan_counter = layout_.scan_counter.present()
                          ? static_cast<int64_t>(ReadBits(d, layout_.scan_counter.first_bit,
                                                          layout_.scan_counter.bits, layout_.byte_order))
                          : int64_t{-1};
  out->first_channel = slot * layout_.samples_per_frame;
  out->channel_count = std::min(layout_.samples_per_frame, channel_count_ - out->first_channel);
  const int bits = layout_.sample_bits;
  const uint32_t sign_bit = uint32_t{1} << (bits - 1);
  for (int j = 0; j < out->channel_count; ++j) {
    uint32_t v = ReadBits(d, layout_.first_sample_bit + j * bits, bits, layout_.byte_order);
    // Sign-extend two's complement samples.
    out->samples[j] = layout_.sample_signed
                          ? static_cast<int32_t>(v ^ sign_bit) - static_cast<int32_t>(sign_bit)
                          : static_cast<int32_t>(v);
  }
  return DecodeStatus::kOk;
}

Frame TaxelCodec::EncodeSlot(int slot, const std::vector<int32_t>& channels, int64_t scan_counter,
                             int64_t utime) const {
  Frame f;
  f.id = layout_.frame_index.present() ? layout_.ids[0] : layout_.ids[slot];
  f.extended = layout_.extended_ids;
  f.fd = layout_.fd;
  f.fd_flags = layout_.fd ? layout_.fd_flags : 0;
  f.len = static_cast<uint8_t>(layout_.length);
  f.utime = utime;
  uint8_t* d = f.data.data();
  if (layout_.frame_index.present())
    WriteBits(d, layout_.frame_index.first_bit, layout_.frame_index.bits, layout_.byte_order,
              static_cast<uint32_t>(slot));
  if (layout_.scan_counter.present())
    WriteBits(d, layout_.scan_counter.first_bit, layout_.scan_counter.bits, layout_.byte_order,
              static_cast<uint32_t>(scan_counter));
  const int bits = layout_.sample_bits;
  for (int j = 0; j < layout_.samples_per_frame; ++j) {
    const int ch = slot * layout_.samples_per_frame + j;
    int64_t v = ch < channel_count_ && ch < static_cast<int>(channels.size()) ? channels[ch] : 0;
    v = std::clamp<int64_t>(v, raw_min_, raw_max_);
    WriteBits(d, layout_.first_sample_bit + j * bits, bits, layout_.byte_order,
              static_cast<uint32_t>(v));
  }
  return f;
}

std::vector<Frame> TaxelCodec::EncodeScan(const std::vector<int32_t>& channels,
                                          int64_t scan_counter, int64_t utime) const {
  std::vector<Frame> frames;
  frames.reserve(layout_.frame_count);
  for (int k = 0; k < layout_.frame_count; ++k)
    frames.push_back(EncodeSlot(k, channels, scan_counter, utime));
  return frames;
}

}  // namespace sedbridge::sensors

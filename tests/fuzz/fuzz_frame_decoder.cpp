// Fuzzes the frame decoder and scan assembler (and the SocketCAN datagram conversion). The first byte picks a shipped profile or a
// layout built from the input itself; the rest is a stream of frames (id, flags, length,
// payload) pushed through the assembler. Checked: no crash/UB, decoded samples in range,
// encode(decode(frame)) reproduces the decoded samples, scans have consistent sizes and
// finite values.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <stdexcept>
#include <vector>

#include "sensors/scan_assembler.h"
#include "sensors/socketcan_source.h"

using namespace sedbridge::sensors;

namespace {

const std::vector<SensorProfile>& Shipped() {
  static const std::vector<SensorProfile> profiles = [] {
    std::vector<SensorProfile> v;
    for (const char* name : {"uskin_4x4", "cyskin_16", "barrett_bh8_pad"})
      v.push_back(LoadSensorProfile(ResolveProfilePath(name)));
    return v;
  }();
  return profiles;
}

struct Reader {
  const uint8_t* p;
  size_t n;
  bool Empty() const { return n == 0; }
  uint8_t U8() {
    if (!n) return 0;
    --n;
    return *p++;
  }
  uint32_t U32() { return U8() | U8() << 8 | U8() << 16 | static_cast<uint32_t>(U8()) << 24; }
};

// A layout from fuzz bytes; nullptr if the profile checks reject it.
std::unique_ptr<SensorProfile> LayoutFromBytes(Reader& in) {
  auto p = std::make_unique<SensorProfile>(Shipped()[1]);  // cyskin_16 as the template
  FrameLayout& l = p->layout;
  p->axes = in.U8() % 2 ? 3 : 1;
  p->taxel_count = 1 + in.U8() % 24;
  p->taxels.assign(p->taxel_count, {});
  l.fd = in.U8() % 4 == 0;
  l.length = 1 + in.U8() % (l.fd ? 64 : 8);
  l.sample_bits = 1 + in.U8() % 24;
  l.sample_signed = in.U8() % 2;
  l.byte_order = in.U8() % 2 ? ByteOrder::kBig : ByteOrder::kLittle;
  l.first_sample_bit = in.U8() % 16;
  l.samples_per_frame = 1 + in.U8() % 16;
  l.frame_count = (p->channel_count() + l.samples_per_frame - 1) / l.samples_per_frame;
  l.frame_index = {};
  l.scan_counter = {};
  if (in.U8() % 2) l.scan_counter = {in.U8() % 64, 1 + in.U8() % 8};
  l.ids.clear();
  for (int k = 0; k < l.frame_count; ++k) l.ids.push_back(0x100 + static_cast<uint32_t>(k));
  p->calibration.scale_per_count.assign(p->axes, 0.01);
  p->calibration.offset_counts.assign(p->axes, 0);
  p->calibration.taxel_gain.assign(p->taxel_count, 1.0);
  p->calibration.saturation_low_counts = p->RawMin() - 1;
  p->calibration.saturation_high_counts = p->RawMax();
  try {
    ValidateProfile(*p);
  } catch (const std::invalid_argument&) {
    return nullptr;
  }
  return p;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // The whole input as a kernel datagram (what SocketCanSource reads).
  Frame kernel;
  if (FrameFromKernel(data, size, &kernel)) {
    if (!IsWellFormed(kernel)) std::abort();
    unsigned char back[72];
    Frame again;
    if (!FrameFromKernel(back, FrameToKernel(kernel, back), &again) || !again.SamePayload(kernel)) std::abort();
  }
  Reader in{data, size};
  const uint8_t choice = in.U8();
  std::unique_ptr<SensorProfile> own;
  const SensorProfile* profile;
  if (choice % 4 < 3) {
    profile = &Shipped()[choice % 4];
  } else {
    own = LayoutFromBytes(in);
    if (!own) return 0;
    profile = own.get();
  }
  const TaxelCodec codec(*profile);
  AssemblerOptions options;
  options.tare_scans = in.U8() % 3;
  ScanAssembler assembler(*profile, options);
  std::vector<Scan> scans;
  int64_t utime = 0;
  while (!in.Empty()) {
    Frame f;
    const uint8_t flags = in.U8();
    // Mostly the profile's own ids, so the decoder is exercised, sometimes anything.
    const auto& ids = profile->layout.ids;
    f.id = flags & 0x80 ? in.U32() & kCanExtIdMask : ids[in.U8() % ids.size()];
    f.extended = (flags & 0x01) ? !profile->layout.extended_ids : profile->layout.extended_ids;
    if (!f.extended) f.id &= kCanStdIdMask;
    f.remote = flags & 0x02;
    f.error = flags & 0x04;
    f.fd = (flags & 0x08) ? !profile->layout.fd : profile->layout.fd;
    f.len = flags & 0x10 ? in.U8() % 65 : static_cast<uint8_t>(profile->layout.length);
    for (int i = 0; i < f.len; ++i) f.data[i] = in.U8();
    utime += in.U8() * 37;
    f.utime = utime;

    DecodedFrame d;
    if (codec.Decode(f, &d) == DecodeStatus::kOk) {
      if (d.slot < 0 || d.slot >= codec.frame_count() || d.channel_count < 1 ||
          d.first_channel + d.channel_count > profile->channel_count())
        std::abort();
      std::vector<int32_t> channels(profile->channel_count(), 0);
      for (int j = 0; j < d.channel_count; ++j) {
        if (d.samples[j] < profile->RawMin() || d.samples[j] > profile->RawMax()) std::abort();
        channels[d.first_channel + j] = d.samples[j];
      }
      const Frame again = codec.EncodeSlot(d.slot, channels, d.scan_counter < 0 ? 0 : d.scan_counter, f.utime);
      DecodedFrame d2;
      if (codec.Decode(again, &d2) != DecodeStatus::kOk || d2.slot != d.slot || d2.scan_counter != d.scan_counter)
        std::abort();
      for (int j = 0; j < d.channel_count; ++j)
        if (d2.samples[j] != d.samples[j]) std::abort();
    }
    assembler.Push(f, &scans);
    if (flags & 0x20) assembler.Poll(utime + 100000, &scans);
    if (flags & 0x40 && !(flags & 0x80)) assembler.RequestTare(1);
  }
  assembler.Flush(&scans);
  for (const Scan& s : scans) {
    if (static_cast<int>(s.pressure_Pa.size()) != profile->taxel_count ||
        static_cast<int>(s.raw_counts.size()) != profile->channel_count() ||
        static_cast<int>(s.valid.size()) != profile->taxel_count)
      std::abort();
    for (double v : s.pressure_Pa)
      if (!std::isfinite(v)) std::abort();
  }
  const BadFrameCounters& c = assembler.counters();
  if (c.frames_used + c.rejected() > c.frames) std::abort();
  return 0;
}

#include "lcm/lcm_safe_decode.h"

#include <cstring>
#include <limits>
#include <vector>

#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_contact_estimate.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_display_rendering.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"
#include "sedbridge/lcmt_tactile_scan.hpp"

namespace sedbridge::lcm_io {
namespace {

// Reads the LCM wire format forward without allocating; any shortfall latches !ok().
class WireCursor {
 public:
  WireCursor(const void* data, std::size_t size) : p_(static_cast<const uint8_t*>(data)), left_(size) {}

  void Skip(std::size_t n) {
    if (!ok_ || n > left_) {
      ok_ = false;
      return;
    }
    p_ += n;
    left_ -= n;
  }
  int32_t Int32() {
    if (!ok_ || left_ < 4) {
      ok_ = false;
      return 0;
    }
    const uint32_t v = (uint32_t(p_[0]) << 24) | (uint32_t(p_[1]) << 16) | (uint32_t(p_[2]) << 8) | uint32_t(p_[3]);
    Skip(4);
    return static_cast<int32_t>(v);
  }
  int8_t Int8() {
    if (!ok_ || left_ < 1) {
      ok_ = false;
      return 0;
    }
    const int8_t v = static_cast<int8_t>(p_[0]);
    Skip(1);
    return v;
  }
  // int32 length including the terminating NUL, then the bytes.
  void String() {
    const int32_t n = Int32();
    if (n < 1) ok_ = false;
    // Exactly one NUL, at the end: an embedded one would make "suction_4x4\0x" a different
    // string that prints like the real one (and does not re-encode to the same bytes).
    if (ok_ && std::size_t(n) <= left_ && (p_[n - 1] != 0 || std::memchr(p_, 0, std::size_t(n - 1)) != nullptr))
      ok_ = false;
    if (ok_) Skip(std::size_t(n));
  }
  // `count` elements of `element_bytes` each; the product is checked before it is formed.
  void Array(int32_t count, std::size_t element_bytes) {
    if (count < 0) ok_ = false;
    if (!ok_) return;
    if (std::size_t(count) > left_ / element_bytes) {
      ok_ = false;
      return;
    }
    Skip(std::size_t(count) * element_bytes);
  }
  bool ok() const { return ok_; }
  bool at_end() const { return ok_ && left_ == 0; }

 private:
  const uint8_t* p_;
  std::size_t left_;
  bool ok_ = true;
};

constexpr std::size_t kFingerprint = 8, kI64 = 8, kI32 = 4, kF32 = 4, kByte = 1;

// One walker per type, field by field in .lcm order (lcmtypes/*.lcm). A change to a .lcm
// file must change its walker; lcmtypes_test round-trips every type through both.
bool Walk(const lcmt_display_command*, WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(4 * kI64);  // utime, sequence, source_scan_utime, source_sed_utime
  c.String();        // display_id
  c.String();        // unit
  const int32_t n = c.Int32();
  c.Array(n, kF32);  // value
  c.Skip(4 * kByte); // clamped, stale, fault, shutdown
  return c.at_end();
}

bool Walk(const lcmt_merkel_sed*, WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(2 * kI64);  // utime, source_scan_utime
  c.String();        // model_id
  const int32_t vertices = c.Int32();
  const int32_t positions = c.Int32();
  for (int k = 0; k < 3; ++k) c.Array(positions, kF32);  // x_mm, y_mm, z_mm
  const int32_t ids = c.Int32();
  c.Array(ids, kI32);       // vertex_id
  c.Array(vertices, kF32);  // sed_Pa
  c.Skip(kF32);             // max_sed_Pa
  return c.at_end();
}

// The scan's fields up to `valid` (all a message from before the shear fields has).
void WalkScanNormal(WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(2 * kI64);  // utime, sequence
  c.String();        // sensor_id
  const int32_t n = c.Int32();
  c.Array(n, kI32);   // raw_counts
  c.Array(n, kF32);   // pressure_kPa
  c.Array(n, kByte);  // valid
}

bool Walk(const lcmt_tactile_scan*, WireCursor& c) {
  WalkScanNormal(c);
  const int32_t shear = c.Int32();  // num_shear
  c.Array(shear, kF32);  // shear_x_kPa
  c.Array(shear, kF32);  // shear_y_kPa
  return c.at_end();
}

// A message of a type's earlier version, rewritten as the current one, for the types whose
// fields have grown at the end: false when `data` is not such a message.
template <typename Msg>
bool Upgrade(const Msg*, const uint8_t*, std::size_t, std::vector<uint8_t>*) {
  return false;
}

// lcmt_tactile_scan before num_shear, shear_x_kPa, shear_y_kPa: its fingerprint, then the
// same fields up to `valid`. Rewritten with today's fingerprint and num_shear = 0.
constexpr uint8_t kScanWithoutShear[kFingerprint] = {0x3a, 0xfe, 0x5a, 0x31, 0xff, 0x1b, 0xfe, 0x44};

bool Upgrade(const lcmt_tactile_scan*, const uint8_t* data, std::size_t size, std::vector<uint8_t>* upgraded) {
  if (size < kFingerprint || std::memcmp(data, kScanWithoutShear, kFingerprint) != 0) return false;
  WireCursor c(data, size);
  WalkScanNormal(c);
  if (!c.at_end()) return false;
  const int64_t hash = lcmt_tactile_scan::getHash();
  upgraded->assign(data, data + size);
  for (std::size_t k = 0; k < kFingerprint; ++k) (*upgraded)[k] = uint8_t(uint64_t(hash) >> (56 - 8 * k));
  upgraded->insert(upgraded->end(), 4, uint8_t(0));  // num_shear = 0
  return true;
}

bool Walk(const lcmt_bridge_status*, WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(kI64);      // utime
  c.Skip(7 * kF32);  // rates and latencies
  c.Skip(kI32);      // solver_iterations
  c.Skip(kF32);      // solver_residual
  c.Skip(5 * kI64);  // scans_received, scans_dropped, bad_frames_*
  const int8_t reasons = c.Int8();  // num_reject_reasons
  if (reasons < 0) return false;
  for (int k = 0; k < reasons && c.ok(); ++k) c.String();  // reject_reason
  c.Array(reasons, kI64);  // scans_rejected
  c.Skip(3 * kI64);  // commands_clamped, commands_stale, commands_fault
  c.Skip(kByte);     // fault_state
  c.String();        // fault_message
  c.Skip(9 * kF32);  // per-stage medians
  const int32_t taxels = c.Int32();  // num_taxels
  c.Array(taxels, kByte);  // taxel_health
  c.Skip(4 * kI32);  // taxels_stuck, taxels_dead, taxels_frozen, taxels_drifting
  c.Skip(4 * kI64);  // taxel_scans_left_out, taxels_masked_total, taxels_recovered, taxel_retares
  c.Skip(kI64);      // model_inadequate_scans
  return c.at_end();
}

bool Walk(const lcmt_sa1_rate_estimate*, WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(kI64);  // utime
  c.String();    // display_id
  const int32_t n = c.Int32();
  c.Array(n, kF32);  // sed_Pa
  c.Array(n, kF32);  // rate_Hz
  return c.at_end();
}

bool Walk(const lcmt_contact_estimate*, WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(2 * kI64);   // utime, source_scan_utime
  c.Skip(kByte);      // shape
  c.Skip(12 * kF32);  // x_mm .. normal_force2_N
  c.Skip(kF32);       // residual_rms_sigma
  c.Skip(kByte);      // fallback
  c.Skip(kF32);       // indentation_mm
  const int32_t n = c.Int32();
  c.Array(n, kByte);  // taxel_used
  c.Skip(kI32);       // num_taxels_used
  c.Skip(kByte);      // model_inadequate
  c.Skip(kF32);       // width_mm
  return c.at_end();
}

bool Walk(const lcmt_display_rendering*, WireCursor& c) {
  c.Skip(kFingerprint);
  c.Skip(3 * kI64);  // utime, command_sequence, source_scan_utime
  c.String();        // display_id
  c.String();        // model_id
  const int32_t n = c.Int32();
  c.Array(n, kF32);  // target_sed_Pa
  c.Array(n, kF32);  // delivered_sed_Pa
  c.Skip(2 * kF32);  // max_target_sed_Pa, max_delivered_sed_Pa
  c.Skip(kByte);     // limited
  return c.at_end();
}

}  // namespace

template <typename Msg>
bool WireSizesFit(const void* data, std::size_t size) {
  if (data == nullptr) return false;
  WireCursor c(data, size);
  return Walk(static_cast<const Msg*>(nullptr), c);
}

template <typename Msg>
bool SafeDecode(const void* data, std::size_t size, Msg* out) {
  if (size > std::size_t(std::numeric_limits<int>::max()) - 64) return false;  // decode() takes int
  std::vector<uint8_t> upgraded;
  if (data != nullptr && Upgrade(static_cast<const Msg*>(nullptr), static_cast<const uint8_t*>(data), size, &upgraded)) {
    data = upgraded.data();
    size = upgraded.size();
  }
  if (!WireSizesFit<Msg>(data, size)) return false;
  try {
    return out->decode(data, 0, static_cast<int>(size)) == static_cast<int>(size);
  } catch (...) {
    return false;  // bad_alloc cannot happen after the walk; keep the promise regardless
  }
}

#define SEDBRIDGE_SAFE_DECODE(T)                                          \
  template bool WireSizesFit<T>(const void*, std::size_t);               \
  template bool SafeDecode<T>(const void*, std::size_t, T*);
SEDBRIDGE_SAFE_DECODE(lcmt_display_command)
SEDBRIDGE_SAFE_DECODE(lcmt_merkel_sed)
SEDBRIDGE_SAFE_DECODE(lcmt_tactile_scan)
SEDBRIDGE_SAFE_DECODE(lcmt_bridge_status)
SEDBRIDGE_SAFE_DECODE(lcmt_sa1_rate_estimate)
SEDBRIDGE_SAFE_DECODE(lcmt_contact_estimate)
SEDBRIDGE_SAFE_DECODE(lcmt_display_rendering)
#undef SEDBRIDGE_SAFE_DECODE

}  // namespace sedbridge::lcm_io

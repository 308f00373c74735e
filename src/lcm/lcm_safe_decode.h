#pragma once
// Decoding LCM messages from untrusted bytes without unbounded allocation.
//
// lcm-gen's decode() sizes each array from its count field before it checks the buffer, so one
// 160-byte DISPLAY_COMMAND with num_actuators = 1e9 makes it allocate 4 GB. SafeDecode first
// walks the wire format (LCM: big-endian, 8-byte type fingerprint, strings as int32 length
// including the NUL) and checks every count against the bytes that remain: negative counts,
// counts whose elements do not fit, and trailing bytes are rejected before anything is
// allocated. Every reader of untrusted LCM bytes (display-view, the log reader, the
// display driver) goes through it.

#include <cstddef>
#include <cstdint>

namespace sedbridge::lcm_io {

/// Decodes `size` bytes at `data` into `out` only when the whole buffer is exactly one
/// well-formed Msg: fingerprint right, every array count >= 0 and backed by bytes, every
/// string NUL-terminated with no NUL inside, no trailing bytes. Returns false otherwise (then `out` is unspecified but holds at most
/// `size` elements in all). Never throws, never allocates more than O(size).
/// Defined for lcmt_display_command, lcmt_merkel_sed, lcmt_tactile_scan,
/// lcmt_bridge_status, lcmt_sa1_rate_estimate, lcmt_contact_estimate and
/// lcmt_display_rendering. A tactile scan from
/// before its shear fields (the old fingerprint, the fields up to `valid`) decodes too, with
/// num_shear 0: old logs stay readable.
template <typename Msg>
bool SafeDecode(const void* data, std::size_t size, Msg* out);

/// The structural check alone (no decode): true when the counts in `size` bytes fit, as
/// above. Exposed for tests and fuzzing.
template <typename Msg>
bool WireSizesFit(const void* data, std::size_t size);

}  // namespace sedbridge::lcm_io

// Fuzzes SafeDecode for every lcmt type: any bytes either decode into a message whose arrays
// match their counts and fit in the input, or are refused — never an allocation larger than
// the input (ASan's allocation limit, -rss_limit_mb and -malloc_limit_mb catch that), no
// crash, no UB. A message that decodes must re-encode to the same bytes.
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "lcm/lcm_safe_decode.h"
#include "sedbridge/lcmt_bridge_status.hpp"
#include "sedbridge/lcmt_display_command.hpp"
#include "sedbridge/lcmt_merkel_sed.hpp"
#include "sedbridge/lcmt_sa1_rate_estimate.hpp"
#include "sedbridge/lcmt_tactile_scan.hpp"

using namespace sedbridge;

namespace {

template <typename Msg>
void Roundtrip(const Msg& m, const uint8_t* data, size_t size) {
  const int n = m.getEncodedSize();
  if (n < 0 || size_t(n) != size) std::abort();
  std::vector<uint8_t> b(size);
  if (m.encode(b.data(), 0, n) != n) std::abort();
  for (size_t i = 0; i < size; ++i)
    if (b[i] != data[i]) std::abort();
}

template <typename Msg, typename Check>
void Try(const uint8_t* data, size_t size, Check check) {
  Msg m;
  if (!lcm_io::SafeDecode(data, size, &m)) return;
  check(m);
  Roundtrip(m, data, size);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* raw, size_t size) {
  if (size < 1) return 0;
  // First byte: which type; the rest gets that type's fingerprint in front, so the fuzzer
  // explores the fields instead of guessing 8 hash bytes.
  const int kind = raw[0] % 5;
  std::vector<uint8_t> buf(8 + size - 1);
  int64_t hash = 0;
  switch (kind) {
    case 0: hash = lcmt_display_command::getHash(); break;
    case 1: hash = lcmt_merkel_sed::getHash(); break;
    case 2: hash = lcmt_tactile_scan::getHash(); break;
    case 3: hash = lcmt_bridge_status::getHash(); break;
    case 4: hash = lcmt_sa1_rate_estimate::getHash(); break;
  }
  for (int i = 0; i < 8; ++i) buf[size_t(i)] = uint8_t(uint64_t(hash) >> (56 - 8 * i));
  std::copy(raw + 1, raw + size, buf.begin() + 8);
  const uint8_t* data = buf.data();
  const size_t n = buf.size();
  switch (kind) {
    case 0:
      Try<lcmt_display_command>(data, n, [&](const lcmt_display_command& m) {
        if (m.num_actuators < 0 || m.value.size() != size_t(m.num_actuators) || m.value.size() * 4 > n) std::abort();
      });
      break;
    case 1:
      Try<lcmt_merkel_sed>(data, n, [&](const lcmt_merkel_sed& m) {
        if (m.sed_Pa.size() != size_t(m.num_vertices) || m.x_mm.size() != size_t(m.num_positions) ||
            m.vertex_id.size() != size_t(m.num_ids) || (m.sed_Pa.size() + 3 * m.x_mm.size()) * 4 > n)
          std::abort();
      });
      break;
    case 2:
      Try<lcmt_tactile_scan>(data, n, [&](const lcmt_tactile_scan& m) {
        if (m.valid.size() != size_t(m.num_taxels) || m.valid.size() * 9 > n) std::abort();
        if (m.shear_x_kPa.size() != size_t(m.num_shear) || m.shear_y_kPa.size() != size_t(m.num_shear) ||
            m.shear_x_kPa.size() * 8 > n)
          std::abort();
      });
      break;
    case 3:
      Try<lcmt_bridge_status>(data, n, [&](const lcmt_bridge_status& m) {
        if (m.fault_message.size() > n || m.taxel_health.size() != size_t(m.num_taxels) || m.taxel_health.size() > n)
          std::abort();
      });
      break;
    case 4:
      Try<lcmt_sa1_rate_estimate>(data, n, [&](const lcmt_sa1_rate_estimate& m) {
        if (m.rate_Hz.size() != size_t(m.num_sites) || m.rate_Hz.size() * 8 > n) std::abort();
      });
      break;
  }
  return 0;
}

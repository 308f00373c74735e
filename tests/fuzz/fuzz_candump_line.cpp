// Fuzzes the candump line parser and writer: any input must parse without crashing or UB,
// and a line that parses must survive format -> parse unchanged.
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "sensors/candump_log.h"

using namespace sedbridge::sensors;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  Frame f;
  const LineResult r = ParseCandumpLine(line, &f);
  if (r.kind == LineKind::kBad && r.error == nullptr) std::abort();  // bad lines say why
  if (r.kind != LineKind::kFrame) return 0;
  if (!IsWellFormed(f)) std::abort();
  const std::string written = FormatCandumpLine(f);
  Frame g;
  if (ParseCandumpLine(written, &g).kind != LineKind::kFrame) std::abort();
  if (!g.SamePayload(f) || g.utime != f.utime || g.Interface() != f.Interface()) std::abort();
  return 0;
}

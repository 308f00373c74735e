// Property fuzzing of the safety limiter and the display driver on random command streams:
// the bytes choose the limits, then a stream of operations (fresh or repeated requests with
// NaN/Inf/huge/negative values or wrong lengths, ticks after any gap, long silences,
// signed/forged/replayed/malformed messages to the driver). Every output must be
//   - finite, >= 0, <= max[i], and 0 or >= min_nonzero;
//   - rise at most slew * min(dt, kMaxRiseInterval_s) + min_nonzero per output;
//   - fall at most slew * dt unless it drops to zero (the safe direction);
//   - zero after silence of timeout + max / slew;
// and a forged or replayed message is never accepted by the driver. Aborts otherwise.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "display/command_authenticator.h"
#include "display/display_driver.h"
#include "display/safety_limiter.h"
#include "lcm/display_command_message.h"
#include "lcm/merkel_sed_message.h"
#include "sedbridge/lcmt_display_command.hpp"

using namespace sedbridge::display;
using namespace sedbridge::lcm_io;
using sedbridge::lcmt_display_command;

namespace {

class Bytes {
 public:
  Bytes(const uint8_t* d, size_t n) : d_(d), n_(n) {}
  bool done() const { return i_ >= n_; }
  uint8_t U8() { return i_ < n_ ? d_[i_++] : 0; }
  uint32_t U32() {
    uint32_t v = 0;
    for (int k = 0; k < 4; ++k) v = (v << 8) | U8();
    return v;
  }
  double Unit() { return U32() / 4294967295.0; }  // [0, 1]

 private:
  const uint8_t* d_;
  size_t n_, i_ = 0;
};

double Value(Bytes& b, double max) {
  switch (b.U8() % 10) {
    case 0: return std::numeric_limits<double>::quiet_NaN();
    case 1: return std::numeric_limits<double>::infinity() * (b.U8() % 2 ? 1 : -1);
    case 2: return 1e300;
    case 3: return -b.Unit() * 1e6;
    case 4: return max * (1 + 10 * b.Unit());
    default: return max * b.Unit();
  }
}

struct Checker {
  SafetyLimits limits;
  bool check_falls = true;  // false for the driver: its frames skip the limiter's outputs at
                            // message times (see the rise and fall checks)
  std::vector<double> prev;
  int64_t prev_t = 0;
  bool have = false;
  void Check(const std::vector<double>& y, int64_t t, bool zero_allowed_drop) {
    if (y.size() != limits.max.size()) std::abort();
    const double dt = have ? std::max<int64_t>(0, t - prev_t) * 1e-6 : 0;
    for (size_t i = 0; i < y.size(); ++i) {
      if (!std::isfinite(y[i]) || y[i] < 0 || y[i] > limits.max[i]) std::abort();
      if (y[i] != 0 && y[i] < limits.min_nonzero) std::abort();
      if (!have) {
        if (y[i] != 0) std::abort();
        continue;
      }
      const double tol = 1e-9 * (1 + limits.max[i]);
      const double step = y[i] - prev[i];
      // Per limiter output the rise uses at most kMaxRiseInterval_s; between two driver
      // frames the limiter may have emitted several times (at messages), so there only the
      // total, slew * dt, holds.
      const double rise_s = check_falls ? std::min({dt, limits.watchdog_timeout_s, kMaxRiseInterval_s}) : dt;
      if (step > limits.slew_rate_per_s * rise_s + limits.min_nonzero + tol)
        std::abort();
      if (check_falls && !(y[i] == 0 && zero_allowed_drop) && step < -limits.slew_rate_per_s * dt - tol)
        std::abort();
    }
    prev = y;
    prev_t = std::max(prev_t, t);
    have = true;
  }
  int64_t ToZero_us() const {
    const double m = *std::max_element(limits.max.begin(), limits.max.end());
    return int64_t(std::ceil((limits.watchdog_timeout_s + m / limits.slew_rate_per_s) * 1e6));
  }
};

// Collects the driver's frames.
struct Capture : ActuatorOutput {
  std::vector<ActuatorFrame>* frames;
  explicit Capture(std::vector<ActuatorFrame>* f) : frames(f) {}
  bool Write(const ActuatorFrame& f) override {
    frames->push_back(f);
    return true;
  }
  std::string Describe() const override { return "capture"; }
};

void FuzzLimiter(Bytes& b) {
  SafetyLimits l;
  const int n = 1 + b.U8() % 8;
  for (int i = 0; i < n; ++i) l.max.push_back(0.01 + 100 * b.Unit());
  // Full scale in 1 ms .. 2 s: slower ramps only make silences (ticked below) longer to run.
  l.slew_rate_per_s = *std::max_element(l.max.begin(), l.max.end()) * (0.5 + 1000 * b.Unit());
  l.watchdog_timeout_s = 0.001 + (kMaxWatchdogTimeout_s - 0.001) * b.Unit();
  if (b.U8() % 2) l.min_nonzero = 0.5 * b.Unit() * *std::min_element(l.max.begin(), l.max.end());
  SafetyLimiter lim(l);
  Checker c{l, true, {}, 0, false};
  int64_t t = 0, stamp = 0;
  while (!b.done()) {
    const uint8_t op = b.U8();
    t += int64_t(b.U8()) * (op & 0x80 ? 20000 : 200);  // gaps up to ~5 s
    switch (op % 4) {
      case 0:
      case 1: {
        std::vector<double> r;
        const int len = b.U8() % 16 == 0 ? n + 1 : n;
        for (int i = 0; i < len; ++i) r.push_back(Value(b, l.max[size_t(i % n)]));
        const int64_t s = b.U8() % 8 == 0 ? stamp - 1 : ++stamp;
        const LimitedOutput& y = lim.Apply(t, s, r);
        c.Check(y.value, t, y.fault || l.min_nonzero > 0);
        break;
      }
      case 2: {
        const LimitedOutput& y = lim.Tick(t);
        c.Check(y.value, t, y.fault || l.min_nonzero > 0);
        break;
      }
      case 3: {  // silence, ticked: must end at zero
        const int64_t period = 2000 + int64_t(b.U8()) * 100;
        const int64_t until = t + c.ToZero_us() + period;
        for (; t < until; t += period) {
          const LimitedOutput& y = lim.Tick(t);
          c.Check(y.value, t, y.fault || l.min_nonzero > 0);
        }
        const LimitedOutput& y = lim.Tick(t);
        c.Check(y.value, t, true);
        for (double v : y.value)
          if (v != 0) std::abort();
        break;
      }
    }
  }
  const LimitedOutput& y = lim.Shutdown(t);
  for (double v : y.value)
    if (v != 0) std::abort();
}

std::vector<uint8_t> Encode(const lcmt_display_command& m) {
  std::vector<uint8_t> out(size_t(m.getEncodedSize()));
  m.encode(out.data(), 0, int(out.size()));
  return out;
}

void FuzzDriver(Bytes& b) {
  DisplayProfile p;
  p.name = "fuzz";
  p.unit = "kPa";
  p.kind = DisplayKind::kSuction;
  const int n = 1 + b.U8() % 8;
  p.x_mm.assign(size_t(n), 0.0);
  p.y_mm.assign(size_t(n), 0.0);
  p.range_min = b.U8() % 2 ? 0.0 : 1.0;
  p.range_max = 100;
  p.safety.max = 2 + 50 * b.Unit();
  p.safety.max_per_actuator.assign(size_t(n), p.safety.max);
  p.safety.slew_rate_per_s = p.safety.max * (0.5 + 100 * b.Unit());
  p.safety.watchdog_timeout_s = 0.01 + 0.99 * b.Unit();
  auto auth = std::make_shared<CommandAuthenticator>(std::vector<uint8_t>(32, 0x5a));
  const CommandAuthenticator attacker(std::vector<uint8_t>(32, 0xa5));
  std::vector<ActuatorFrame> frames;
  DisplayDriver driver(p, std::make_unique<Capture>(&frames), DecodeDisplayCommand, auth);
  // Falls are not checked here: a NaN message between two ticks drops the output to zero at
  // once (with the fault flag) and the next good one clears the flag before the tick sees it.
  int64_t t = 1'700'000'000'000'000, utime = t;
  // The driver starts at rest at `t`; its first frame may follow messages already ramping.
  Checker c{SafetyLimits::FromProfile(p), false, std::vector<double>(size_t(n), 0.0), t, true};
  int64_t sequence = 0;
  std::vector<std::vector<uint8_t>> sent;
  while (!b.done()) {
    const uint8_t op = b.U8();
    t += int64_t(b.U8()) * (op & 0x80 ? 20000 : 200);
    lcmt_display_command m{};
    m.utime = ++utime;
    m.sequence = ++sequence;
    m.display_id = b.U8() % 16 ? p.name : "other";
    m.unit = p.unit;
    m.num_actuators = n;
    for (int i = 0; i < n; ++i) m.value.push_back(float(Value(b, p.safety.max)));
    const std::vector<uint8_t> plain = Encode(m);
    const int64_t accepted_before = driver.counters().accepted;
    switch (op % 6) {
      case 0:
      case 1: {  // genuine
        std::vector<uint8_t> s = auth->Sign(plain.data(), plain.size());
        driver.OnMessage(s.data(), s.size(), t);
        sent.push_back(std::move(s));
        break;
      }
      case 2: {  // unsigned, wrong key, or bit-flipped: never accepted
        std::vector<uint8_t> s = b.U8() % 2 ? attacker.Sign(plain.data(), plain.size()) : plain;
        if (!s.empty() && b.U8() % 2) s[b.U8() % s.size()] ^= uint8_t(1 + b.U8() % 255);
        if (driver.OnMessage(s.data(), s.size(), t) && s != auth->Sign(plain.data(), plain.size())) std::abort();
        if (driver.counters().accepted != accepted_before && s.size() == plain.size()) std::abort();
        break;
      }
      case 3:  // replay of an earlier genuine message: never accepted
        if (!sent.empty()) {
          const auto& old = sent[b.U8() % sent.size()];
          if (driver.OnMessage(old.data(), old.size(), t)) std::abort();
        }
        break;
      default: {
        const ActuatorFrame& f = driver.Tick(t);
        c.Check(f.value, t, f.fault || p.range_min > 0);
        break;
      }
    }
  }
  const ActuatorFrame& f = driver.Shutdown(t);
  for (double v : f.value)
    if (v != 0) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 2 || size > 4096) return 0;
  Bytes b(data + 1, size - 1);
  if (data[0] % 2)
    FuzzLimiter(b);
  else
    FuzzDriver(b);
  return 0;
}

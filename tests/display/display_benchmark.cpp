// Speed of the display stage per FE step (prints numbers; nothing is asserted).
//   build-display/tests/display/display_benchmark

#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "display/display_controller.h"
#include "lcm/display_command_message.h"
#include "lcm/lcm_publisher.h"

namespace sedbridge::display {
using namespace sedbridge::lcm_io;  // LCM messages in and out
namespace {

// A Merkel-layer-like field: `n` vertices on a 16 mm x 16 mm patch 1.5 mm under the pad.
SedField Field(int n, int64_t utime) {
  SedField f;
  f.utime = utime;
  const int side = static_cast<int>(std::sqrt(n));
  for (int i = 0; i < side; ++i)
    for (int j = 0; j < side; ++j) {
      const double x = -8 + 16.0 * i / (side - 1), y = -8 + 16.0 * j / (side - 1);
      f.x_mm.push_back(x);
      f.y_mm.push_back(y);
      f.z_mm.push_back(-1.5);
      f.sed_Pa.push_back(3000 * std::exp(-(x * x + y * y) / 8));
    }
  return f;
}

void BM_MapAndLimit(benchmark::State& state, const char* profile) {
  DisplayController display(LoadDisplayProfile(std::string("config/displays/") + profile + ".yaml"));
  SedField f = Field(static_cast<int>(state.range(0)), 1);
  int64_t t = 0;
  for (auto _ : state) {
    f.utime += 1000;
    t += 1000;
    benchmark::DoNotOptimize(display.OnSedField(f, t));
  }
  state.counters["vertices"] = static_cast<double>(f.size());
  state.counters["actuators"] = static_cast<double>(display.profile().size());
}
BENCHMARK_CAPTURE(BM_MapAndLimit, suction_4x4, "suction_4x4")->Arg(400)->Arg(1600)->Arg(6400);
BENCHMARK_CAPTURE(BM_MapAndLimit, pin_6x4_interpolate, "pin_6x4")->Arg(400)->Arg(1600)->Arg(6400);

void BM_PublishCommandMemq(benchmark::State& state) {
  LcmPublisher out("memq://");
  DisplayCommand c;
  c.display_id = "suction_4x4";
  c.unit = "kPa";
  c.value.assign(16, 5.0);
  int k = 0;
  for (auto _ : state) {
    c.sequence = k++;
    out.Publish(out.channels().command, ToLcm(c));
    if (k % 256 == 0) state.PauseTiming(), out.lcm().handleTimeout(0), state.ResumeTiming();
  }
}
BENCHMARK(BM_PublishCommandMemq);

}  // namespace
}  // namespace sedbridge::display

BENCHMARK_MAIN();

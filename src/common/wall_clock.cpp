#include "common/wall_clock.h"

#include <chrono>

namespace sedbridge {

int64_t WallClockUtime() {
  using namespace std::chrono;
  return duration_cast<microseconds>(system_clock::now().time_since_epoch()).count();
}

}  // namespace sedbridge

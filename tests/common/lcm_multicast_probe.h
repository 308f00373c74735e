#pragma once
// Shared by the udpm tests: whether LCM multicast loops back on this host, so a test can
// skip saying why instead of failing on a machine without a multicast route.

#include <lcm/lcm-cpp.hpp>

#include <string>

namespace sedbridge::testing {

/// Publishes to itself once; "" when multicast works on `url`, else the reason.
inline std::string MulticastProblem(const std::string& url) {
  lcm::LCM lcm(url);
  if (!lcm.good()) return "LCM cannot open " + url + " (no multicast route?)";
  struct Probe {
    bool got = false;
    void On(const lcm::ReceiveBuffer*, const std::string&) { got = true; }
  } probe;
  lcm.subscribe("SEDBRIDGE_PROBE", &Probe::On, &probe);
  const char byte = 1;
  for (int attempt = 0; attempt < 5 && !probe.got; ++attempt) {
    if (lcm.publish("SEDBRIDGE_PROBE", &byte, 1) != 0) return "publish on " + url + " failed";
    lcm.handleTimeout(100);
  }
  return probe.got ? "" : "multicast on this host does not loop back (" + url + ")";
}

}  // namespace sedbridge::testing

#pragma once
// A synthetic display influence for the renderer's tests: `vertices` vertices, each the
// average of two neighbouring elements, and actuators whose strain falls off with distance
// along a line of elements (as a hole's or pin's does across the pad).

#include <Eigen/Core>
#include <cmath>
#include <random>

#include "render/display_influence.h"

namespace sedbridge::render::testing {

inline ElementStrainInfluence SyntheticInfluence(int actuators, int elements, double preload, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-1.0, 1.0);
  ElementStrainInfluence in;
  in.strain_per_command.setZero(kStrainComponents * elements, actuators);
  in.preload_strain.setZero(kStrainComponents * elements);
  in.mu_Pa.setConstant(elements, 10e3);
  in.lambda_Pa.setConstant(elements, 400e3);
  for (int e = 0; e < elements; ++e) {
    const double x = (e + 0.5) / elements;  // element position along the pad [0, 1]
    for (int a = 0; a < actuators; ++a) {
      const double centre = (a + 0.5) / actuators, d = (x - centre) * actuators;
      const double fall = std::exp(-d * d);
      for (int k = 0; k < kStrainComponents; ++k)
        in.strain_per_command(kStrainComponents * e + k, a) = 1e-3 * fall * (k == 2 ? -1.0 : 0.3 * jitter(rng));
    }
    in.preload_strain[kStrainComponents * e + 2] = -preload;
  }
  const int vertices = elements - 1;
  for (int v = 0; v < vertices; ++v) {
    in.vertex_start.push_back(int(in.vertex_element.size()));
    for (int e : {v, v + 1}) {
      in.vertex_element.push_back(e);
      in.vertex_weight.push_back(0.5);
    }
  }
  in.vertex_start.push_back(int(in.vertex_element.size()));
  return in;
}

}  // namespace sedbridge::render::testing

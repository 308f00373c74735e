#include "render/element_sed_kernel.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace sedbridge::render {
namespace {

// VertexFormSeds over chunked forms against each vertex's form summed on its own in double:
// every actuator count (the vector part and the tail of its sums) and vertex count (a chunk's
// unused lanes), with and without the Jacobian; nothing is written past the last vertex.
TEST(VertexFormSeds, EachLaneIsItsVertexsOwnFormForAnyActuatorAndVertexCount) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> draw(-2.0f, 2.0f);
  for (int n : {1, 3, 4, 5, 8, 13, 16, 17}) {
    for (size_t vertices : {size_t(1), size_t(7), size_t(8), size_t(9), size_t(23)}) {
      const size_t entries = VertexFormEntries(n);
      std::vector<float> plain(vertices * entries), chunked(SedChunks(vertices) * entries * kSedLanes, 0.0f);
      for (size_t v = 0; v < vertices; ++v)
        for (size_t k = 0; k < entries; ++k) {
          plain[v * entries + k] = draw(rng);
          chunked[VertexFormIndex(v, k, n)] = plain[v * entries + k];
        }
      std::vector<float> u(static_cast<size_t>(n)), scratch(static_cast<size_t>(n) * kSedLanes);
      for (float& x : u) x = draw(rng);
      std::vector<double> constant(vertices);
      for (double& c : constant) c = 100.0 * draw(rng);
      const double sentinel = std::numeric_limits<double>::quiet_NaN();
      std::vector<double> sed(vertices + 1, sentinel), jacobian(vertices * size_t(n) + 1, sentinel), alone(vertices + 1);
      VertexFormSeds(vertices, n, chunked.data(), constant.data(), u.data(), sed.data(), jacobian.data(), scratch.data());
      VertexFormSeds(vertices, n, chunked.data(), constant.data(), u.data(), alone.data(), nullptr, scratch.data());
      EXPECT_TRUE(std::isnan(sed[vertices]) && std::isnan(jacobian[vertices * size_t(n)])) << n << " " << vertices;
      for (size_t v = 0; v < vertices; ++v) {
        const float* g = plain.data() + v * entries;
        const float* Q = g + n;  // column by column
        double expected = constant[v], scale = std::abs(constant[v]);
        for (int j = 0; j < n; ++j) {
          double Qu_j = 0, size_j = 0;
          for (int i = 0; i < n; ++i) Qu_j += double(Q[i * n + j]) * u[size_t(i)], size_j += std::abs(Q[i * n + j] * u[size_t(i)]);
          expected += double(g[j]) * u[size_t(j)] + u[size_t(j)] * Qu_j;
          scale += std::abs(g[j] * u[size_t(j)]) + std::abs(u[size_t(j)]) * size_j;
          const double derivative = double(g[j]) + 2.0 * Qu_j;
          EXPECT_NEAR(jacobian[v * size_t(n) + size_t(j)], derivative, 1e-5 * (std::abs(g[j]) + 2.0 * size_j))
              << n << " " << vertices << " " << v << " " << j;
        }
        EXPECT_NEAR(sed[v], expected, 1e-5 * scale) << n << " " << vertices << " " << v;
        EXPECT_EQ(sed[v], alone[v]) << "the Jacobian changes no SED";
      }
    }
  }
}

}  // namespace
}  // namespace sedbridge::render

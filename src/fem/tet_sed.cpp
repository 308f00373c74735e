#include "fem/tet_sed.h"

#include "common/hot_clones.h"

namespace sedbridge::fem {

// A hot loop of the compliance step (the other: the dense column products,
// fem/column_products.h), hence raw pointers and an AVX2 clone (common/hot_clones.h).
SEDBRIDGE_HOT_CLONES
void LinearTetSeds(int begin, int end, int count, const int* offset, const double* gradient, const double* mu_Pa,
                   const double* lambda_Pa, const double* u, double* sed_Pa) {
#pragma omp simd
  for (int e = begin; e < end; ++e) {
    double H[3][3] = {};  // displacement gradient sum_a u_a g_a^T
    for (int a = 0; a < 4; ++a) {
      const double* ua = u + offset[a * count + e];
      for (int q = 0; q < 3; ++q) {
        const double g = gradient[(3 * a + q) * count + e];
        for (int r = 0; r < 3; ++r) H[r][q] += ua[r] * g;
      }
    }
    sed_Pa[e] = DisplacementGradientSed(H[0][0], H[0][1], H[0][2], H[1][0], H[1][1], H[1][2], H[2][0], H[2][1], H[2][2],
                                        mu_Pa[e], lambda_Pa[e]);
  }
}

}  // namespace sedbridge::fem

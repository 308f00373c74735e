#pragma once
// The small-strain strain energy density of a linear tetrahedron (paper eq. 1),
//   W = 1/2 sigma:eps = mu eps:eps + lambda/2 tr(eps)^2   [Pa = J/m^3],
// written once for every path that evaluates it: one element at a time (ElementSed), four
// at a time in vector registers (the scene's SED, T = a GCC vector of four doubles), and
// the compliance method's structure-of-arrays pass (LinearTetSeds). The operations are in
// one order everywhere, so the paths agree to the last bit on the same strain.

namespace sedbridge::fem {

// T: double, or a GCC vector of doubles (element-wise); results through a reference (no
// vector is passed or returned by value: that changes the ABI without AVX). Always inlined,
// so hot loops keep the strain in registers.
#define SEDBRIDGE_TET_SED_INLINE inline __attribute__((always_inline))

/// SED [Pa] of the symmetric strain (e00, e11, e22, e01, e02, e12) [-] with Lamé
/// parameters mu_Pa and lambda_Pa [Pa], into sed_Pa.
template <typename T>
SEDBRIDGE_TET_SED_INLINE void SymmetricStrainSed(const T& e00, const T& e11, const T& e22, const T& e01, const T& e02,
                                                 const T& e12, const T& mu_Pa, const T& lambda_Pa, T& sed_Pa) {
  const T tr = e00 + e11 + e22;
  const T eps_eps = e00 * e00 + e11 * e11 + e22 * e22 + 2.0 * (e01 * e01 + e02 * e02 + e12 * e12);
  sed_Pa = mu_Pa * eps_eps + 0.5 * lambda_Pa * tr * tr;
}

/// SED [Pa] of the small strain eps = sym(H) of a displacement gradient H [-] (linear FEM),
/// its nine entries by value (row by row): a reference to a local array here keeps GCC from
/// vectorizing the structure-of-arrays loop that calls it.
SEDBRIDGE_TET_SED_INLINE double DisplacementGradientSed(double h00, double h01, double h02, double h10, double h11,
                                                        double h12, double h20, double h21, double h22, double mu_Pa,
                                                        double lambda_Pa) {
  const double e01 = 0.5 * (h01 + h10), e02 = 0.5 * (h02 + h20), e12 = 0.5 * (h12 + h21);
  double sed_Pa = 0;
  SymmetricStrainSed<double>(h00, h11, h22, e01, e02, e12, mu_Pa, lambda_Pa, sed_Pa);
  return sed_Pa;
}

/// SED [Pa] of eps = sym(G) - I for G = R^T F [-] (corotational; R = I: linear FEM with F).
template <typename T>
SEDBRIDGE_TET_SED_INLINE void StretchSed(const T (&G)[3][3], const T& mu_Pa, const T& lambda_Pa, T& sed_Pa) {
  const T e00 = G[0][0] - 1.0, e11 = G[1][1] - 1.0, e22 = G[2][2] - 1.0;
  const T e01 = 0.5 * (G[0][1] + G[1][0]), e02 = 0.5 * (G[0][2] + G[2][0]), e12 = 0.5 * (G[1][2] + G[2][1]);
  SymmetricStrainSed<T>(e00, e11, e22, e01, e02, e12, mu_Pa, lambda_Pa, sed_Pa);
}

/// Linear SED of tetrahedra [begin, end) of `count` from the displacements u [m] of their
/// nodes, in structure-of-arrays layout (the loop vectorizes across elements): element e's
/// node a at u + offset[a * count + e], shape gradient component (a, q) [1/m] at
/// gradient[(3 a + q) * count + e], Lamé parameters mu_Pa[e], lambda_Pa[e]; writes sed_Pa[e].
void LinearTetSeds(int begin, int end, int count, const int* offset, const double* gradient, const double* mu_Pa,
                   const double* lambda_Pa, const double* u, double* sed_Pa);

}  // namespace sedbridge::fem

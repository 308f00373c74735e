#pragma once
// The render's inner loop (render/display_influence.h): the strain, SED and SED gradient of
// the influence's elements at a stroke vector, eight elements at a time in structure-of-
// arrays layout, one vector lane per element: no horizontal sums, no per-element dispatch.
// On x86-64 it is compiled twice, for the baseline the build targets and for x86-64-v3
// (AVX2, FMA), and the CPU picks at load time (GCC's target_clones): the package stays
// portable, the machines that have wider vectors use them.

#include <cstddef>

namespace sedbridge::render {

/// Elements per chunk (vector lanes of the kernel).
constexpr int kSedLanes = 8;
/// Strain components per element (xx, yy, zz, xy, xz, yz).
constexpr int kSedStrainComponents = 6;

/// Chunks holding `elements` elements.
inline size_t SedChunks(size_t elements) { return (elements + kSedLanes - 1) / kSedLanes; }

/// Where element e's strain component c per unit stroke of actuator i (of n) lies in the
/// chunked slope array: chunk e / 8, then actuator, component, lane.
inline size_t ChunkedSlopeIndex(size_t e, int c, int i, int n) {
  return ((e / kSedLanes * size_t(n) + size_t(i)) * kSedStrainComponents + size_t(c)) * kSedLanes + e % kSedLanes;
}

/// For elements [0, elements): eps_e = intercept_e + slopes_e . stroke [-], the linear SED
/// W_e = mu eps:eps + lambda/2 tr(eps)^2 [Pa] into sed_Pa[e], and, when gradient_t is not
/// null, dW_e/dstroke_i [Pa / command unit] into gradient_t[e n + i] (a contiguous column
/// per element).
/// @param slopes     SedChunks(elements) * n * 6 * 8 floats (ChunkedSlopeIndex; padding 0)
/// @param stroke     n floats [command unit]
/// @param intercept  6 doubles per element, element-major (6 e + c) [-]
/// @param mu_Pa, lambda_Pa  per element [Pa]
/// @param scratch    n * 8 floats (the chunk's gradient before it is stored per element)
void ChunkedElementSeds(size_t elements, int n, const float* slopes, const float* stroke, const double* intercept,
                        const double* mu_Pa, const double* lambda_Pa, double* sed_Pa, float* gradient_t, float* scratch);

/// Floats of one vertex's form: g (n), then Q (n * n, column by column).
inline size_t VertexFormEntries(int n) { return size_t(n) + size_t(n) * size_t(n); }
/// Where entry k of vertex v's form lies in VertexFormSeds' chunked array.
inline size_t VertexFormIndex(size_t v, size_t k, int n) {
  return ((v / kSedLanes) * VertexFormEntries(n) + k) * kSedLanes + v % kSedLanes;
}
/// Vertex SEDs of a linear influence from per-vertex quadratic forms: S_v = constant_v +
/// g_v . u + u^T Q_v u [Pa], and, when jacobian_t is not null, dS_v/du = g_v + 2 Q_v u into
/// jacobian_t[v n + i] [Pa / command unit].
/// @param forms   SedChunks(vertices) chunks of eight vertices, one lane each: per vertex
///                VertexFormEntries(n) floats, g_v then Q_v (symmetric, column by column),
///                entry k of lane l at (chunk VertexFormEntries(n) + k) 8 + l
///                (VertexFormIndex; padding 0)
/// @param u       n floats [command unit]
/// @param scratch n * 8 floats
void VertexFormSeds(size_t vertices, int n, const float* forms, const double* constant, const float* u,
                    double* sed_Pa, double* jacobian_t, float* scratch);

}  // namespace sedbridge::render

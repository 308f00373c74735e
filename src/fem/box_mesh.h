#pragma once
// Structured tetrahedral meshes of a box (each cube split into 6 tets along its main
// diagonal, conforming). For analytic tests, benchmarks and small reference decks.

#include "fem/tet_mesh.h"

namespace sedbridge::fem {

/// Box [0, size] with cells.x * cells.y * cells.z cubes, one material.
TetMesh MakeBoxMesh(const Eigen::Vector3d& size_m, const Eigen::Vector3i& cells,
                    const LinearElasticMaterial& material);

/// Node index of lattice point (i, j, k) in a MakeBoxMesh mesh.
int BoxNodeIndex(const Eigen::Vector3i& cells, int i, int j, int k);

}  // namespace sedbridge::fem

// SPDX-License-Identifier: Apache-2.0
#pragma once
// Mass, centre of mass and inertia of a solid of uniform density bounded by a closed triangle mesh, exactly (to
// rounding), from the volume integrals of 1, x, y, z, x², y², z², xy, yz, zx turned into surface integrals by the
// divergence theorem, one triangle at a time (Mirtich 1996, "Fast and accurate computation of polyhedral mass
// properties"; in the compact form of Eberly, "Polyhedral Mass Properties (Revisited)", 2002).

#include "common/mesh/triangle_mesh.h"

#include <Eigen/Core>

namespace impetus {

struct MassProperties {
  double volume_m3 = 0.0;
  double mass_kg = 0.0;
  Eigen::Vector3d centre_of_mass_m = Eigen::Vector3d::Zero();                // in the mesh's frame
  Eigen::Matrix3d inertia_about_com_kgm2 = Eigen::Matrix3d::Zero();          // axes of the mesh's frame
};

// Of a closed, outward-wound mesh (mesh_check.h) at `density_kgpm3`. The integrals are taken about the centre of the
// mesh's bounding box, so a mesh far from its origin loses no digits to cancellation.
MassProperties mass_properties(const TriangleMesh& mesh, double density_kgpm3);

}  // namespace impetus

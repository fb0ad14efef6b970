// SPDX-License-Identifier: Apache-2.0
#include "common/mesh/mass_properties.h"

#include <Eigen/Geometry>

namespace impetus {
namespace {

// The per-triangle sums of Eberly's form of the integrals along one axis, for the axis's three vertex coordinates
// w0, w1, w2: f1 = Σw, f2 = Σ of degree-2 monomials, f3 = Σ of degree 3, and g_i = f2 + w_i·(f1 + w_i).
struct Sums {
  double f1, f2, f3, g0, g1, g2;
};

Sums sums(double w0, double w1, double w2) {
  const double t0 = w0 + w1;
  const double t1 = w0 * w0;
  const double t2 = t1 + w1 * t0;
  Sums s{};
  s.f1 = t0 + w2;
  s.f2 = t2 + w2 * s.f1;
  s.f3 = w0 * t1 + w1 * t2 + w2 * s.f2;
  s.g0 = s.f2 + w0 * (s.f1 + w0);
  s.g1 = s.f2 + w1 * (s.f1 + w1);
  s.g2 = s.f2 + w2 * (s.f1 + w2);
  return s;
}

}  // namespace

MassProperties mass_properties(const TriangleMesh& mesh, double density_kgpm3) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& v : mesh.vertices_m) box.extend(v);
  const Eigen::Vector3d origin = box.isEmpty() ? Eigen::Vector3d(Eigen::Vector3d::Zero()) : Eigen::Vector3d(box.center());
  // ∫1, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫yz, ∫zx over the solid, about `origin`.
  double I[10] = {};
  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3d p0 = mesh.vertices_m[tri[0]] - origin;
    const Eigen::Vector3d p1 = mesh.vertices_m[tri[1]] - origin;
    const Eigen::Vector3d p2 = mesh.vertices_m[tri[2]] - origin;
    const Eigen::Vector3d d = (p1 - p0).cross(p2 - p0);  // twice the area times the outward normal
    const Sums x = sums(p0.x(), p1.x(), p2.x());
    const Sums y = sums(p0.y(), p1.y(), p2.y());
    const Sums z = sums(p0.z(), p1.z(), p2.z());
    I[0] += d.x() * x.f1;
    I[1] += d.x() * x.f2;
    I[2] += d.y() * y.f2;
    I[3] += d.z() * z.f2;
    I[4] += d.x() * x.f3;
    I[5] += d.y() * y.f3;
    I[6] += d.z() * z.f3;
    I[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    I[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    I[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  I[0] /= 6.0;
  for (int k = 1; k <= 3; ++k) I[k] /= 24.0;
  for (int k = 4; k <= 6; ++k) I[k] /= 60.0;
  for (int k = 7; k <= 9; ++k) I[k] /= 120.0;

  MassProperties out;
  out.volume_m3 = I[0];
  out.mass_kg = density_kgpm3 * I[0];
  if (!(I[0] > 0.0)) return out;
  const Eigen::Vector3d c(I[1] / I[0], I[2] / I[0], I[3] / I[0]);  // about `origin`
  // Inertia per unit density about `origin`, then moved to the centre of mass (parallel axes).
  Eigen::Matrix3d J;
  J << I[5] + I[6], -I[7], -I[9],
       -I[7], I[4] + I[6], -I[8],
       -I[9], -I[8], I[4] + I[5];
  J -= I[0] * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  out.centre_of_mass_m = origin + c;
  out.inertia_about_com_kgm2 = density_kgpm3 * J;
  return out;
}

}  // namespace impetus

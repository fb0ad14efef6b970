// SPDX-License-Identifier: Apache-2.0
#include "world_manager/engine/speculative_contact.h"

#include <cmath>

namespace impetus {

int speculative_contacts(dGeomID moving, dBodyID body, dGeomID other, const Eigen::Vector3d& displacement_m,
                         dContact* out, int capacity) {
  const dReal* p = dBodyGetPosition(body);
  const dReal start[3] = {p[0], p[1], p[2]};
  dBodySetPosition(body, start[0] + displacement_m.x(), start[1] + displacement_m.y(), start[2] + displacement_m.z());
  const int count = dCollide(moving, other, capacity, &out[0].geom, sizeof(dContact));
  dBodySetPosition(body, start[0], start[1], start[2]);
  int kept = 0;
  for (int i = 0; i < count; ++i) {
    const dContactGeom& overlap = out[i].geom;
    const Eigen::Vector3d normal(overlap.normal[0], overlap.normal[1], overlap.normal[2]);
    // The overlap along n at the moved pose is depth; moving back by d changes it by d·n (n pushes `moving` out),
    // so at the start the pair is apart by gap = −depth − d·n.
    const double gap_m = -overlap.depth - displacement_m.dot(normal);
    if (!std::isfinite(gap_m)) continue;
    const Eigen::Vector3d at = Eigen::Vector3d(overlap.pos[0], overlap.pos[1], overlap.pos[2]) - displacement_m -
                               0.5 * gap_m * normal;
    dContact& kept_contact = out[kept++];
    kept_contact.geom = overlap;
    for (int k = 0; k < 3; ++k) kept_contact.geom.pos[k] = at[k];
    kept_contact.geom.depth = -gap_m;
  }
  return kept;
}

}  // namespace impetus

// SPDX-License-Identifier: Apache-2.0
#pragma once
// The world log (DESIGN.md §4 "Logs"): a CSV with a header row and one row per world step, time first, then for every
// dynamic object its pose, velocity and the impulse the world applied to it (this step and since the start), then the
// cumulative reaction into static geometry. Column names carry units: `cube.x_m`, `cube.jx_Ns`, `cube.jx_total_Ns`.

#include "world_manager/world.h"

#include <ostream>

namespace impetus {

class WorldLog {
 public:
  // Keeps a reference to `world`, which must outlive the log.
  explicit WorldLog(const World& world) : world_(world) {}

  void write_header(std::ostream& out) const;
  // The state after the world's last step.
  void write_row(std::ostream& out) const;

 private:
  const World& world_;
};

}  // namespace impetus

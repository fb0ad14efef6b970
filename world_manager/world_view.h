// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the world shows its viewers (common/contract/world_view.h), taken from the scene and the world after a step.

#include "common/contract/world_view.h"
#include "world_manager/world.h"

#include <span>

namespace impetus {

// The scene's shapes, names (cut to kMaxViewNameBytes − 1 bytes) and floor; the first kMaxViewBodies objects.
void describe_scene(const Scene& scene, Coupling coupling, double world_rate_hz, std::uint64_t world_session,
                    ViewScene& out);
// A body's pose as the scene places it (static bodies keep it for the whole run).
ViewBodyPose scene_pose(const SceneObject& object);

// Every body's pose after the last step and, for each endpoint slot with a report (`reports[k]`, slot k; nullptr:
// none), its endpoint: finger, proxy, force and the planes of the slot's last frame nearest the proxy (at most
// kMaxViewPlanes). Touches only the used part of `out`.
void take_snapshot(const World& world, std::span<const HapticReport* const> reports, const LoopStats& world_stats,
                   const LoopStats* haptic_stats, WorldSnapshot& out);
// The same for one endpoint slot.
inline void take_snapshot(const World& world, const HapticReport* report, const LoopStats& world_stats,
                          const LoopStats* haptic_stats, WorldSnapshot& out) {
  take_snapshot(world, std::span<const HapticReport* const>(&report, 1), world_stats, haptic_stats, out);
}

}  // namespace impetus

// SPDX-License-Identifier: Apache-2.0
#pragma once
// The god-object (Zilles & Salisbury; paper §3.3, docs/architecture.md §1.2 step 3): the proxy D_j, the point that
// represents the finger on the surface, outside every interpolated plane, with friction (paper §6.2).
//
// GodObject::solve = project_outside_planes (the frictionless proxy and the contact's multipliers) followed by
// apply_friction (stick/slip of the proxy on the surface). The proxy is not left inside a mesh: its move from where
// the walk over the meshes ended stops where it would go into one (mesh_walk.h stop_at_meshes; a held triangle's
// plane runs on behind a concave neighbour, and a primitive's plane knows nothing of the meshes). The reported active
// constraints and multipliers are the frictionless ones: the normal load each plane carries, by which the reaction is
// shared among objects (§3.4).
// Owned by the servo thread; allocation-free.
//
// A finger that starts inside an object (the device attaches, or the finger reappears, with the fingertip already
// behind a surface) is not kicked out to the nearest face: that would render a force of k·depth — the device maximum
// for a centimetre — for energy nobody put in. Instead, at the start of a finger session the planes of resting objects
// the finger is already behind are disarmed: they do not constrain the proxy until the finger has come out of them
// (or the object has left the frame), after which they act normally. Planes the finger is in front of at the start,
// planes of objects moving onto the finger, and every plane that appears later act at once — so an object that
// arrives onto the finger still pushes it out (hard case 5, the pinch).
//
// A finger that vanishes while pressing (the device absent or invalid for a while, a web page silent, the servo
// stalled) and comes back into an object it was pressing resumes that contact as it left it: the object's planes are
// set back by however much deeper the finger is now than when it vanished (not at all if no deeper), until the finger
// has left the object. The force it meets again is at most the one it was pressing against, k·depth then, and on the
// way out it gets back ½k·depth² at most: energy the hand had put in. Disarming the object instead would let the
// finger sink through what it was pressing on.

#include "haptic_controller/contact_plane.h"
#include "haptic_controller/friction.h"
#include "haptic_controller/mesh_walk.h"
#include "haptic_controller/proxy_projection.h"

#include <Eigen/Core>

namespace impetus {

struct GodObjectResult {
  ProxySolution contact;  // contact.proxy_m is the final proxy D_j (after friction)
  bool sticking = false;
};

class GodObject {
 public:
  // `dt_s` is the real time since the previous solve: how far the anchor's object moved. `walked`, if given, is this
  // tick's walk over the meshes of `planes` (mesh_walk.h: its end, outside every mesh, and the triangles it held): the
  // proxy's move from that end, which friction and the primitives' planes make and the walk did not know of, stops
  // where it would go into a mesh. Without it, friction's move from the frictionless proxy does.
  const GodObjectResult& solve(const PlaneSet& planes, const Eigen::Vector3d& finger_m, double dt_s,
                               const MeshHold* walked = nullptr);

  // No contact memory (device detached, session restart).
  void reset();

  // The finger has just become known at `finger_m` (first valid device reading after none): the next solve that sees
  // planes sets back those of resting objects that both this starting position and the current finger are behind —
  // the finger was inside from the start, not driven in while the first world frame was on its way: by what it sank
  // since it vanished from an object it pressed, entirely (disarmed) from any other.
  void begin_finger_session(const Eigen::Vector3d& finger_m);

  // The finger vanished: forget the contact memory, but keep the objects the last solve pressed and how deep, for
  // the next session to resume (above). reset() forgets those too.
  void end_finger_session();

  const GodObjectResult& result() const { return result_; }

 private:
  // The planes that constrain the proxy this tick: `planes` minus the disarmed ones, the set-back ones moved. Returns
  // `planes` itself when nothing is set back (the usual case, no copy); otherwise fills armed_ and armed_index_.
  const PlaneSet& armed_planes(const PlaneSet& planes, const Eigen::Vector3d& finger_m);

  // An object the finger pressed, and how deep behind its (set-back) plane, m.
  struct Pressed {
    std::int32_t object_id = 0;
    double depth_m = 0.0;
  };
  // An object whose planes the finger is set back from: disarmed (setback infinite) or moved inward along their
  // normals by setback_m (m, > 0), until the finger has left the object; depth_m is how deep behind its true planes
  // the finger was at the last solve.
  struct Sunk {
    std::int32_t object_id = 0;
    double setback_m = 0.0;
    double depth_m = 0.0;
  };
  // How deep the finger was behind the object's (set-back) planes when it vanished (m), −∞ if it was not in it.
  double held_depth_m(std::int32_t object_id) const;
  // Forgets the anchor, the last result, what is pressed and set back; keeps held_.
  void forget_contact();

  FrictionAnchor anchor_;
  GodObjectResult result_;
  bool session_starting_ = false;
  Eigen::Vector3d session_start_finger_m_ = Eigen::Vector3d::Zero();
  std::array<Sunk, kMaxServoPlanes> sunk_{};
  int sunk_count_ = 0;
  std::array<Pressed, kMaxActiveConstraints + 1> pressed_{};  // by the last solve
  int pressed_count_ = 0;
  std::array<Pressed, kMaxActiveConstraints + 1 + kMaxServoPlanes> held_{};  // when the finger vanished
  int held_count_ = 0;
  PlaneSet armed_;
  std::array<int, kMaxServoPlanes> armed_index_{};  // armed_ index → index in the caller's PlaneSet
};

}  // namespace impetus

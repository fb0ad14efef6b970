// SPDX-License-Identifier: Apache-2.0
#pragma once
// The fields of the contract frames (common/contract/frames.h), listed once for every encoding of them: the contract
// structs, the shared-memory wire frames (shm/wire_frames.h) and the DDS topic types (dds/impetus_link.idl) name their
// fields alike, so visit_X(a, b, f) calls f(a.field, b.field) for every field of X, whichever two of them a and b
// are. A transport's f converts or copies; adding a field to the contract means adding it here and to each encoding.
//
// Not visited: each frame's checksum and reserved words (the encodings' own), and the planes and entries beyond the
// headers' counts (the codecs loop over them).

#include "common/contract/frames.h"
#include "common/runtime/loop_stats.h"

#include <cstddef>

namespace impetus::fields {

template <class A, class B, class F>
void visit_contact(A& a, B& b, F&& f) {
  f(a.normal, b.normal);
  f(a.friction, b.friction);
  f(a.other_velocity_mps, b.other_velocity_mps);
  f(a.other_inverse_mass_per_kg, b.other_inverse_mass_per_kg);
  f(a.flags, b.flags);
  f(a.gap_m, b.gap_m);
}

template <class A, class B, class F>
void visit_shape(A& a, B& b, F&& f) {
  f(a.kind, b.kind);
  f(a.box_size_m, b.box_size_m);
  f(a.radius_m, b.radius_m);
  f(a.length_m, b.length_m);
  f(a.mesh_hash, b.mesh_hash);
}

template <class A, class B, class F>
void visit_plane(A& a, B& b, F&& f) {
  f(a.object_id, b.object_id);
  f(a.flags, b.flags);
  f(a.point_m, b.point_m);
  f(a.normal, b.normal);
  f(a.com_m, b.com_m);
  f(a.velocity_mps, b.velocity_mps);
  f(a.angular_velocity_radps, b.angular_velocity_radps);
  f(a.static_friction, b.static_friction);
  f(a.dynamic_friction, b.dynamic_friction);
  f(a.extent_m, b.extent_m);
  f(a.yield_force_N, b.yield_force_N);
  f(a.yield_depth_mpNs, b.yield_depth_mpNs);
  f(a.yield_radius_m, b.yield_radius_m);
  f(a.yield_room_m, b.yield_room_m);
  f(a.yield_compliance_mpN, b.yield_compliance_mpN);
  visit_shape(a.shape, b.shape, f);
  f(a.body_axis_x, b.body_axis_x);
  f(a.body_axis_y, b.body_axis_y);
  f(a.inverse_mass_per_kg, b.inverse_mass_per_kg);
  f(a.inverse_inertia_world, b.inverse_inertia_world);
  f(a.local_contact_count, b.local_contact_count);
  for (std::size_t c = 0; c < kMaxLocalContacts; ++c) visit_contact(a.local_contacts[c], b.local_contacts[c], f);
}

template <class A, class B, class F>
void visit_frame_header(A& a, B& b, F&& f) {
  f(a.frame_index, b.frame_index);
  f(a.world_session, b.world_session);
  f(a.endpoint, b.endpoint);
  f(a.report_tick_applied, b.report_tick_applied);
  f(a.report_session_applied, b.report_session_applied);
  f(a.world_time_s, b.world_time_s);
  f(a.world_period_s, b.world_period_s);
  f(a.coupling, b.coupling);
  f(a.plane_count, b.plane_count);
  f(a.stiffness_Npm, b.stiffness_Npm);
  f(a.damping_Nspm, b.damping_Nspm);
  f(a.gravity_mps2, b.gravity_mps2);
  f(a.world_substep_s, b.world_substep_s);
  f(a.reach_radius_m, b.reach_radius_m);
  f(a.port_layer, b.port_layer);
  f(a.port_returned_J, b.port_returned_J);
  f(a.dent_patch.object_id, b.dent_patch.object_id);
  f(a.dent_patch.origin_m, b.dent_patch.origin_m);
  f(a.dent_patch.axis_x, b.dent_patch.axis_x);
  f(a.dent_patch.axis_y, b.dent_patch.axis_y);
  f(a.dent_patch.spacing_m, b.dent_patch.spacing_m);
  f(a.dent_patch.height_m, b.dent_patch.height_m);
}

template <class A, class B, class F>
void visit_entry(A& a, B& b, F&& f) {
  f(a.object_id, b.object_id);
  f(a.epoch, b.epoch);
  f(a.impulse_Ns, b.impulse_Ns);
  f(a.angular_impulse_Nms, b.angular_impulse_Nms);
  f(a.impulse_moment_Nss, b.impulse_moment_Nss);
  f(a.angular_impulse_moment_Nmss, b.angular_impulse_moment_Nmss);
  f(a.hand_input_J, b.hand_input_J);
  f(a.press_Ns, b.press_Ns);
  f(a.press_point_Nsm, b.press_point_Nsm);
  f(a.press_point2_Nsm2, b.press_point2_Nsm2);
  f(a.last_tick, b.last_tick);
}

template <class A, class B, class F>
void visit_report_header(A& a, B& b, F&& f) {
  f(a.tick, b.tick);
  f(a.haptic_session, b.haptic_session);
  f(a.endpoint, b.endpoint);
  f(a.world_session, b.world_session);
  f(a.haptic_time_s, b.haptic_time_s);
  f(a.finger_m, b.finger_m);
  f(a.finger_velocity_mps, b.finger_velocity_mps);
  f(a.proxy_m, b.proxy_m);
  f(a.force_N, b.force_N);
  f(a.oriented, b.oriented);
  f(a.torque_Nm, b.torque_Nm);
  f(a.finger_wxyz, b.finger_wxyz);
  f(a.proxy_wxyz, b.proxy_wxyz);
  f(a.finger_valid, b.finger_valid);
  f(a.entry_count, b.entry_count);
  f(a.static_impulse_Ns, b.static_impulse_Ns);
  f(a.link_round_trip_s, b.link_round_trip_s);
}

// A loop's statistics (not a frame: no seal, no counts), for the transports that carry them.
template <class A, class B, class F>
void visit_loop_stats(A& a, B& b, F&& f) {
  f(a.heartbeat_ns, b.heartbeat_ns);
  f(a.pid, b.pid);
  f(a.ticks, b.ticks);
  f(a.skipped_periods, b.skipped_periods);
  f(a.faults, b.faults);
  f(a.rejected_frames, b.rejected_frames);
  f(a.lateness_p50_ns, b.lateness_p50_ns);
  f(a.lateness_p99_ns, b.lateness_p99_ns);
  f(a.lateness_p999_ns, b.lateness_p999_ns);
  f(a.lateness_max_ns, b.lateness_max_ns);
}

}  // namespace impetus::fields

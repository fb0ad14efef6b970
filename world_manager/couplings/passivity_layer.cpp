// SPDX-License-Identifier: Apache-2.0
#include "world_manager/couplings/passivity_layer.h"

#include <Eigen/Geometry>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>

namespace impetus {

PassivityLayer::PassivityLayer(std::span<const ObjectState> states, RigidBodyEngine& engine, bool enabled,
                               const Eigen::Vector3d& gravity_mps2)
    : states_(states),
      engine_(engine),
      enabled_(enabled),
      gravity_mps2_(gravity_mps2),
      books_(states.size()),
      force_N_(states.size(), Eigen::Vector3d::Zero()),
      torque_Nm_(states.size(), Eigen::Vector3d::Zero()),
      is_forced_(states.size(), false),
      admitted_J_(states.size(), 0.0),
      low_water_J_(states.size(), 0.0),
      velocity_before_mps_(states.size(), Eigen::Vector3d::Zero()),
      angular_before_radps_(states.size(), Eigen::Vector3d::Zero()),
      is_touched_(states.size(), false) {
  forced_.reserve(states.size());
  touched_.reserve(states.size());
}

void PassivityLayer::touch(std::size_t id) {
  if (is_touched_[id]) return;
  is_touched_[id] = true;
  touched_.push_back(id);
}

void PassivityLayer::add_hand_input(std::size_t id, double work_J) {
  if (!std::isfinite(work_J)) return;
  books_[id].hand_input_J += work_J;
  touch(id);
}

double PassivityLayer::budget_J(std::size_t id) const {
  const PortEnergy& books = books_[id];
  return books.hand_input_J - books.port_work_J - books.returned_J - admitted_J_[id];
}

void PassivityLayer::count(std::size_t id, double withheld_J, double damped_J, double impulse_Ns) {
  PortEnergy& books = books_[id];
  books.withheld_J += withheld_J;
  books.damped_J += damped_J;
  books.removed_impulse_Ns += impulse_Ns;
  ++books.interventions;
}

namespace {

// The largest α ∈ [0, 1] with α·a + α²·b ≤ B (b ≥ 0): the share of a push whose energy a·α + b·α² fits the budget B.
double admitted_share(double a, double b, double budget_J) {
  if (!(a + b > budget_J) || !(b > 0.0)) {
    if (b > 0.0 || !(a > budget_J)) return 1.0;
    return a > 0.0 ? std::clamp(budget_J / a, 0.0, 1.0) : 1.0;  // linear: a push along the motion, no b
  }
  if (a * a + 4.0 * b * budget_J >= 0.0) {
    // The larger root of b·α² + a·α − B = 0: ΔKE(α) ≤ B on [0, α] when B ≥ 0; when B < 0 the roots bracket the
    // braking part of the push (a < 0), and the larger one is the most of it that still leaves ΔKE ≤ B.
    return std::clamp((-a + std::sqrt(a * a + 4.0 * b * budget_J)) / (2.0 * b), 0.0, 1.0);
  }
  return std::clamp(-a / (2.0 * b), 0.0, 1.0);  // B out of reach: the α that gives the least energy
}

}  // namespace

double PassivityLayer::admit_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                                             const Eigen::Vector3d& angular_impulse_Nms,
                                             const Eigen::Vector3d& v0_mps, const Eigen::Vector3d& w0_radps,
                                             double inverse_mass_per_kg, const Eigen::Matrix3d& inverse_inertia_world) {
  if (!enabled_) return 1.0;
  // ΔKE(α) = α·a + α²·b, exact for a velocity change (header).
  const double a = impulse_Ns.dot(v0_mps) + angular_impulse_Nms.dot(w0_radps);
  const double b = 0.5 * (inverse_mass_per_kg * impulse_Ns.squaredNorm() +
                          angular_impulse_Nms.dot(inverse_inertia_world * angular_impulse_Nms));
  const double full_J = a + b;
  if (!(full_J > budget_J(id)) || !(b > 0.0)) return 1.0;
  const double alpha = admitted_share(a, b, budget_J(id));
  count(id, full_J - (alpha * a + alpha * alpha * b), 0.0, (1.0 - alpha) * impulse_Ns.norm());
  return alpha;
}

double PassivityLayer::admit_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm,
                                   double substep_s) {
  if (!enabled_) return 1.0;
  Eigen::Vector3d velocity_mps;
  Eigen::Vector3d angular_radps;
  engine_.velocity(id, velocity_mps, angular_radps);
  // The work booked after the substep, h·F·(v₀+v₁)/2 with v₁ = v₀ + h·(F/m + g) on a free body, is α·a + α²·b
  // (header). Several pushes on one body in a substep share the budget, each taken at the velocity now.
  const ObjectState& state = states_[id];
  const Eigen::Vector3d mid_fall_mps = velocity_mps + 0.5 * substep_s * gravity_mps2_;
  const double a = substep_s * (force_N.dot(mid_fall_mps) + torque_Nm.dot(angular_radps));
  const double b = 0.5 * substep_s * substep_s *
                   (state.inverse_mass_per_kg * force_N.squaredNorm() +
                    torque_Nm.dot(state.inverse_inertia_world * torque_Nm));
  const double full_J = a + b;
  const double alpha = full_J > budget_J(id) ? admitted_share(a, b, budget_J(id)) : 1.0;
  if (alpha < 1.0) {
    count(id, full_J - (alpha * a + alpha * alpha * b), 0.0, (1.0 - alpha) * force_N.norm() * substep_s);
  }
  admitted_J_[id] += std::max(0.0, alpha * a + alpha * alpha * b);
  return alpha;
}

void PassivityLayer::record_velocity_change(std::size_t id, const Eigen::Vector3d& impulse_Ns,
                                            const Eigen::Vector3d& angular_impulse_Nms, const Eigen::Vector3d& v0_mps,
                                            const Eigen::Vector3d& w0_radps, const Eigen::Vector3d& v1_mps,
                                            const Eigen::Vector3d& w1_radps) {
  // ½m(v₁² − v₀²) = J·(v₀+v₁)/2 for v₁ = v₀ + J/m; likewise ½(ω₁ᵀIω₁ − ω₀ᵀIω₀) = L·(ω₀+ω₁)/2 for ω₁ = ω₀ + I⁻¹L.
  books_[id].port_work_J += 0.5 * (impulse_Ns.dot(v0_mps + v1_mps) + angular_impulse_Nms.dot(w0_radps + w1_radps));
  touch(id);
}

void PassivityLayer::record_force(std::size_t id, const Eigen::Vector3d& force_N, const Eigen::Vector3d& torque_Nm) {
  if (!is_forced_[id]) {
    is_forced_[id] = true;
    forced_.push_back(id);
    engine_.velocity(id, velocity_before_mps_[id], angular_before_radps_[id]);  // the substep has not run yet
  }
  force_N_[id] += force_N;
  torque_Nm_[id] += torque_Nm;
}

void PassivityLayer::after_substep(double substep_s) {
  for (const std::size_t id : forced_) {
    Eigen::Vector3d velocity_mps;
    Eigen::Vector3d angular_radps;
    engine_.velocity(id, velocity_mps, angular_radps);
    // h·F·(v₀+v₁)/2: the kinetic energy the held force gives a free body in the substep, exactly (header).
    books_[id].port_work_J += 0.5 * substep_s *
                              (force_N_[id].dot(velocity_before_mps_[id] + velocity_mps) +
                               torque_Nm_[id].dot(angular_before_radps_[id] + angular_radps));
    force_N_[id].setZero();
    torque_Nm_[id].setZero();
    admitted_J_[id] = 0.0;
    is_forced_[id] = false;
    touch(id);
  }
  forced_.clear();
  settle();
}

void PassivityLayer::settle() {
  for (const std::size_t id : touched_) {
    is_touched_[id] = false;
    if (!enabled_) continue;
    enforce(id);
    low_water_J_[id] = std::min(low_water_J_[id], budget_J(id));
  }
  touched_.clear();
}

void PassivityLayer::enforce(std::size_t id) {
  PortEnergy& books = books_[id];
  const double excess_J = books.port_work_J + books.returned_J - books.hand_input_J;
  if (!(excess_J > 0.0)) return;
  // Level again whatever happens: what the damper cannot take is counted as unrecovered (header, stage 2).
  books.port_work_J -= excess_J;
  ObjectState now;
  engine_.read_state(id, now);
  const double inverse_mass_per_kg = states_[id].inverse_mass_per_kg;
  double kinetic_J = 0.0;
  double mass_kg = 0.0;
  if (inverse_mass_per_kg > 0.0) {
    mass_kg = 1.0 / inverse_mass_per_kg;
    const Eigen::Matrix3d rotation = now.pose.orientation.toRotationMatrix();
    const Eigen::Matrix3d inertia_world = rotation * engine_.inverse_inertia_body(id).inverse() * rotation.transpose();
    kinetic_J = 0.5 * mass_kg * now.velocity_mps.squaredNorm() +
                0.5 * now.angular_velocity_radps.dot(inertia_world * now.angular_velocity_radps);
  }
  const double taken_J = std::isfinite(kinetic_J) && kinetic_J > 0.0 ? std::min(excess_J, kinetic_J) : 0.0;
  books.unrecovered_J += excess_J - taken_J;
  if (!(taken_J > 0.0)) return;
  // Scaling both velocities by λ scales the kinetic energy by λ²: λ² = 1 − taken/KE removes exactly what is taken.
  const double lambda = std::sqrt(std::max(0.0, 1.0 - taken_J / kinetic_J));
  engine_.set_velocity(id, lambda * now.velocity_mps, lambda * now.angular_velocity_radps);
  count(id, 0.0, taken_J, (1.0 - lambda) * mass_kg * now.velocity_mps.norm());
}

double PassivityLayer::return_unspent(std::size_t id) {
  if (!enabled_) return 0.0;
  // What sat unspent through the whole step (its low-water mark) goes back; what came in or was freed during the
  // step stays for the next.
  const double budget = budget_J(id);
  const double now_J = std::isfinite(budget) ? budget : 0.0;
  const double given_J = std::max(0.0, std::min(now_J, low_water_J_[id]));
  books_[id].returned_J += given_J;
  low_water_J_[id] = std::max(0.0, now_J - given_J);
  return given_J;
}

PortEnergy PassivityLayer::total() const {
  PortEnergy sum;
  for (const PortEnergy& books : books_) {
    sum.hand_input_J += books.hand_input_J;
    sum.port_work_J += books.port_work_J;
    sum.withheld_J += books.withheld_J;
    sum.damped_J += books.damped_J;
    sum.removed_impulse_Ns += books.removed_impulse_Ns;
    sum.unrecovered_J += books.unrecovered_J;
    sum.returned_J += books.returned_J;
    sum.interventions += books.interventions;
  }
  return sum;
}

}  // namespace impetus

// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/tool/tool_proxy.h"

#include "common/contract/rotation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace impetus {
namespace {

static_assert(kMaxToolConstraints == kMaxContactRows);

// Rounding room for the reach of a pass: the bound itself is exact (below), this only keeps a contact exactly at it.
constexpr double kReachRounding_m = 1e-9;
// A contact within this of the proxy touches it (kOnSurface_m, common/shape/shape.h).
constexpr double kTouching_m = kOnSurface_m;

void require(bool ok, const char* field, const char* rule) {
  if (!ok) throw std::invalid_argument(std::string("tool coupling: ") + field + " " + rule);
}

bool finite(const BodyPose& pose) {
  return pose.position_m.allFinite() && pose.orientation.coeffs().allFinite() && pose.orientation.norm() > 0.0;
}

// e = (x_p − x_d, θ): the proxy's displacement from the grip, θ the turn that takes the grip's orientation to the
// proxy's.
Vector6d displacement(const BodyPose& proxy, const BodyPose& grip) {
  Vector6d e;
  e.head<3>() = proxy.position_m - grip.position_m;
  e.tail<3>() = turn_between(grip.orientation, proxy.orientation);
  return e;
}

}  // namespace

ToolProxy::ToolProxy(const ToolShape& tool, const ToolCoupling& coupling)
    : contacts_(tool), coupling_(coupling), weight_N_(tool.weight_N), centre_of_mass_m_(tool.placement.position_m) {
  if (!(tool.mass_kg >= 0.0) || !std::isfinite(tool.mass_kg)) {
    throw std::invalid_argument("tool: mass_kg must be >= 0 and finite");
  }
  if (!tool.weight_N.allFinite()) throw std::invalid_argument("tool: weight_N must be finite");
  const ToolCoupling& c = coupling;
  require(std::isfinite(c.stiffness_Npm) && c.stiffness_Npm > 0.0, "stiffness_Npm", "must be > 0");
  require(std::isfinite(c.rotational_stiffness_Nmprad) && c.rotational_stiffness_Nmprad > 0.0,
          "rotational_stiffness_Nmprad", "must be > 0");
  require(std::isfinite(c.damping_Nspm) && c.damping_Nspm >= 0.0, "damping_Nspm", "must be >= 0");
  require(std::isfinite(c.rotational_damping_Nmsprad) && c.rotational_damping_Nmsprad >= 0.0,
          "rotational_damping_Nmsprad", "must be >= 0");
  require(c.max_force_N > 0.0 && !std::isnan(c.max_force_N), "max_force_N", "must be > 0");
  require(c.max_torque_Nm > 0.0 && !std::isnan(c.max_torque_Nm), "max_torque_Nm", "must be > 0");
}

void ToolProxy::reset(const BodyPose& grip) {
  proxy_ = {grip.position_m, grip.orientation.normalized()};
  grip_ = proxy_;
  hold_release_s_ = std::numeric_limits<double>::infinity();
  hold_limit_count_ = 0;
  started_ = finite(proxy_);
  previous_displacement_.setZero();
  hold_next_ = true;
  held_count_ = 0;
  grip_velocity_mps_.setZero();
  grip_angular_velocity_radps_.setZero();
  zero_output();
}

void ToolProxy::zero_output() {
  force_count_ = 0;
  share_count_ = 0;
  result_ = ToolResult{};
  result_.proxy = proxy_;
}

const ToolResult& ToolProxy::solve(const PlaneSet& planes, const BodyPose& grip_in, double dt_s) {
  ++counters_.solves;
  const BodyPose grip{grip_in.position_m, grip_in.orientation.normalized()};
  if (!finite(grip) || !(dt_s > 0.0) || !std::isfinite(dt_s)) {
    ++counters_.faults;
    zero_output();
    result_.fault = true;
    return result_;
  }
  if (!started_) reset(grip);
  const bool mark_held = hold_next_;
  hold_next_ = false;
  for (int s = held_count_ - 1; s >= 0; --s) {
    Held& held = held_[static_cast<std::size_t>(s)];
    held.depth_m -= held.release_mps * dt_s;
    if (!(held.depth_m > 0.0)) held = held_[static_cast<std::size_t>(--held_count_)];
  }
  grip_velocity_mps_ = (grip.position_m - grip_.position_m) / dt_s;
  grip_angular_velocity_radps_ = turn_between(grip_.orientation, grip.orientation) / dt_s;
  grip_ = grip;

  const BodyPose goal = goal_of(grip);
  // Nothing in the way: the proxy is at its goal, and the wrench is the weight alone (a tool that leaves a surface
  // lets go at once).
  if (contacts_.path_clear(planes, proxy_, goal)) {
    proxy_ = goal;
    previous_displacement_.setZero();
    held_count_ = 0;
    zero_output();
    set_wrench(grip);  // finite: the weight is
    return result_;
  }
  const BodyPose proxy_before = proxy_;
  result_ = ToolResult{};
  failed_ = false;
  // The god-object: the pose nearest the grip in the springs' metric that the contacts allow; again from where a
  // pass put it while a contact acts and the pass still moved the tool (the linearised turn and curved surfaces are
  // exact only for a move that vanishes). The first pass gathers the contacts within its reach; a later one measures
  // the same ones again where the tool now is, unless the passes together have moved the tool farther than that
  // reach (then some other contact may have come within it, and the pass is made again from a new gathering).
  double travelled_m = 0.0, turned_rad = 0.0;
  Vector6d last_move = Vector6d::Zero();
  for (int p = 0; p < kMaxToolPasses; ++p) {
    const Vector6d target = -displacement(proxy_, goal);
    const BodyPose before = proxy_;
    Vector6d q;
    if (p > 0) {
      contacts_.refresh(planes, proxy_, gathered_);
      q = pass(planes, target, false, false);
      travelled_m += q.head<3>().norm();
      turned_rad += q.tail<3>().norm();
    }
    if (p == 0 || travelled_m > gathered_.linear_m || turned_rad > gathered_.angular_rad) {
      proxy_ = before;
      q = pass(planes, target, true, mark_held && p == 0);
      travelled_m = q.head<3>().norm();
      turned_rad = q.tail<3>().norm();
    }
    last_move = q;
    const double moved_m = q.head<3>().norm() + q.tail<3>().norm() * contacts_.bounding_radius_m();
    if (failed_ || result_.active == 0 || moved_m <= kToolSettled_m) break;
  }
  release_held(last_move);
  const Vector6d e = displacement(proxy_, goal);
  damp(e, dt_s);
  previous_displacement_ = e;
  if (!set_wrench(grip)) {
    ++counters_.faults;
    proxy_ = proxy_before;
    zero_output();
    result_.fault = true;
    return result_;
  }
  share_reaction(planes, grip, dt_s);
  return result_;
}

BodyPose ToolProxy::goal_of(const BodyPose& grip) const {
  if (weight_N_.isZero()) return grip;
  // The sag K⁻¹·W, the weight's torque taken about the grip's centre at the grip's orientation (the sag's own turn
  // changes it by k_r⁻¹ times less: 10⁻³ rad for a 50 g tool at 3 cm).
  const Eigen::Vector3d torque_Nm = (grip.orientation * centre_of_mass_m_).cross(weight_N_);
  return {grip.position_m + weight_N_ / coupling_.stiffness_Npm,
          turned(grip.orientation, torque_Nm / coupling_.rotational_stiffness_Nmprad)};
}

bool ToolProxy::set_wrench(const BodyPose& grip) {
  // The contacts' pushes, carried by the massless proxy: their sum, and their moments about the grip's centre at the
  // points where the objects receive them (the tool's and the object's points of a contact differ only along its
  // normal, so the world's torque and the hand's cancel exactly). The weight acts at the proxy's centre of mass.
  Eigen::Vector3d force_N = weight_N_;
  Eigen::Vector3d weight_torque_Nm = Eigen::Vector3d::Zero();
  if (!weight_N_.isZero()) {
    const Eigen::Vector3d centre_m = proxy_.position_m + proxy_.orientation * centre_of_mass_m_;
    weight_torque_Nm = (centre_m - grip.position_m).cross(weight_N_);
  }
  Eigen::Vector3d torque_Nm = weight_torque_Nm;
  for (int k = 0; k < force_count_; ++k) {
    const ToolContactForce& f = forces_[static_cast<std::size_t>(k)];
    force_N += f.force_N * f.normal;
    torque_Nm += (f.tool_point_m - grip.position_m).cross(f.force_N * f.normal);
  }
  if (!force_N.allFinite() || !torque_Nm.allFinite() || !finite(proxy_)) return false;
  // The limits scale the whole wrench, the weight with the pushes, so the objects receive the scaled pushes.
  double scale = 1.0;
  if (force_N.norm() > coupling_.max_force_N) scale = coupling_.max_force_N / force_N.norm();
  if (scale * torque_Nm.norm() > coupling_.max_torque_Nm) scale = coupling_.max_torque_Nm / torque_Nm.norm();
  if (scale < 1.0) {
    ++counters_.clamps;
    for (int k = 0; k < force_count_; ++k) forces_[static_cast<std::size_t>(k)].force_N *= scale;
  }
  result_.force_N = scale * force_N;
  result_.torque_Nm = scale * torque_Nm;
  result_.weight_force_N = scale * weight_N_;
  result_.weight_torque_Nm = scale * weight_torque_Nm;
  result_.scale = scale;
  result_.proxy = proxy_;
  return true;
}

void ToolProxy::damp(const Vector6d& displacement_now, double dt_s) {
  // The spring's wrench K·e is Σ λ_i·a_i (the pass's multipliers). The damper adds B·(e − e_prev)/Δt; the sum is
  // projected onto the cone of the acting contacts' pushes {Σ μ_i·a_i : μ_i ≥ 0}: a contact pushes, it never pulls,
  // so the damper brakes an approach but does not drag the tool after a surface it leaves (force_renderer.h in 3 DoF).
  // The projection is the polar decomposition w = Σ μ_i·a_i + u with a_iᵀu ≤ 0 (Moreau), solved as the QP of
  // contact_qp.h for u, in units scaled by the stiffnesses (force/√k, torque/√k_r) so force and torque weigh alike.
  // After a pass that failed (pass()), the spring's wrench is K·e at the unmoved proxy, and the acting contacts are
  // those it touches.
  Vector6d spring = Vector6d::Zero();
  int acting = 0;
  for (int k = 0; k < contacts_.count(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (failed_ ? rows_[i].gap_m > kTouching_m : !(lambda_[i] > 0.0)) continue;
    spring += lambda_[i] * rows_[i].a;
    acting_[static_cast<std::size_t>(acting++)] = k;
  }
  if (failed_) {
    spring.head<3>() = coupling_.stiffness_Npm * displacement_now.head<3>();
    spring.tail<3>() = coupling_.rotational_stiffness_Nmprad * displacement_now.tail<3>();
  }
  const Vector6d rate = (displacement_now - previous_displacement_) / dt_s;
  Vector6d wrench = spring;
  wrench.head<3>() += coupling_.damping_Nspm * rate.head<3>();
  wrench.tail<3>() += coupling_.rotational_damping_Nmsprad * rate.tail<3>();
  Vector6d unit_scale;
  const double force_scale = 1.0 / std::sqrt(coupling_.stiffness_Npm);
  const double torque_scale = 1.0 / std::sqrt(coupling_.rotational_stiffness_Nmprad);
  unit_scale << force_scale, force_scale, force_scale, torque_scale, torque_scale, torque_scale;
  for (int j = 0; j < acting; ++j) {
    ContactQpRow& row = cone_rows_[static_cast<std::size_t>(j)];
    row.a = -rows_[static_cast<std::size_t>(acting_[static_cast<std::size_t>(j)])].a.cwiseProduct(unit_scale);
    row.gap_m = 0.0;
  }
  const ContactQpResult projected =
      solve_contact_qp(cone_rows_, acting, Vector6d::Ones(), wrench.cwiseProduct(unit_scale), mu_);
  if (!projected.converged) ++counters_.unconverged;
  force_count_ = 0;
  for (int j = 0; j < acting; ++j) {
    const double mu_N = mu_[static_cast<std::size_t>(j)];
    if (!(mu_N > 0.0)) continue;
    const ToolConstraint& c = contacts_[acting_[static_cast<std::size_t>(j)]];
    forces_[static_cast<std::size_t>(force_count_++)] = {c.plane, c.object_id, c.normal, c.tool_point_m,
                                                         c.object_point_m, mu_N};
  }
}

Vector6d ToolProxy::pass(const PlaneSet& planes, const Vector6d& target, bool gather, bool mark_held) {
  const double k_Npm = coupling_.stiffness_Npm;
  const double k_r_Nmprad = coupling_.rotational_stiffness_Nmprad;
  // The move q minimises ½(q − q*)ᵀK(q − q*) over a convex set that holds q = 0 (every gap is kept ≥ 0), so
  // |q|_K ≤ |q*|_K (projection onto it does not lengthen): the proxy moves at most |q*|_K/√k and turns at most
  // |q*|_K/√k_r, and a contact farther than that cannot act in this pass.
  const double reach_K =
      std::sqrt(k_Npm * target.head<3>().squaredNorm() + k_r_Nmprad * target.tail<3>().squaredNorm());
  int count = contacts_.count();
  if (gather) {
    ToolReach reach{reach_K / std::sqrt(k_Npm) + kReachRounding_m, reach_K / std::sqrt(k_r_Nmprad)};
    count = contacts_.gather(planes, proxy_, reach);
    if (mark_held) {
      // An object may hold at most what the proxy was already allowed in it plus how far the jump moved it.
      for (int h = 0; h < hold_limit_count_; ++h) {
        Held& limit = hold_limits_[static_cast<std::size_t>(h)];
        limit.depth_m += allowance_m(limit.object_id);
      }
      for (int k = 0; k < count; ++k) {
        if (!(contacts_[k].gap_m < 0.0)) continue;
        double most_m = -contacts_[k].gap_m;
        for (int h = 0; h < hold_limit_count_; ++h) {
          const Held& limit = hold_limits_[static_cast<std::size_t>(h)];
          if (limit.object_id == contacts_[k].object_id) most_m = std::min(most_m, limit.depth_m);
        }
        if (most_m > 0.0) hold(contacts_[k].object_id, most_m);
      }
    }
    // A body the proxy is inside beyond its allowance (one that came onto the tool, or the last pass's linearised
    // turn) pushes it out: the move may then be longer by the depth (twice it, for a push-out between oblique faces).
    double deepest_m = 0.0;
    for (int k = 0; k < count; ++k) {
      deepest_m = std::max(deepest_m, -(contacts_[k].gap_m + allowance_m(contacts_[k].object_id)));
    }
    if (deepest_m > 0.0) {
      reach.linear_m += 2.0 * deepest_m;
      // Gathered again only if a feature left out missed the reach by less than it grew (most such overlaps are the
      // last pass's linearised turn, nanometres deep).
      if (!contacts_.complete_for_growth(2.0 * deepest_m)) count = contacts_.gather(planes, proxy_, reach);
    }
    gathered_ = reach;
    ++result_.gathers;
  }

  // Rows a = [n; r × n]. A held body's gap is taken less its allowance, up to 0: the proxy may stay as deep in it as
  // the allowance, no deeper, and is not thrown out (energy nobody put in).
  for (int k = 0; k < count; ++k) {
    const ToolConstraint& c = contacts_[k];
    ContactQpRow& row = rows_[static_cast<std::size_t>(k)];
    row.a.head<3>() = c.normal;
    row.a.tail<3>() = (c.tool_point_m - proxy_.position_m).cross(c.normal);
    const double allowance = allowance_m(c.object_id);
    row.gap_m = allowance > 0.0 ? std::min(std::max(c.gap_m, 0.0), c.gap_m + allowance) : c.gap_m;
  }
  Vector6d metric;
  metric << k_Npm, k_Npm, k_Npm, k_r_Nmprad, k_r_Nmprad, k_r_Nmprad;
  ContactQpResult solved = solve_contact_qp(rows_, count, metric, target, lambda_);
  result_.constraints = count;
  result_.passes += 1;
  result_.iterations += solved.iterations;
  if (!solved.converged) {
    // No move satisfies the contacts as linearised: the proxy is in a pinch, inside contacts that face each other
    // (a curved surface's linearisation left it a little inside two). Taken with every gap kept ≥ 0 the problem has
    // q = 0 and so an answer: the proxy goes no deeper into any of them this tick.
    for (int k = 0; k < count; ++k) {
      ContactQpRow& row = rows_[static_cast<std::size_t>(k)];
      row.gap_m = std::max(row.gap_m, 0.0);
    }
    solved = solve_contact_qp(rows_, count, metric, target, lambda_);
    result_.iterations += solved.iterations;
    ++counters_.pinches;
  }
  if (!solved.converged) {
    // Rounding stalled the method: the proxy stays where it was, outside, and the contacts it touches there carry
    // the wrench (damp()).
    ++counters_.unconverged;
    result_.converged = false;
    failed_ = true;
    for (int k = 0; k < count; ++k) lambda_[static_cast<std::size_t>(k)] = 0.0;
    result_.active = 0;
    return Vector6d::Zero();
  }
  proxy_.position_m += solved.q.head<3>();
  proxy_.orientation = turned(proxy_.orientation, solved.q.tail<3>());

  result_.active = solved.active;
  return solved.q;
}

double ToolProxy::allowance_m(std::int32_t object_id) const {
  for (int k = 0; k < held_count_; ++k) {
    if (held_[static_cast<std::size_t>(k)].object_id == object_id) return held_[static_cast<std::size_t>(k)].depth_m;
  }
  return 0.0;
}

void ToolProxy::hold(std::int32_t object_id, double depth_m) {
  for (int k = 0; k < held_count_; ++k) {
    Held& held = held_[static_cast<std::size_t>(k)];
    if (held.object_id != object_id) continue;
    held.depth_m = std::max(held.depth_m, depth_m);
    held.release_mps = std::isfinite(hold_release_s_) ? held.depth_m / hold_release_s_ : 0.0;
    return;
  }
  if (held_count_ == static_cast<int>(held_.size())) return;
  const double release_mps = std::isfinite(hold_release_s_) ? depth_m / hold_release_s_ : 0.0;
  held_[static_cast<std::size_t>(held_count_++)] = {object_id, depth_m, release_mps};
}

void ToolProxy::release_held(const Vector6d& last_move) {
  // The depth the proxy has in each held object after the last pass's move: its contacts' gaps as measured before
  // the move, carried by it to first order (gap + a·q).
  for (int s = held_count_ - 1; s >= 0; --s) {
    Held& held = held_[static_cast<std::size_t>(s)];
    double depth_m = 0.0;
    for (int k = 0; k < contacts_.count(); ++k) {
      if (contacts_[k].object_id != held.object_id) continue;
      depth_m = std::max(depth_m, -(contacts_[k].gap_m + rows_[static_cast<std::size_t>(k)].a.dot(last_move)));
    }
    held.depth_m = std::min(held.depth_m, depth_m);
    if (!(held.depth_m > 0.0)) held = held_[static_cast<std::size_t>(--held_count_)];
  }
}

void ToolProxy::share_reaction(const PlaneSet& planes, const BodyPose& grip, double dt_s) {
  share_count_ = 0;
  for (int k = 0; k < force_count_; ++k) {
    const ToolContactForce& f = forces_[static_cast<std::size_t>(k)];
    const ContactPlane& plane = planes.planes[static_cast<std::size_t>(f.plane)];
    const Eigen::Vector3d impulse_Ns = -f.force_N * dt_s * f.normal;  // the user's push on the object (§3.4)
    const Eigen::Vector3d centre_m = object_centre(plane);
    const Eigen::Vector3d angular_Nms = (f.object_point_m - centre_m).cross(impulse_Ns);
    // The hand's work behind the push: the grip's velocity at the contact, over the tick.
    const Eigen::Vector3d hand_velocity_mps =
        grip_velocity_mps_ + grip_angular_velocity_radps_.cross(f.tool_point_m - grip.position_m);
    const double credit_J = std::max(0.0, impulse_Ns.dot(hand_velocity_mps));
    int s = 0;
    while (s < share_count_ && shares_[static_cast<std::size_t>(s)].object_id != f.object_id) ++s;
    if (s == share_count_) {
      if (share_count_ == static_cast<int>(shares_.size())) continue;  // cannot happen: one object per plane at most
      ImpulseShare& fresh = shares_[static_cast<std::size_t>(share_count_++)];
      fresh = ImpulseShare{};
      fresh.object_id = f.object_id;
      fresh.dynamic = plane.dynamic();
    }
    ImpulseShare& share = shares_[static_cast<std::size_t>(s)];
    share.impulse_Ns += impulse_Ns;
    share.angular_impulse_Nms += angular_Nms;
    share.credit_J += credit_J;
  }
}

}  // namespace impetus

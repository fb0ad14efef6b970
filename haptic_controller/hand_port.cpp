// SPDX-License-Identifier: Apache-2.0
#include "haptic_controller/hand_port.h"

#include <algorithm>
#include <cmath>

namespace impetus {

void HandPort::on_plane_frame(const PlaneFrame& frame) {
  active_ = frame.port_layer != 0;
  const double total_J = std::isfinite(frame.port_returned_J) ? frame.port_returned_J : returned_seen_J_;
  if (!have_baseline_ || frame.world_session != world_session_) {
    // A new world (or the first frame): its running total starts from whatever it handed out before we came.
    have_baseline_ = true;
    world_session_ = frame.world_session;
    returned_seen_J_ = total_J;
    return;
  }
  if (active_ && total_J > returned_seen_J_) books_.returned_J += total_J - returned_seen_J_;
  returned_seen_J_ = std::max(returned_seen_J_, total_J);
}

HandPortTick HandPort::tick(const Eigen::Vector3d& force_N, const Eigen::Vector3d* displacement_m,
                            bool pushing_dynamic, double stored_J) {
  HandPortTick out{force_N, 0.0};
  if (!active_) {
    holding_ = false;
    return out;
  }
  const bool known = displacement_m != nullptr && displacement_m->allFinite();
  if (known && holding_) {
    // What the finger received under the force held since the last tick (header).
    const double work_J = command_N_.dot(*displacement_m);
    books_.input_J += std::max(0.0, -work_J);
    books_.output_J += std::max(0.0, work_J);
    books_.damped_J += (contact_N_ - command_N_).dot(*displacement_m);
  }
  // Step 1, the damper, on the prediction that the finger moves as it did.
  double predicted_J = 0.0;
  if (known) {
    predicted_J = force_N.dot(*displacement_m);
    const double available_J = std::max(0.0, books_.reservoir_J());
    if (predicted_J > available_J && std::isfinite(predicted_J)) {
      const double squared_m2 = displacement_m->squaredNorm();
      out.force_N = force_N - ((predicted_J - available_J) / squared_m2) * *displacement_m;
      predicted_J = available_J;
      ++books_.interventions;
    }
  }
  // Step 2, the credit: what neither the spring nor the coming tick needs.
  if (pushing_dynamic) {
    const double reserve_J = (std::isfinite(stored_J) ? std::max(0.0, stored_J) : 0.0) + std::max(0.0, predicted_J);
    const double surplus_J = books_.reservoir_J() - reserve_J;
    if (surplus_J > 0.0 && std::isfinite(surplus_J)) out.credit_J = surplus_J;
  }
  holding_ = out.force_N.allFinite();
  contact_N_ = force_N;
  command_N_ = out.force_N;
  return out;
}

void HandPort::idle() { holding_ = false; }

void HandPort::credit(double credited_J) {
  if (active_ && credited_J > 0.0 && std::isfinite(credited_J)) books_.credited_J += credited_J;
}

}  // namespace impetus

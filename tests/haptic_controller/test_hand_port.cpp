// SPDX-License-Identifier: Apache-2.0
// The passivity layer's half at the hand (haptic_controller/hand_port.h): the finger receives no more than it put in
// and the world handed back, booked exactly for a force held over each tick.
#include "haptic_controller/hand_port.h"

#include <catch2/catch.hpp>

#include <cmath>

using impetus::HandPort;
using impetus::HandPortTick;
using impetus::PlaneFrame;
using Eigen::Vector3d;

namespace {

PlaneFrame frame(bool layer, double returned_J, std::uint64_t world_session = 1) {
  PlaneFrame f{};
  f.world_session = world_session;
  f.port_layer = layer ? 1 : 0;
  f.port_returned_J = returned_J;
  return f;
}

// The energy the finger received under the forces commanded, Σ f'_{k−1}·Δx_k (what the books must hold exactly).
struct Finger {
  Vector3d held_N = Vector3d::Zero();
  double received_J = 0.0;
  HandPortTick tick(HandPort& port, const Vector3d& force_N, const Vector3d& step_m, bool pushing, double stored_J) {
    received_J += held_N.dot(step_m);
    const HandPortTick out = port.tick(force_N, &step_m, pushing, stored_J);
    held_N = out.force_N;
    return out;
  }
};

}  // namespace

TEST_CASE("the hand port changes nothing and books nothing with the layer off") {
  HandPort port;
  port.on_plane_frame(frame(false, 0.0));
  const Vector3d step_m(0.0, 0.0, 1e-4);
  const HandPortTick out = port.tick(Vector3d(0.0, 0.0, 5.0), &step_m, true, 0.0);
  CHECK(out.force_N == Vector3d(0.0, 0.0, 5.0));
  CHECK(out.credit_J == 0.0);
  CHECK(port.books().output_J == 0.0);
  CHECK(port.books().interventions == 0);
}

TEST_CASE("a plane pushing a finger that put nothing in gives it nothing: the damper takes the force along its way") {
  HandPort port;
  port.on_plane_frame(frame(true, 0.0));
  Finger finger;
  // The finger moves away along +z at 0.1 m/s while the force pushes it that way (an object arriving at it).
  for (int k = 0; k < 50; ++k) {
    const HandPortTick out = finger.tick(port, Vector3d(1.0, 0.0, 8.0), Vector3d(0.0, 0.0, 1e-4), false, 0.0);
    CHECK(out.force_N.z() == Approx(0.0).margin(1e-12));  // the part along the motion is gone
    CHECK(out.force_N.x() == Approx(1.0).epsilon(1e-12));  // the part across it does no work and stays
  }
  CHECK(finger.received_J == Approx(0.0).margin(1e-15));
  CHECK(port.books().damped_J == Approx(49 * 8.0 * 1e-4).epsilon(1e-9));
  CHECK(port.books().interventions == 50);
}

TEST_CASE("a finger that pressed in gets back what it put in, and no more") {
  HandPort port;
  port.on_plane_frame(frame(true, 0.0));
  Finger finger;
  // Press: 20 ticks in along −z against a spring force growing to 4 N (input), then 40 ticks out with the force
  // unchanged as if the wall had moved in behind it (output twice the input without the port).
  for (int k = 1; k <= 20; ++k) finger.tick(port, Vector3d(0.0, 0.0, 0.2 * k), Vector3d(0.0, 0.0, -1e-4), false, 0.0);
  const double input_J = port.books().input_J;
  CHECK(input_J > 0.0);
  for (int k = 0; k < 40; ++k) finger.tick(port, Vector3d(0.0, 0.0, 4.0), Vector3d(0.0, 0.0, 1e-4), false, 0.0);
  // Exact books: what the finger received is input less output, and it gave out at most what it put in.
  CHECK(-finger.received_J == Approx(port.books().input_J - port.books().output_J).margin(1e-15));
  CHECK(port.books().output_J <= port.books().input_J + 1e-15);
  CHECK(port.books().output_J == Approx(port.books().input_J).epsilon(1e-9));  // it does get all of it back
  CHECK(port.books().reservoir_J() >= -1e-15);
}

TEST_CASE("what the world hands back lets the force push the finger once, and the first frame is a baseline") {
  HandPort port;
  port.on_plane_frame(frame(true, 0.7));  // an earlier owner of the slot was handed 0.7 J: not ours
  CHECK(port.books().returned_J == 0.0);
  port.on_plane_frame(frame(true, 0.7 + 0.002));
  CHECK(port.books().returned_J == Approx(0.002).epsilon(1e-9));
  Finger finger;
  for (int k = 0; k < 10; ++k) finger.tick(port, Vector3d(0.0, 0.0, 5.0), Vector3d(0.0, 0.0, 1e-4), false, 0.0);
  // 0.5 mJ a tick: the first four ticks go through whole, the rest is damped.
  CHECK(finger.received_J == Approx(0.002).epsilon(1e-9));
  CHECK(port.books().reservoir_J() == Approx(0.0).margin(1e-15));
  // The same total again adds nothing; a new world's total is a new baseline.
  port.on_plane_frame(frame(true, 0.702));
  port.on_plane_frame(frame(true, 5.0, 2));
  CHECK(port.books().returned_J == Approx(0.002).epsilon(1e-9));
}

TEST_CASE("the hand keeps its spring's stored energy and sends the rest behind a push on a dynamic object") {
  HandPort port;
  port.on_plane_frame(frame(true, 0.0));
  port.on_plane_frame(frame(true, 0.010));  // 10 mJ handed back
  const Vector3d still_m = Vector3d::Zero();
  const HandPortTick no_push = port.tick(Vector3d(0.0, 0.0, 2.0), &still_m, false, 0.001);
  CHECK(no_push.credit_J == 0.0);  // nothing pushed that the world could credit
  const HandPortTick push = port.tick(Vector3d(0.0, 0.0, 2.0), &still_m, true, 0.001);
  CHECK(push.credit_J == Approx(0.009).epsilon(1e-12));
  port.credit(push.credit_J);
  CHECK(port.books().reservoir_J() == Approx(0.001).epsilon(1e-9));
  // An unknown displacement (the finger was away) books nothing and predicts nothing.
  const HandPortTick away = port.tick(Vector3d(0.0, 0.0, 2.0), nullptr, true, 0.0);
  CHECK(away.force_N == Vector3d(0.0, 0.0, 2.0));
  CHECK(away.credit_J == Approx(0.001).epsilon(1e-9));
}

# SPDX-License-Identifier: Apache-2.0
"""Mechanical energy of a trial's finger and rigid bodies, and the work the hand does on the finger: the energy
balance every hard case is checked against (energy_balance)."""
import math

import numpy as np


# ODE contact depth allowance for the energy tolerance (see energy_balance): ODE's steady contact compliance under
# these loads is micrometres (k = ERP/(h CFM) = 4e6 N/m at h = 5 ms); 1 mm is the transient depth v·h of a body meeting
# a surface at 0.2 m/s with 5 ms substeps, faster than anything in the hard cases meets the floor.
CONTACT_SLOP_M = 1e-3


def mass_and_inertia(body):
    """Mass (kg) and principal moments of inertia (kg·m²) about the centre of mass, in the body frame, of a dynamic
    body as the world simulated it: its entry in summary.json's "objects" (mass_kg, inertia_kgm2, which the world
    takes from its shape, common/shape/shape.h), whatever its shape."""
    return float(body["mass_kg"]), tuple(float(x) for x in body["inertia_kgm2"])


def rotate_to_body(q_wxyz, w):
    """World-frame vectors w (n x 3) in the body frames of the unit quaternions q_wxyz (n x 4, body -> world):
    R^T w = conj(q) w q, computed as t = 2 (-q_v × w), w' = w + q_w t + (-q_v × t)."""
    qw = q_wxyz[:, 0]
    v = -q_wxyz[:, 1:]
    t = 2 * np.cross(v, w)
    return w + qw[:, None] * t + np.cross(v, t)


def _dot3(a, b):
    """Row-wise a · b of n x 3 arrays, summed x + y + z in that order."""
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def object_energy_J(body, gravity_mps2, position_m, orientation_wxyz, velocity_mps, omega_radps):
    """Kinetic plus potential energy (J) of a dynamic body (its summary entry, mass_and_inertia) in each of n states
    (n x 3 arrays, n x 4 for the orientation; world frame): 1/2 m v² + 1/2 ω_b · I ω_b - m g · p, with ω_b the angular
    velocity in the body frame."""
    mass, inertia = mass_and_inertia(body)
    wb = rotate_to_body(orientation_wxyz, omega_radps)
    kinetic = 0.5 * mass * _dot3(velocity_mps, velocity_mps) + 0.5 * _dot3(np.asarray(inertia) * wb, wb)
    potential = -mass * _dot3(np.broadcast_to(np.asarray(gravity_mps2, dtype=float), position_m.shape), position_m)
    return kinetic + potential


def _initial_energy_J(obj, body, gravity_mps2):
    """object_energy_J of scene object `obj` (its summary entry `body`) in its state in the scene file."""
    return object_energy_J(body, gravity_mps2, *(np.array([obj[key]], dtype=float) for key in (
        "position_m", "orientation_wxyz", "linear_velocity_mps", "angular_velocity_radps")))[0]


def energy_balance(scene, bodies, device, world, finger, world_period_s, haptic_period_s):
    """Energy of finger + dynamic objects against the hand's work, from a trial's scene (scene.Scene), its bodies'
    mass properties (the summary's "objects"), device log (or the list of a several-finger device's logs, one per
    finger) and world log (logs.Log) and the finger and hand it ran with (the summary's "device" section:
    finger_mass_kg, hand_stiffness_Npm, hand_damping_Nspm).

    The system is the finger (point mass m_f) and the dynamic objects. External forces on it: the hand
    F_hand = k_h (target - x) + b_h (target_v - v), gravity (counted as potential energy), the static geometry
    (floor, static boxes; they do no work on a body at rest against them and dissipate otherwise). The device force
    f on the finger and the reaction -f delivered to the objects are internal: over a contact their net work is
    -Delta(1/2 k_p |D - C|^2) - integral k_d |d(D - C)/dt|^2 dt, i.e. the virtual coupling only stores (then returns)
    or dissipates energy *if* it is passive. So for a passive system

        E(t) - E(0) + 1/2 k_p |D - C|^2 + dissipated = W_hand(t) = integral F_hand . v_finger dt
        =>  E(t) - E(0) <= W_hand(t)

    with E = 1/2 m_f v_f^2 + sum(1/2 m v^2 + 1/2 w . I w + m g z). The stored coupling energy is on the left with a
    + sign, so leaving it out of E needs no tolerance (it makes the inequality harder to pass, never easier). Any
    energy that the sampled (1 kHz) wall, the plane interpolation or the impulse coupling (20 Hz) create appears as
    a violation. The hand spring's own stored energy 1/2 k_h |target - x|^2 never enters: W_hand is the work the
    hand force does on the finger, not the work the scripted target does on the hand spring.

    Tolerance, each term with its reason:
      * quadrature: W_hand is integrated by the trapezoid rule from the 1 kHz device log (the simulator integrates
        at 0.1 ms); the error of the trapezoid rule is ~h^2, so |W(h) - W(2h)| (= 3x the error at h) bounds it;
      * ODE contact stabilisation: ODE pushes penetrating bodies apart with ERP and a soft constraint (CFM); a body
        resting on another gains at most its weight times the depth it is pushed back out. Contact depths in these
        scenes stay below CONTACT_SLOP_M, so the allowance is sum(m g) * CONTACT_SLOP_M over the dynamic bodies.

    Objects are sampled at world steps: the state after the step taken at haptic tick k*n (phase 0) is compared with
    the finger and W_hand at that tick, i.e. with the impulse the world has just applied.

    Returns excess_J (the largest E(t) - E(0) - W_hand(t)), at_s, dE_J and W_J (at that time), tolerance_J and its
    parts quadrature_J and contact_J, W_total_J (the hand's work over the trial) and ok (excess_J <= tolerance_J)."""
    finger_mass_kg = finger["finger_mass_kg"]
    hand_stiffness_Npm = finger["hand_stiffness_Npm"]
    hand_damping_Nspm = finger["hand_damping_Nspm"]
    gravity = scene.gravity_mps2
    g = math.sqrt(sum(x * x for x in gravity))
    dynamic = scene.dynamic_objects
    # A device of several fingers: each finger is a point mass on its own hand spring, the system holds them all, and
    # the hand's work is the sum over the fingers. Their logs share the device's ticks.
    devices = device if isinstance(device, (list, tuple)) else [device]
    times = np.concatenate(([0.0], devices[0]["time_s"]))
    ticks = np.arange(len(times))
    even = ticks[2::2]
    work = np.zeros(len(times))
    quadrature = 0.0
    finger_kinetic = np.zeros(len(times))
    for one in devices:
        # Tick 0 (t = 0) is the finger at rest on its target, before the first device tick the log records.
        target = one.vectors("target_", "_m")
        target = np.concatenate((target[:1], target))
        position = np.concatenate((target[:1], one.vectors("finger_", "_m")))
        velocity = np.concatenate((np.zeros((1, 3)), one.vectors("finger_v", "_mps")))
        # Target velocity by central finite differences (one-sided at the ends).
        before, after = np.maximum(ticks - 1, 0), np.minimum(ticks + 1, len(times) - 1)
        target_velocity = (target[after] - target[before]) / (times[after] - times[before])[:, None]
        hand_force = hand_stiffness_Npm * (target - position) + hand_damping_Nspm * (target_velocity - velocity)
        power = _dot3(hand_force, velocity)
        # W_hand by the trapezoid rule at the log's step h, and at 2h for the quadrature tolerance (each finger's
        # bound added, so errors of opposite sign in two fingers cannot hide each other).
        finger_work = np.concatenate(([0.0], np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(times))))
        finger_coarse = np.cumsum((power[even] + power[even - 2]) * 0.5 * (times[even] - times[even - 2]))
        quadrature += float(np.abs(finger_work[even] - finger_coarse).max(initial=0.0))
        work = work + finger_work
        finger_kinetic = finger_kinetic + 0.5 * finger_mass_kg * _dot3(velocity, velocity)

    e0 = float(finger_kinetic[0])
    for obj in dynamic:
        e0 += _initial_energy_J(obj, bodies[obj["name"]], gravity)
    # World step j (at world time t_j) was taken at haptic tick round((t_j - T_world) / T_haptic); steps before the
    # device log starts (a world log whose times were shifted back by a link's delay) and after it ends are left out.
    tick = np.rint((world["time_s"] - world_period_s) / haptic_period_s).astype(int)
    late = np.flatnonzero(tick >= len(times))
    rows = np.arange(late[0] if len(late) else len(tick))
    rows = rows[tick[rows] >= 0]
    tick = tick[rows]
    energy = finger_kinetic[tick]
    for obj in dynamic:
        name = obj["name"]
        orientation = np.stack([world[f"{name}.q{axis}"] for axis in "wxyz"], axis=1)
        energy = energy + object_energy_J(bodies[name], gravity, world.vectors(f"{name}.", "_m")[rows], orientation[rows],
                                          world.vectors(f"{name}.v", "_mps")[rows],
                                          world.vectors(f"{name}.w", "_radps")[rows])
    excess = energy - e0 - work[tick]
    worst = (-math.inf, 0.0, 0.0, 0.0)
    if (excess > -math.inf).any():  # NaN (a non-finite log) never counts as the worst
        j = int(np.argmax(np.where(excess > -math.inf, excess, -math.inf)))
        worst = (float(excess[j]), float(times[tick[j]]), float(energy[j] - e0), float(work[tick[j]]))
    contact = sum(mass_and_inertia(bodies[obj["name"]])[0] for obj in dynamic) * g * CONTACT_SLOP_M
    tolerance = quadrature + contact
    return {"excess_J": worst[0], "at_s": worst[1], "dE_J": worst[2], "W_J": worst[3], "tolerance_J": tolerance,
            "quadrature_J": quadrature, "contact_J": contact, "W_total_J": float(work[-1]),
            "ok": bool(worst[0] <= tolerance)}

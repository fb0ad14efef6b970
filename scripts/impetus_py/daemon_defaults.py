# SPDX-License-Identifier: Apache-2.0
"""C++ defaults the scripts need before any trial has run (a trial's own values are in its summary.json: the haptic
rate, the force limit, the finger and hand, the scene's gravity), kept here once. Each names the flag or field it
mirrors; if that default changes in C++, change it here too.

Scene keys a file leaves out take the scene parser's defaults (world_manager/scene.h); scene.py fills them in from the
SCENE_* values below.
"""

# haptic_controller --rate (1000). A trial's own rate is in its summary (Summary.haptic_period_s); this value is for
# planning trials before any has run (world-clock phases are counted in haptic ticks).
HAPTIC_RATE_HZ = 1000

# Scene parser defaults (world_manager/scene.h).
SCENE_GRAVITY_MPS2 = (0.0, 0.0, -9.81)  # "gravity_mps2"
SCENE_FRICTION = 0.5                    # Material::kDefaultFriction: "static_friction", "dynamic_friction"
SCENE_SUBSTEPS = 10                     # PhysicsParams::substeps: "physics": {"substeps"}
SCENE_HAPTIC_STIFFNESS_NPM = 2000.0     # HapticParams::stiffness_Npm: "haptic": {"stiffness_Npm"}
SCENE_HAPTIC_DAMPING_NSPM = 5.0         # HapticParams::damping_Nspm: "haptic": {"damping_Nspm"}

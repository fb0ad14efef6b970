"""C++ defaults the scripts need and that no trial output exports yet, kept here once. Each names the flag or field
it mirrors; if that default changes in C++, change it here too.

Scene keys a file leaves out take the scene parser's defaults (world_manager/scene.h); scene.py fills them in from the
SCENE_* values below.
"""

# spidar_sim's finger (FingerParams in spidar_sim/finger.h; flags --finger-mass, --hand-stiffness, --hand-damping).
FINGER_MASS_KG = 0.1
HAND_STIFFNESS_NPM = 300.0
HAND_DAMPING_NSPM = 8.0

# The largest force the haptic controller renders before clamping (SpidarGeometry::max_force_N,
# common/spidar/geometry.h).
DEVICE_MAX_FORCE_N = 10.0

# haptic_controller --rate (1000). A trial's own rate is in its summary (Summary.haptic_period_s); this value is for
# planning trials before any has run (world-clock phases are counted in haptic ticks).
HAPTIC_RATE_HZ = 1000

# Scene parser defaults (world_manager/scene.h).
SCENE_GRAVITY_MPS2 = (0.0, 0.0, -9.81)  # "gravity_mps2"
SCENE_FRICTION = 0.5                    # Material::kDefaultFriction: "static_friction", "dynamic_friction"
SCENE_SUBSTEPS = 10                     # PhysicsParams::substeps: "physics": {"substeps"}
SCENE_HAPTIC_STIFFNESS_NPM = 2000.0     # HapticParams::stiffness_Npm: "haptic": {"stiffness_Npm"}
SCENE_HAPTIC_DAMPING_NSPM = 5.0         # HapticParams::damping_Nspm: "haptic": {"damping_Nspm"}

# SPDX-License-Identifier: Apache-2.0
"""A scene file (scenes/*.json, tests/hard_cases/*.json; format in world_manager/scene.h) as the scripts read it:
objects by name, with the scene parser's defaults filled in wherever a file leaves a key out, so no script guesses a
default of its own."""
import json
import pathlib

from . import daemon_defaults


class Scene:
    """One parsed scene file. `objects` maps each object's name to its JSON object (file order) with the optional
    keys the scripts read filled in: orientation_wxyz, linear_velocity_mps, angular_velocity_radps, static_friction,
    dynamic_friction."""

    def __init__(self, path):
        self.path = pathlib.Path(path)
        self.data = json.loads(self.path.read_text())
        self.objects = {obj["name"]: _with_defaults(obj) for obj in self.data["objects"]}

    @property
    def dynamic_objects(self):
        """The objects the world moves, in file order."""
        return [obj for obj in self.objects.values() if obj["dynamic"]]

    @property
    def static_objects(self):
        """The immovable objects (walls, blocks), in file order."""
        return [obj for obj in self.objects.values() if not obj["dynamic"]]

    @property
    def gravity_mps2(self):
        return self.data.get("gravity_mps2", daemon_defaults.SCENE_GRAVITY_MPS2)

    @property
    def floor_static_friction(self):
        """The floor's static friction coefficient, or None for a scene without a floor (`"floor": null`)."""
        floor = self.data.get("floor", {})
        return None if floor is None else floor.get("static_friction", daemon_defaults.SCENE_FRICTION)

    @property
    def floor_dynamic_friction(self):
        """The floor's dynamic friction coefficient (its static one when only that is given), or None without a
        floor."""
        floor = self.data.get("floor", {})
        if floor is None:
            return None
        return floor.get("dynamic_friction", floor.get("static_friction", daemon_defaults.SCENE_FRICTION))

    @property
    def substeps(self):
        """ODE steps per world period when world_manager gets no --substeps."""
        return int(self.data.get("physics", {}).get("substeps", daemon_defaults.SCENE_SUBSTEPS))

    @property
    def haptic_stiffness_Npm(self):
        """The haptic controller's k_p when it gets no --stiffness."""
        return self.data.get("haptic", {}).get("stiffness_Npm", daemon_defaults.SCENE_HAPTIC_STIFFNESS_NPM)

    @property
    def haptic_damping_Nspm(self):
        """The haptic controller's k_d when it gets no --damping."""
        return self.data.get("haptic", {}).get("damping_Nspm", daemon_defaults.SCENE_HAPTIC_DAMPING_NSPM)

    def start_position_m(self, name):
        """Where object `name` starts: its centre, [x, y, z]."""
        return self.objects[name]["position_m"]


def _with_defaults(obj):
    filled = dict(obj)
    filled.setdefault("orientation_wxyz", [1.0, 0.0, 0.0, 0.0])
    filled.setdefault("linear_velocity_mps", [0.0, 0.0, 0.0])
    filled.setdefault("angular_velocity_radps", [0.0, 0.0, 0.0])
    filled.setdefault("static_friction", daemon_defaults.SCENE_FRICTION)
    filled.setdefault("dynamic_friction", filled["static_friction"])  # one coefficient given: both
    return filled

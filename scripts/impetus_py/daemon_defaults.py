# SPDX-License-Identifier: Apache-2.0
"""The C++ side's defaults, read from it, never copied: the couplings, engines and shape kinds there are, the haptic
rate, and what a scene's left-out keys become (world_manager/defaults.h). A trial's own values are in its summary.json;
these are for planning trials before any has run and for filling in a scene file's left-out keys (scene.py).

They come from the impetus package when this process runs trials through it (impetus.defaults()), else from the
built daemon (world_manager --defaults), once, when a value is first asked for:

  HAPTIC_RATE_HZ               haptic_controller --rate's default (paper §4.2.1)
  COUPLINGS, ENGINES, SHAPES   world_manager --coupling's values, physics.engine's, a scene object's "shape"
  SCENE_GRAVITY_MPS2, SCENE_FRICTION, SCENE_SUBSTEPS, SCENE_HAPTIC_STIFFNESS_NPM, SCENE_HAPTIC_DAMPING_NSPM
                               a scene's "gravity_mps2", materials' friction, "physics": {"substeps"}, "haptic":
                               {"stiffness_Npm", "damping_Nspm"} when the file leaves them out
"""
import json
import subprocess

from .paths import build_dir

_document = None


def document():
    """The whole defaults document (world_manager --defaults), loaded once."""
    global _document
    if _document is None:
        from .trial import _impetus_module  # here, not at import: trial imports this module's users
        module = _impetus_module()
        if module is not None:
            _document = module.defaults()
        else:
            binary = build_dir() / "world_manager" / "world_manager"
            try:
                text = subprocess.run([str(binary), "--defaults"], check=True, capture_output=True, text=True).stdout
            except (OSError, subprocess.CalledProcessError) as error:
                raise RuntimeError(f"cannot read the defaults from {binary} ({error}): build it first "
                                   f"(bash scripts/build.sh)") from error
            _document = json.loads(text)
    return _document


_VALUES = {
    # A whole number of hertz as an int: the scripts count world periods and phases in whole haptic ticks.
    "HAPTIC_RATE_HZ": lambda d: int(d["haptic_rate_hz"]) if float(d["haptic_rate_hz"]).is_integer()
    else d["haptic_rate_hz"],
    "COUPLINGS": lambda d: tuple(d["couplings"]),
    "ENGINES": lambda d: tuple(d["engines"]),
    "SHAPES": lambda d: tuple(d["shapes"]),
    "SCENE_GRAVITY_MPS2": lambda d: tuple(d["scene"]["gravity_mps2"]),
    "SCENE_FRICTION": lambda d: d["scene"]["friction"],
    "SCENE_SUBSTEPS": lambda d: d["scene"]["physics"]["substeps"],
    "SCENE_HAPTIC_STIFFNESS_NPM": lambda d: d["scene"]["haptic"]["stiffness_Npm"],
    "SCENE_HAPTIC_DAMPING_NSPM": lambda d: d["scene"]["haptic"]["damping_Nspm"],
}


def __getattr__(name):  # PEP 562: each value is read from the C++ side when first used
    if name in _VALUES:
        return _VALUES[name](document())
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

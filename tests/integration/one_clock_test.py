# SPDX-License-Identifier: Apache-2.0
"""One trial, one clock: a world started before the finger (what scripts/demo.sh does with run.sh --view-wait, so a
person can open the viewer first) runs its clock ahead of the finger's by the wait. The world log's haptic_time_s
pairs each step with the finger's clock, and what reads both logs (scripts/plot_trial.py, the viewer's replay through
the same rule) must show the cube move when the finger pushes it, not a wait later.

Real time, the three daemons started by hand: the world, 1.5 s later the haptic controller and the simulated device
on the tap. usage: one_clock_test.py OUT_DIR (IMPETUS_BUILD_DIR: the build)
"""
import os
import pathlib
import signal
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from impetus_py import logs  # noqa: E402

WAIT_S = 1.5       # the finger starts this long after the world
PUSH_N = 0.5       # a force on the finger beyond this is the push
MOVED_M = 1e-3     # the cube has moved once its centre is this far from where it rested
# The cube moves at the first world step after the push began: one world period (50 ms) plus the push's own build-up
# and real-time lateness; 0.3 s bounds it with room and is 5× shorter than the wait the raw clocks would show.
CAUSE_TO_EFFECT_S = 0.3


def main():
    build = pathlib.Path(os.environ["IMPETUS_BUILD_DIR"])
    out = pathlib.Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    shm = f"impetus_one_clock_{os.getpid()}"
    scene = ROOT / "scenes/tap.json"
    world = subprocess.Popen([str(build / "world_manager/world_manager"), "--scene", str(scene), "--clock", "realtime",
                              "--shm", shm, "--log", str(out / "world.csv"), "--summary", str(out / "world.json")])
    time.sleep(WAIT_S)
    haptic = subprocess.Popen([str(build / "haptic_controller/haptic_controller"), "--clock", "realtime", "--shm", shm,
                               "--no-realtime-priority", "--log", str(out / "haptic.csv")])
    device = subprocess.run([str(build / "spidar_sim/spidar_sim"), "--clock", "realtime", "--shm", shm,
                             "--trajectory", "tap"], timeout=60, check=False)
    for process in (haptic, world):  # stopped as run.sh stops them
        process.send_signal(signal.SIGINT)
        process.wait(timeout=30)
    if device.returncode != 0 or haptic.returncode != 0 or world.returncode != 0:
        sys.exit(f"one_clock_test: a daemon failed (device {device.returncode}, haptic {haptic.returncode}, "
                 f"world {world.returncode})")

    world_log = logs.read_log(out / logs.WORLD)
    haptic_log = logs.read_log(out / logs.HAPTIC)
    ahead_s = logs.world_clock_offset_s(world_log)
    pushed = haptic_log["time_s"][haptic_log["force_x_N"] < -PUSH_N]
    moved = abs(world_log["cube.x_m"] - world_log["cube.x_m"][0]) > MOVED_M
    if len(pushed) == 0 or not moved.any():
        sys.exit("one_clock_test: the finger never pushed the cube away")
    push_s = pushed[0]
    move_s = world_log["time_s"][moved][0] - ahead_s  # on the finger's clock
    raw_move_s = world_log["time_s"][moved][0]
    print(f"one_clock_test: world ahead by {ahead_s:.3f} s; push at {push_s:.3f} s, cube moves at {move_s:.3f} s on "
          f"the finger's clock ({raw_move_s:.3f} s on the world's)")
    problems = []
    if not WAIT_S - 0.5 <= ahead_s <= WAIT_S + 1.0:
        problems.append(f"the world's clock is {ahead_s:.3f} s ahead, not about the {WAIT_S} s it started earlier")
    if not push_s <= move_s <= push_s + CAUSE_TO_EFFECT_S:
        problems.append(f"on one clock the cube moves {move_s - push_s:+.3f} s after the push, not within "
                        f"0..{CAUSE_TO_EFFECT_S} s")
    if raw_move_s - push_s < WAIT_S - 0.5:
        problems.append("the two logs' raw clocks agree: the test no longer shows the wait it corrects for")
    # The plot of this trial uses the same rule; it must draw.
    plot = subprocess.run(["/usr/bin/python3", str(ROOT / "scripts/plot_trial.py"), str(out), "--out",
                           str(out / "trial.png")], capture_output=True, text=True)
    if plot.returncode != 0 or not (out / "trial.png").is_file():
        problems.append(f"plot_trial.py failed: {plot.stderr}")
    for problem in problems:
        print(f"one_clock_test: {problem}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

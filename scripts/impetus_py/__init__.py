# SPDX-License-Identifier: Apache-2.0
"""What the experiment scripts in scripts/ share: running trials (through the impetus package, or scripts/run.sh) and
reading what a trial leaves behind.

  paths            the repository root and the daemons' build directory
  daemon_defaults  the C++ side's defaults (couplings, rates, scene defaults), read from it (world_manager --defaults)
  scene            a scene file (scenes/*.json) with the scene parser's defaults filled in
  trial            run one lockstep trial, in this process or as three daemons (COUPLINGS: the couplings)
  parallel         run many trials at once, in worker processes
  progress         a progress bar (tqdm) weighted by each trial's expected cost
  summary          summary.json: how run.sh merges it and how its fields are read
  logs             the daemons' CSV logs (world.csv, haptic.csv, device.csv)
  energy           mechanical energy of the finger and the scene's rigid bodies, and the hand's work on them

Scripts import it as `from impetus_py import ...` after putting scripts/ on sys.path, so they run from any directory
with /usr/bin/python3 (Debian's python3-numpy, python3-matplotlib and python3-tqdm; nothing else).
"""

#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds Impetus (scripts/build.sh build) and runs its benchmarks, printing the numbers. Asserts nothing: timing on a
# shared 2-core VM is a measurement, not a pass/fail test (timing goals live in benchmarks).
#   scripts/bench.sh [--short]       --short: 5 s instead of 30 s for the real-time loop benchmark
#
#   1. haptic tick cost vs number of planes (passivity layer off and on), per endpoint count, and the 8-string
#      grip SPIDAR's pose and tensions                 build/tests/bench_haptic_tick
#   2. world step and feature query vs object count, physics in the 1 kHz loop vs the 20 Hz world, a world of
#      N resting bodies with sleeping on and off (--short: up to 10 k, else 100 k)   build/tests/bench_world
#   3. channel latency between processes               build/tests/bench_channel
#   4. 1 kHz real-time loop lateness (FIFO + mlock)    build/tests/bench_rt_loop SECONDS
#   5. lockstep throughput of the tap trial (simulated s per wall s, target >= 50x) via scripts/run.sh, against the
#      floor of three-process turn-taking with no work (build/tests/bench_lockstep_ring), and the in-process loop
#      without logs (build/tests/bench_in_process)
#   6. peak RSS of each process during a tap trial
#   7. the world view: snapshot size and cost per world step, a viewer's read and encode   build/tests/bench_world_view
#   8. world link one-way latency, shared memory and DDS, and DDS across a veth   build/tests/bench_dds_link
#   9. ghost force, release, lost walls and pop-through in clutter and streams, of primitives and of users' meshes
#      build/tests/bench_ghost_force
#  10. the closed loop from Python: ticks/s at 1 to 1000 ticks a call, free and in contact (goal: >= 200 k at 50)
#      tests/bench/bench_closed_loop.py
#  11. nearest point on a user's mesh of 10^3 to 10^6 triangles: tree build, memory, query percentiles
#      build/tests/bench_mesh_query
#  12. the servo's tick on a mesh ball of 10^3 to 10^6 triangles, beside the primitive box and sphere
#      build/tests/bench_mesh_tick
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
cd "$root"

rt_seconds=30
world_args=()
while (($#)); do
  case "$1" in
    --short) rt_seconds=5; world_args=(--quick); shift ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "bench.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done

bash scripts/build.sh build
build="$root/build"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

section() { printf '\n== %s\n' "$*"; }
# Runs a benchmark program if it was built; a missing one (not written yet) or a failing one is reported, not fatal.
bench() {
  local program="$build/tests/$1"; shift
  if [ ! -x "$program" ]; then
    echo "(skipped: $program does not exist yet)"
    return 0
  fi
  "$program" "$@" || echo "(${program##*/} exited with status $?)"
}

section "1. Haptic tick cost vs number of planes (ns)"
bench bench_haptic_tick
# Instructions do not depend on the machine's load: count those of the servo and its SPIDAR driver per tick (the
# finger's kinematics, the frame's intake every 50 ticks, the servo's tick, the tensions and the command).
if command -v valgrind >/dev/null && [ -x "$build/tests/bench_haptic_tick" ]; then
  for planes in 1 16; do
    valgrind --tool=callgrind --callgrind-out-file="$tmp/callgrind.$planes" \
      --toggle-collect='impetus::SpidarDriver::read*' --toggle-collect='impetus::HapticServo::tick*' \
      --toggle-collect='impetus::SpidarDriver::command*' --toggle-collect='impetus::HapticServo::on_plane_frame*' \
      "$build/tests/bench_haptic_tick" --planes "$planes" >/dev/null 2>&1
    instructions=$(sed -n 's/^totals: *//p' "$tmp/callgrind.$planes")
    echo "planes $planes: $((instructions / 20000)) instructions a tick (callgrind, 20000 ticks; goal: 5 k at 1 plane," \
         "15 k at 16)"
  done
  # Everything the daemon does in a tick of a lockstep tap trial (servo, driver, report published and sealed, log row
  # queued, frames taken, statistics), without its waits for the device's and the world's turns (wait_slice toggles
  # collection off inside lockstep_tick; the log rows it formats while waiting are left out with them).
  shm="impetus_bench_$$"
  "$build/world_manager/world_manager" --scene scenes/tap.json --clock lockstep --shm "$shm" 2>/dev/null &
  world_pid=$!
  valgrind --tool=callgrind --callgrind-out-file="$tmp/callgrind.daemon" \
    --toggle-collect='impetus::HapticNode::lockstep_tick*' --toggle-collect='impetus::LockstepTurn::wait_slice*' \
    "$build/haptic_controller/haptic_controller" --clock lockstep --shm "$shm" --log "$tmp/daemon.csv" \
    2>"$tmp/daemon.err" &
  haptic_pid=$!
  "$build/spidar_sim/spidar_sim" --clock lockstep --shm "$shm" --trajectory tap 2>/dev/null
  kill -TERM "$haptic_pid" 2>/dev/null || true  # stopped as run.sh stops it, at the trial's end
  wait "$haptic_pid" || true
  kill -TERM "$world_pid" 2>/dev/null || true
  wait "$world_pid" || true
  instructions=$(sed -n 's/^totals: *//p' "$tmp/callgrind.daemon")
  ticks=$(sed -n 's/^haptic_controller: \([0-9]*\) ticks.*/\1/p' "$tmp/daemon.err")
  if [ -n "$instructions" ] && [ -n "$ticks" ]; then
    echo "haptic_controller, lockstep tap trial (0-1 planes): $((instructions / ticks)) instructions a tick over $ticks" \
         "ticks, everything but its waits for the device and the world (goal: 5 k)"
  else
    echo "(the daemon's instruction count failed: $(tail -1 "$tmp/daemon.err"))"
  fi
else
  echo "(instruction counts skipped: valgrind is missing; scripts/deps.sh installs it)"
fi

section "2. World step and feature query vs number of objects; physics in the 1 kHz loop vs the 20 Hz world; sleeping"
bench bench_world "${world_args[@]}"

section "3. Channel latency between processes"
bench bench_channel

section "4. Real-time loop lateness at 1 kHz, ${rt_seconds} s per mode (ordinary, then SCHED_FIFO + mlockall)"
bench bench_rt_loop "$rt_seconds"

section "5. Lockstep throughput: tap trial (world 20 Hz, impulse coupling), three processes against their floor"
echo "The floor: the same three-process turns with no work in them (ticks/s; a 1 kHz tick is 1/1000 of a simulated s):"
bench bench_lockstep_ring | tee "$tmp/floor.txt"
echo "The in-process loop (one thread, no processes, no logs):"
bench bench_in_process
# Simulated seconds are the world's (summary world.time_s); wall time is run.sh's, from launching the three processes
# to their clean exit, so start-up and shared-memory set-up count against the short trial's throughput. The steady
# state is the marginal rate between a 20 s and a 120 s final hold (100 simulated s, medians of 3 runs each, a few
# tenths of a second of wall time: long enough that this VM's stalls do not decide it), with the logs and without.
for i in 1 2 3 4 5; do
  bash scripts/run.sh --scene scenes/tap.json --trajectory tap --out "$tmp/throughput$i" --quiet
done
for logs in logs no-logs; do
  flags=(); [ "$logs" = no-logs ] && flags=(--no-logs)
  for hold in 20 120; do
    for i in 1 2 3; do
      bash scripts/run.sh --scene scenes/tap.json --trajectory "tap:hold=$hold" --duration 200 "${flags[@]}" \
        --out "$tmp/hold$hold-$logs-$i" --quiet
    done
  done
done
/usr/bin/python3 - "$tmp" <<'PY'
import json, pathlib, re, statistics, sys
tmp = pathlib.Path(sys.argv[1])
def run(name):
    s = json.loads((tmp / name / "summary.json").read_text())
    return s["world"]["time_s"], s["config"]["wall_time_s"]
runs = [run(f"throughput{i}") for i in range(1, 6)]
for sim, wall in runs:
    print(f"  tap: {sim:.3f} s simulated in {wall:.3f} s wall: {sim / wall:6.1f}x real time")
median = statistics.median(sim / wall for sim, wall in runs)
print(f"  median {median:.1f}x real time, start-up included (target >= 50x: {'met' if median >= 50 else 'NOT met'})")
floors = [float(m) for m in re.findall(r"quiet: (\d+) ticks/s", (tmp / "floor.txt").read_text())]
floor = statistics.median(floors) if floors else float("nan")
for logs in ("logs", "no-logs"):
    sim = {h: statistics.median(run(f"hold{h}-{logs}-{i}")[0] for i in (1, 2, 3)) for h in (20, 120)}
    wall = {h: statistics.median(run(f"hold{h}-{logs}-{i}")[1] for i in (1, 2, 3)) for h in (20, 120)}
    ticks_per_s = (sim[120] - sim[20]) * 1000 / (wall[120] - wall[20])
    print(f"  steady state, {'with all three logs' if logs == 'logs' else 'no logs (--no-logs)'}: "
          f"{ticks_per_s / 1e3:.0f} k ticks/s ({ticks_per_s / 1e3:.0f}x real time), {1e6 / ticks_per_s:.2f} us a tick: "
          f"{100 * ticks_per_s / floor:.0f} % of the floor's median {floor / 1e3:.0f} k ticks/s (goal 50 %)")
PY

section "6. Peak RSS of each process during a lockstep trial (tap trajectory)"
# run.sh starts $IMPETUS_BUILD_DIR/NAME/NAME. Here each of those is a wrapper that runs the real binary under
# /usr/bin/time (its ru_maxrss is the binary's own peak; time's fork is tiny, whereas a Python launcher's pages would
# be counted in it) and passes run.sh's SIGTERM on to the binary, since GNU time itself would die of it.
if [ ! -x /usr/bin/time ]; then
  echo "(skipped: /usr/bin/time is missing; scripts/deps.sh installs the Debian package 'time')"
  exit 0
fi
for name in world_manager haptic_controller spidar_sim; do
  mkdir -p "$tmp/wrapped/$name"
  {
    echo '#!/usr/bin/env bash'
    printf 'report=%q\n' "$tmp/rss.$name"
    printf '/usr/bin/time -f "%%x %%M" -o "$report" %q "$@" &\n' "$build/$name/$name"
    cat <<'WRAPPER'
timer=$!
# The binary is time's only child: pass run.sh's signals on to it.
forward() { kill -"$1" $(cat /proc/$timer/task/$timer/children 2>/dev/null) 2>/dev/null || true; }
trap 'forward TERM' TERM
trap 'forward INT' INT
# A trapped signal interrupts wait, so wait until time has really exited. Its exit status is taken from its report
# (%x), not from wait, whose status after an interrupted wait is not reliable.
wait $timer 2>/dev/null || true
while kill -0 $timer 2>/dev/null; do wait $timer 2>/dev/null || true; done
signal="$(sed -n 's/^Command terminated by signal \([0-9]*\).*/\1/p' "$report")"
[ -n "$signal" ] && exit $((128 + signal))
read -r code _ < <(tail -n 1 "$report")
exit "${code:-1}"
WRAPPER
  } >"$tmp/wrapped/$name/$name"
  chmod +x "$tmp/wrapped/$name/$name"
done
for scene in tap spheres; do
  IMPETUS_BUILD_DIR="$tmp/wrapped" bash scripts/run.sh --scene "scenes/$scene.json" --trajectory tap \
    --out "$tmp/rss-$scene" --quiet || { echo "  (the $scene trial failed; see above)"; continue; }
  echo "  scenes/$scene.json:"
  for name in world_manager haptic_controller spidar_sim; do
    read -r _ kb < <(tail -n 1 "$tmp/rss.$name")
    awk -v name="$name" -v kb="$kb" 'BEGIN { printf "    %-18s peak RSS %6.1f MiB\n", name, kb / 1024 }'
  done
done

section "7. World view: snapshot size and cost per world step, and a viewer's per frame, vs number of bodies"
bench bench_world_view

section "8. World link one-way latency: shared memory and DDS on this host, DDS between two network hosts"
# Both ends poll every 20 µs (the timer's slack makes it ~60 µs here): the shared-memory figures are the method's
# floor, and the DDS figures minus them are what DDS adds.
bench bench_dds_link --link shm --seconds 5
bench bench_dds_link --link dds --seconds 5
source scripts/netns_hosts.sh
if make_hosts "impb$$"; then
  ip netns exec "$world_ns" "$build/tests/bench_dds_link" --role world --seconds 5 --partition "impb$$" &
  world_end=$!
  sleep 0.5
  ip netns exec "$hands_ns" "$build/tests/bench_dds_link" --role controller --seconds 5 --partition "impb$$" |
    sed 's/^dds link/dds link across a veth/'
  wait "$world_end" || true
  remove_hosts
else
  remove_hosts
  echo "(DDS across a veth skipped: network namespaces need root and iproute2)"
fi

section "9. Ghost force between world frames in static clutter and in streams past the finger, scored against the true geometry (docs/ghost_force.md)"
bench bench_ghost_force

section "10. The closed loop from Python (impetus.Simulation): ticks per wall second by ticks per call"
if [ -f "$build/python/impetus/__init__.py" ]; then
  PYTHONPATH="$build/python" /usr/bin/python3 tests/bench/bench_closed_loop.py --seconds 2 ||
    echo "(bench_closed_loop.py exited with status $?)"
else
  echo "(skipped: the Python package was not built)"
fi

section "11. Nearest point on a user's mesh (docs/meshes.md): a sphere of 10^3 to 10^6 triangles, 3 mm inside and on the surface"
bench bench_mesh_query

section "12. Haptic tick on a mesh (docs/meshes.md): pressed 3 mm into a ball of 10^3 to 10^6 triangles and sliding, beside the primitive box and sphere"
bench bench_mesh_tick

section "13. A plastic slab (docs/deformation.md): a 128 × 128-cell slab's step on the world side, the haptic tick on its face beside a rigid box's"
bench bench_deform

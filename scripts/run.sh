#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Runs one trial: world_manager + haptic_controller + spidar_sim (docs/architecture.md §4), collects their logs under
# DIR, prints the outcome and writes DIR/summary.json. Exits non-zero if any process failed. Ctrl-C stops all three.
#
#   scripts/run.sh --scene FILE (--trajectory SPEC | --finger NAME=SPEC ... | --device web[:FILE.json])
#                  [--device spidar:FILE.json | --device grip[:FILE.json]]
#                  [--user SPEC ...] [--coupling impulse|position|local] [--passivity on|off]
#                  [--rate HZ] [--phase TICKS] [--substeps N] [--engine ode|bullet]
#                  [--clock realtime|lockstep] [--duration S] [--out DIR] [--quiet] [--no-logs]
#                  [--view [--view-listen HOST:PORT] [--view-wait S]]
#                  [-- extra haptic_controller flags, e.g. --stiffness 5000]
# --finger (once per finger, up to 8) runs a several-finger device: one endpoint of the world per finger; logs of
# finger k > 0 are haptic.endpointK.csv and device.endpointK.csv.
# --user SPEC (once per user) adds another user on the same world: a haptic controller of its own with one finger on
# trajectory SPEC (in lockstep it follows the first controller's ticks); user U's logs are userU.haptic.csv and
# userU.device.csv, its summary summary.json's "followers"[U-1].
# --view starts a viewer beside the trial (default address 127.0.0.1:8080) and prints where to watch it; with
# --view-wait S the finger starts S seconds after the world, time to open the page. Afterwards
# `build/viewer/viewer --replay DIR` plays the trial back.
#
# --device spidar:FILE.json: the SPIDAR's geometry from a device file, for the haptic controller and spidar_sim alike.
# --device grip: the scene's tool (its "tool" block) in the hand, held on the 8-string grip SPIDAR (docs/tool.md);
# the trajectory may turn the grip (a CSV of t,x,y,z,qw,qx,qy,qz, e.g. scenes/peg_in_hole.csv); the tool's poses and
# torque go to haptic.tool.csv.
# --device web: a person steers the finger from the viewer's page instead of a trajectory (a simulated hand in the
# haptic controller, no spidar_sim): real time, the viewer on, and the trial runs until Ctrl-C (or --duration). It
# prints the address to open; FILE.json sets the hand (docs/touch.md).
#
# --no-logs writes only the summaries (no CSV logs: for throughput, or sweeps that read summary.json alone).
#
# Binaries come from $IMPETUS_BUILD_DIR (default build/); build them with scripts/build.sh.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="${IMPETUS_BUILD_DIR:-$root/build}"

usage() { sed -n '3,30p' "$0" | sed 's/^# \{0,1\}//'; }
die() { echo "run.sh: $*" >&2; exit 2; }

view=0 view_listen="127.0.0.1:8080" view_wait=0 logs=1
substeps="" engine="" passivity="" scene="" trajectory="" coupling="impulse" rate="" phase="0" clock="" duration="" out="" quiet=0
device="spidar"
haptic_extra=()
fingers=()
users=()
while (($#)); do
  case "$1" in
    --scene) scene="${2:?}"; shift 2 ;;
    --trajectory) trajectory="${2:?}"; shift 2 ;;
    --finger) fingers+=("${2:?}"); shift 2 ;;
    --user) users+=("${2:?}"); shift 2 ;;
    --coupling) coupling="${2:?}"; shift 2 ;;
    --rate) rate="${2:?}"; shift 2 ;;
    --substeps) substeps="${2:?}"; shift 2 ;;
    --engine) engine="${2:?}"; shift 2 ;;
    --passivity) passivity="${2:?}"; shift 2 ;;
    --device) device="${2:?}"; shift 2 ;;
    --phase) phase="${2:?}"; shift 2 ;;
    --clock) clock="${2:?}"; shift 2 ;;
    --duration) duration="${2:?}"; shift 2 ;;
    --out) out="${2:?}"; shift 2 ;;
    --quiet) quiet=1; shift ;;
    --no-logs) logs=0; shift ;;
    --view) view=1; shift ;;
    --view-listen) view_listen="${2:?}"; shift 2 ;;
    --view-wait) view_wait="${2:?}"; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    --) shift; haptic_extra=("$@"); break ;;
    *) die "unknown argument '$1' (see --help)" ;;
  esac
done
[ -n "$scene" ] || die "--scene is required"
[ -f "$scene" ] || die "--scene: no such file '$scene'"
web=0 grip=0
case "$device" in
  web|web:*) web=1 ;;
  grip|grip:?*) grip=1 ;;
  spidar|spidar:?*) ;;
  *) die "--device must be spidar, spidar:FILE.json, grip, grip:FILE.json, web or web:FILE.json, not '$device'" ;;
esac
if ((grip)); then
  ((${#fingers[@]} == 0 && ${#users[@]} == 0)) || die "--device grip holds one tool: give no --finger or --user"
  [ "$coupling" != position ] || die "--device grip: position coupling samples one point, and a tool touches at \
many; use local or impulse"
fi
if ((web)); then
  [ -z "$trajectory" ] && ((${#fingers[@]} == 0 && ${#users[@]} == 0)) || \
    die "--device web: the page steers the finger; give no --trajectory, --finger or --user"
  [ -z "$clock" ] || [ "$clock" = realtime ] || die "--device web runs in real time (a person does not wait for \
lockstep turns), not --clock $clock"
  clock=realtime
  view=1
  trajectory="web"
elif ((${#fingers[@]})); then
  [ -z "$trajectory" ] || die "give --trajectory or --finger, not both"
  ((${#fingers[@]} <= 8)) || die "--finger: at most 8 fingers, not ${#fingers[@]}"
else
  [ -n "$trajectory" ] || die "--trajectory (or --finger NAME=SPEC for each finger) is required"
fi
[ -n "$clock" ] || clock=lockstep
[ -n "$duration" ] || { ((web)) || duration=60; }
case "$clock" in realtime|lockstep) ;; *) die "--clock must be realtime or lockstep, not '$clock'" ;; esac
first_fingers=$(( ${#fingers[@]} > 0 ? ${#fingers[@]} : 1 ))
endpoints=$(( first_fingers + ${#users[@]} ))
((endpoints <= 8)) || die "a world serves at most 8 endpoints: the first controller's $first_fingers finger(s) and \
${#users[@]} other user(s) make $endpoints"
[[ "$view_wait" =~ ^[0-9]+([.][0-9]+)?$ ]] || die "--view-wait must be a number of seconds, not '$view_wait'"
bins=(world_manager haptic_controller)
((web)) || bins+=(spidar_sim)
((view)) && bins+=(viewer)
for bin in "${bins[@]}"; do
  [ -x "$build/$bin/$bin" ] || die "$build/$bin/$bin is missing: run scripts/build.sh first"
done
[ -n "$out" ] || out="$root/out/run-$(date +%Y%m%d-%H%M%S)-$$"
mkdir -p "$out"
# One shared-memory name per trial, so trials can run in parallel.
shm="impetus_run_$$_$RANDOM"

# add_log ARRAY NAME: appends the flags of a process's log NAME.csv to ARRAY (nothing under --no-logs).
add_log() { local -n flags=$1; if ((logs)); then flags+=(--log "$out/$2.csv"); fi; }
world_args=(--scene "$scene" --coupling "$coupling" --clock "$clock" --phase "$phase" --shm "$shm"
            --summary "$out/world.json")
add_log world_args world
[ -n "$rate" ] && world_args+=(--rate "$rate")
[ -n "$substeps" ] && world_args+=(--substeps "$substeps")
[ -n "$engine" ] && world_args+=(--engine "$engine")
[ -n "$passivity" ] && world_args+=(--passivity "$passivity")
# --meshes-from: the servo reads the scene's meshes too, to follow their triangles between world frames.
haptic_args=(--clock "$clock" --shm "$shm" --summary "$out/haptic.json" --meshes-from "$scene" "${haptic_extra[@]}")
[ -n "$duration" ] && haptic_args+=(--duration "$duration")
haptic_args+=(--device "$device")
# The tool the grip holds is the scene's.
((grip)) && haptic_args+=(--tool-from "$scene")
add_log haptic_args haptic
device_args=(--clock "$clock" --shm "$shm" --summary "$out/device.json" --device "$device")
add_log device_args device
if ((${#fingers[@]})); then
  haptic_args+=(--fingers "${#fingers[@]}")
  for finger in "${fingers[@]}"; do device_args+=(--finger "$finger"); done
  trajectory="$(IFS=' '; echo "${fingers[*]}")"
else
  device_args+=(--trajectory "$trajectory")
fi
# Every segment the trial may create: the world's, the viewer's and one device port per finger.
segments=("/dev/shm/$shm.world" "/dev/shm/$shm.view" "/dev/shm/$shm.device" "/dev/shm/$shm.touch")
for ((k = 1; k < ${#fingers[@]}; ++k)); do segments+=("/dev/shm/$shm.device$k"); done
# Another user's controller has a device port of its own: NAME_uU.device.
for ((u = 1; u <= ${#users[@]}; ++u)); do segments+=("/dev/shm/${shm}_u$u.device"); done
if ((${#users[@]})) && [ "$clock" = lockstep ]; then
  haptic_args+=(--followers "${#users[@]}")  # the first controller leads, and starts when every user is there
fi

# Every process's flags are checked before any starts (--check-flags parses them and exits): a bad value is one
# message and status 2, not three daemons started and stopped.
check_flags() {
  local bin="$1" message
  shift
  if ! message="$("$build/$bin/$bin" "$@" --check-flags 2>&1 >/dev/null)"; then
    echo "run.sh: $bin: ${message:-its flags were refused}" >&2
    exit 2
  fi
}
check_flags world_manager "${world_args[@]}"
check_flags haptic_controller "${haptic_args[@]}"
((web)) || check_flags spidar_sim "${device_args[@]}"

pids=()
viewer_pid=""
stop_all() {
  for pid in "${pids[@]}" $viewer_pid; do kill -TERM "$pid" 2>/dev/null || true; done
}
on_interrupt() {
  echo "run.sh: interrupted, stopping the trial" >&2
  stop_all
  wait || true
  rm -f "${segments[@]}"
  exit 130
}
trap on_interrupt INT TERM

start=$(date +%s.%N)
"$build/world_manager/world_manager" "${world_args[@]}" 2>"$out/world.err" & world=$!; pids+=("$world")
if ((view)); then
  # The viewer is a bystander: if it cannot start (the port is taken), the trial runs without it.
  viewer_args=(--shm "$shm" --listen "$view_listen" --meshes-from "$scene")
  ((web)) && viewer_args+=(--touch)
  "$build/viewer/viewer" "${viewer_args[@]}" >"$out/viewer.out" 2>"$out/viewer.err" & viewer_pid=$!
  for _ in $(seq 100); do
    grep -q serving "$out/viewer.out" 2>/dev/null && break
    kill -0 "$viewer_pid" 2>/dev/null || break
    sleep 0.05
  done
  if ((web)) && grep -q "touch the world" "$out/viewer.out" 2>/dev/null; then
    echo "run.sh: touch it: open $(sed -n 's/.*touch the world: \(http[^ ]*\).*/\1/p' "$out/viewer.out") in a browser;" \
         "drag to move the finger, wheel for depth; Ctrl-C ends the trial" >&2
  elif grep -q serving "$out/viewer.out" 2>/dev/null; then
    echo "run.sh: watch it live: open $(sed -n 's/.*serving \(http[^ ]*\).*/\1/p' "$out/viewer.out") in a browser" >&2
  elif ((web)); then
    echo "run.sh: the viewer did not start, and --device web needs it:" >&2
    cat "$out/viewer.err" >&2
    stop_all
    wait || true
    rm -f "${segments[@]}"
    exit 1
  else
    echo "run.sh: the viewer did not start (the trial runs without it):" >&2
    cat "$out/viewer.err" >&2
    viewer_pid=""
  fi
  sleep "$view_wait"
fi
"$build/haptic_controller/haptic_controller" "${haptic_args[@]}" 2>"$out/haptic.err" & haptic=$!; pids+=("$haptic")
if ((!web)); then
  "$build/spidar_sim/spidar_sim" "${device_args[@]}" 2>"$out/device.err" & device=$!; pids+=("$device")
fi
user_haptics=() user_devices=()
if ((${#users[@]})); then
  if [ "$clock" = lockstep ]; then
    # The others follow once the first holds the world's lockstep (it says it is waiting for them), so it leads.
    for _ in $(seq 600); do
      grep -q "waiting for" "$out/haptic.err" 2>/dev/null && break
      kill -0 "$haptic" 2>/dev/null || break
      sleep 0.05
    done
  fi
  for ((u = 1; u <= ${#users[@]}; ++u)); do
    user_haptic_args=(--clock "$clock" --duration "$duration" --shm "${shm}_u$u" --world-shm "$shm"
                      --summary "$out/user$u.haptic.json" --meshes-from "$scene" "${haptic_extra[@]}")
    add_log user_haptic_args "user$u.haptic"
    user_device_args=(--clock "$clock" --shm "${shm}_u$u" --trajectory "${users[u - 1]}"
                      --summary "$out/user$u.device.json")
    add_log user_device_args "user$u.device"
    "$build/haptic_controller/haptic_controller" "${user_haptic_args[@]}" 2>"$out/user$u.haptic.err" &
    user_haptics+=($!); pids+=($!)
    "$build/spidar_sim/spidar_sim" "${user_device_args[@]}" 2>"$out/user$u.device.err" &
    user_devices+=($!); pids+=($!)
  done
fi

# The trial lasts as long as the trajectory (its final hold lets the objects come to rest), capped by --duration.
# Then the haptic controller and the world are stopped like a user would, and must exit cleanly.
device_status=0 haptic_status=0 world_status=0
user_status=()
if ((web)); then
  # The person ends a web trial: Ctrl-C stops the haptic controller as --duration would, and the trial is summarised.
  trap 'echo "run.sh: ending the trial" >&2; kill -TERM "$haptic" 2>/dev/null || true' INT TERM
  while :; do
    haptic_status=0
    wait "$haptic" || haptic_status=$?
    kill -0 "$haptic" 2>/dev/null || break
  done
  trap on_interrupt INT TERM
else
  wait "$device" || device_status=$?
  # Other users: their devices end with their trajectories; then their controllers leave before the first one.
  for ((u = 1; u <= ${#users[@]}; ++u)); do
    status_u=0
    wait "${user_devices[u - 1]}" || status_u=$?
    kill -TERM "${user_haptics[u - 1]}" 2>/dev/null || true
    wait "${user_haptics[u - 1]}" || status_u=$((status_u ? status_u : $?))
    user_status+=("$status_u")
  done
  kill -TERM "$haptic" 2>/dev/null || true
  wait "$haptic" || haptic_status=$?
fi
kill -TERM "$world" 2>/dev/null || true
wait "$world" || world_status=$?
if [ -n "$viewer_pid" ]; then
  kill -TERM "$viewer_pid" 2>/dev/null || true
  wait "$viewer_pid" || echo "run.sh: the viewer exited with an error: $(tail -1 "$out/viewer.err")" >&2
  echo "run.sh: play it back: $build/viewer/viewer --replay $out" >&2
fi
# Failures upstream first: a bad scene stops the world, and the others' errors (no world link, no device port) follow
# from it.
status=0
for name in world haptic device; do
  var="${name}_status"
  if ((${!var} != 0)); then
    case "$name" in world) bin=world_manager ;; haptic) bin=haptic_controller ;; device) bin=spidar_sim ;; esac
    echo "run.sh: $bin failed (exit ${!var}):" >&2
    cat "$out/$name.err" >&2
    status=1
  fi
done
for ((u = 1; u <= ${#users[@]}; ++u)); do
  if ((user_status[u - 1] != 0)); then
    echo "run.sh: user $u's haptic_controller or spidar_sim failed (exit ${user_status[u - 1]}):" >&2
    cat "$out/user$u.haptic.err" "$out/user$u.device.err" >&2
    status=1
  fi
done
# The processes' warnings (objects placed inside each other or too light for the coupling, a trajectory cut at
# --duration) reach the user here, not only the .err files.
for err in "$out"/*.err; do
  [ -f "$err" ] && grep -h "warning:" "$err" | sed 's/^/run.sh: /' >&2 || true
done
end=$(date +%s.%N)
trap - INT TERM
for segment in "${segments[@]}"; do
  [ -e "$segment" ] && { echo "run.sh: $segment was left behind; removing it" >&2; rm -f "$segment"; status=1; }
done
((status == 0)) || exit "$status"

args=("$out" --set "scene=$scene" --set "trajectory=$trajectory" --set "coupling=$coupling" --set "rate=$rate" --set "substeps_override=$substeps"
      --set "phase_ticks=$phase" --set "clock=$clock" --set "duration_s=$duration"
      --set "wall_start=$start" --set "wall_end=$end")
((quiet)) && args+=(--quiet)
/usr/bin/python3 "$root/scripts/summarize_trial.py" "${args[@]}"

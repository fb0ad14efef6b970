#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The world link over DDS between two network hosts: the world manager in one network namespace, the haptic
# controllers and their devices in another, joined by a veth pair (iproute2). Real time; asserts the ledger, the
# re-attachment and the absence of bursts, never timing.
#
#   tests/dds/netns_test.sh BUILD_DIR OUT_DIR [hosts|netem|secure]
#
# hosts (the default):
# 1. a tap trial across the hosts at 0, 1 and 10 % packet loss (Cyclone's Internal/Test/XmitLossiness on both
#    sides): the world applies exactly what the controller rendered;
# 2. the link pulled down for longer than the DDS lease mid-press and brought back: the controller holds its last
#    planes, the world drops the finger, and after the link returns the controller is served again, the totals still
#    agree and the cube shows no burst;
# 3. one world serves four controllers on the other host, and a viewer there watches it (--link dds).
# netem: the tap trial (local coupling, a rest first) with 10 and 50 ms of one-way delay: on the veth (tc netem on
#    both ends) where the kernel has netem, else in the DDS transport's own delay stage (--dds-delay-ms on both
#    ends, common/link/delay_stage.h). The world applies exactly what was rendered; the servo's own measure of the
#    round trip (local_replayed_ticks_max) is at least twice the delay; the cube's stop position is printed beside
#    the in-process delay line's (docs/latency.md).
# secure: a secured link (DDS Security, credentials from scripts/dds_security.sh): a tap trial across the hosts with
#    the ledger exact; a controller without credentials, one certified by another CA and one whose permissions do not
#    allow publishing reports are each refused, and the world serves none of them; the link's one-way latency, open
#    and secured, is printed side by side.
# Needs root (network namespaces). Exits 77 (CTest: skipped, not passed) where namespaces cannot be made.
set -euo pipefail
build="${1:?usage: netns_test.sh BUILD_DIR OUT_DIR}"
out="${2:?usage: netns_test.sh BUILD_DIR OUT_DIR}"
mode="${3:-hosts}"
case "$mode" in hosts|netem|secure) ;; *) echo "netns_test: the mode is hosts, netem or secure, not '$mode'" >&2; exit 2 ;; esac
root="$(cd "$(dirname "$0")/../.." && pwd)"
skip() { echo "netns_test: SKIPPED: $*"; exit 77; }
fail() { echo "netns_test: FAILED: $*" >&2; exit 1; }

source "$root/scripts/netns_hosts.sh"
tag="imp$$"
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  remove_hosts
  rm -f /dev/shm/"${tag}"_*
}
trap cleanup EXIT
make_hosts "$tag" || skip "cannot make network namespaces here (needs root and iproute2)"

rm -rf "$out"
mkdir -p "$out"
scene="$root/scenes/tap.json"
link=(--clock realtime --link dds --dds-partition "$tag")
world_security=() hands_security=()  # --dds-security DIR of each host's participants (secure mode)

# world DIR [extra world_manager flags]: starts the world on its host; sets $world.
start_world() {
  local dir="$1"; shift
  ip netns exec "$world_ns" "$build/world_manager/world_manager" --scene "$scene" "${link[@]}" "${world_security[@]}" \
    --shm "${tag}_world" --log "$dir/world.csv" --summary "$dir/world.json" "$@" >"$dir/world.out" 2>&1 &
  world=$!; pids+=("$world")
}
# hands DIR USER TRAJECTORY: a controller and its device on the other host; sets $haptic and $device.
start_hands() {
  local dir="$1" user="$2" trajectory="$3"
  ip netns exec "$hands_ns" "$build/haptic_controller/haptic_controller" "${link[@]}" "${hands_security[@]}" \
    --shm "${tag}_$user" --log "$dir/haptic_$user.csv" --summary "$dir/haptic_$user.json" >"$dir/haptic_$user.out" 2>&1 &
  haptic=$!; pids+=("$haptic")
  ip netns exec "$hands_ns" "$build/spidar_sim/spidar_sim" --clock realtime --shm "${tag}_$user" \
    --trajectory "$trajectory" --attach-timeout 30 >"$dir/device_$user.out" 2>&1 &
  device=$!; pids+=("$device")
}
stop() {  # stop PID NAME: SIGTERM, and it must exit 0
  kill -TERM "$1"
  wait "$1" || fail "$2 exited with status $?"
}
# check DIR USER...: the world applied exactly what each controller rendered on the cube, nothing faulted.
check_ledger() {
  local dir="$1"; shift
  /usr/bin/python3 - "$dir" "$@" <<'PY'
import json, sys
dir, users = sys.argv[1], sys.argv[2:]
world = json.load(open(f"{dir}/world.json"))
applied = {(e["haptic_session"], e["endpoint"]): e["impulse_by_object_Ns"]["0"] for e in world["world"]["endpoints"]}
for user in users:
    haptic = json.load(open(f"{dir}/haptic_{user}.json"))["haptic"]
    rendered = haptic["impulse_by_object_Ns"].get("0")
    if rendered is None or max(abs(v) for v in rendered) < 0.1:
        sys.exit(f"{dir}: controller {user} rendered no push on the cube: {rendered}")
    mine = applied.get((haptic["haptic_session"], 0))
    for a in range(3):
        if mine is None or abs(mine[a] - rendered[a]) > 1e-12 * max(1.0, abs(rendered[a])):
            sys.exit(f"{dir}: controller {user} rendered {rendered} N·s, the world applied {mine}")
    if haptic["faults"] != 0:
        sys.exit(f"{dir}: controller {user} faulted")
    print(f"{dir}: controller {user}: rendered = applied = {rendered} N·s, {haptic.get('dds', {}).get('reports_sent')} reports sent")
PY
}

if [ "$mode" = secure ]; then
  creds="$out/credentials"
  bash "$root/scripts/dds_security.sh" "$creds" world controller observer >/dev/null
  bash "$root/scripts/dds_security.sh" "$out/other_ca" controller >/dev/null
  # 1. A tap across the hosts, both ends secured: the world applies exactly what the controller rendered.
  dir="$out/tap"; mkdir -p "$dir"
  world_security=(--dds-security "$creds/world") hands_security=(--dds-security "$creds/controller")
  start_world "$dir"
  start_hands "$dir" u tap
  wait "$device" || fail "secured tap: spidar_sim exited with status $?"
  stop "$haptic" "secured tap: haptic_controller"
  # 2. Refused while the secured world runs: no credentials, another CA, and permissions without the report topic.
  dir2="$out/refused"; mkdir -p "$dir2"
  for who in open other_ca observer; do
    case "$who" in
      open) flags=() ;;
      other_ca) flags=(--dds-security "$out/other_ca/controller") ;;
      observer) flags=(--dds-security "$creds/observer") ;;
    esac
    status=0
    ip netns exec "$hands_ns" "$build/haptic_controller/haptic_controller" "${link[@]}" "${flags[@]}" \
      --shm "${tag}_$who" --world-wait 5 >"$dir2/$who.out" 2>&1 || status=$?
    [ "$status" -ne 0 ] || fail "secured: a controller ($who) was served: $(cat "$dir2/$who.out")"
    echo "netns_test: secured: refused ($who): $(tail -1 "$dir2/$who.out")"
  done
  grep -q "Not Allowed By Security" "$dir2/observer.out" || fail "secured: the observer's writer was not refused"
  stop "$world" "secured tap: world_manager"
  check_ledger "$dir" u || fail "secured tap: the ledger disagrees"
  [ "$(grep -c "serves controller" "$dir/world.out")" -eq 1 ] ||
    fail "secured: the world served more than its one certified controller: $(cat "$dir/world.out")"
  # 3. One-way latency across the hosts, open and secured (bench_dds_link, one end on each host).
  if [ -x "$build/tests/bench_dds_link" ]; then
    for secure in "" "$creds"; do
      flags=(--seconds 5 --partition "${tag}_bench")
      [ -n "$secure" ] && flags+=(--secure "$secure")
      ip netns exec "$world_ns" "$build/tests/bench_dds_link" --role world "${flags[@]}" >"$out/bench_world.out" 2>&1 &
      bench=$!; pids+=("$bench")
      ip netns exec "$hands_ns" "$build/tests/bench_dds_link" --role controller "${flags[@]}" 2>&1 | grep "link," || true
      wait "$bench" || true
      grep "link," "$out/bench_world.out" || true
    done
  fi
  echo "netns_test: passed (secure)"
  exit 0
fi

if [ "$mode" = netem ]; then
  netem=1
  tc -n "$world_ns" qdisc add dev "$world_if" root netem delay 1ms 2>/dev/null || netem=0
  [ "$netem" = 1 ] || echo "netns_test: this kernel has no netem qdisc; the DDS transport's delay stage delays instead"
  plain_link=("${link[@]}")
  for delay_ms in 10 50; do
    dir="$out/delay$delay_ms"; mkdir -p "$dir"
    # One-way delay: each end delays what it sends (netem), or what it receives (the transport's stage).
    if [ "$netem" = 1 ]; then
      tc -n "$world_ns" qdisc replace dev "$world_if" root netem delay "${delay_ms}ms"
      tc -n "$hands_ns" qdisc replace dev "$hands_if" root netem delay "${delay_ms}ms"
    else
      link=("${plain_link[@]}" --dds-delay-ms "$delay_ms")
    fi
    start_world "$dir" --coupling local
    start_hands "$dir" u tap:rest=0.4
    wait "$device" || fail "delay $delay_ms ms: spidar_sim exited with status $?"
    stop "$haptic" "delay $delay_ms ms: haptic_controller"
    stop "$world" "delay $delay_ms ms: world_manager"
    check_ledger "$dir" u || fail "delay $delay_ms ms: the ledger disagrees"
    # The servo measures the round trip on the link: how many ticks after a report the frame that applied it came.
    /usr/bin/python3 - "$dir" "$delay_ms" <<'PY' || fail "delay $delay_ms ms: the round trip is shorter than the delay"
import json, sys
dir, delay_ms = sys.argv[1], float(sys.argv[2])
haptic = json.load(open(f"{dir}/haptic_u.json"))["haptic"]
round_trip = max(e["local_replayed_ticks_max"] for e in haptic["endpoints"])
world = json.load(open(f"{dir}/world.json"))
print(f"delay {delay_ms:g} ms: round trip as the servo measured it {round_trip} ticks, the cube stopped at x = "
      f"{world['objects']['cube']['position'][0]:.4f} m")
if round_trip < 2 * delay_ms:  # a 1 kHz servo: ticks are milliseconds
    sys.exit(f"round trip {round_trip} ticks < 2 x {delay_ms:g} ms")
PY
  done
  link=("${plain_link[@]}")
  echo "netns_test: passed (netem)"
  exit 0
fi

# 1. Packet loss.
for per_mille in 0 10 100; do
  dir="$out/loss$per_mille"; mkdir -p "$dir"
  if ((per_mille)); then
    export CYCLONEDDS_URI="<Internal><Test><XmitLossiness>$per_mille</XmitLossiness></Test></Internal>"
  fi
  start_world "$dir"
  start_hands "$dir" u tap
  wait "$device" || fail "loss $per_mille: spidar_sim exited with status $?"
  stop "$haptic" "loss $per_mille: haptic_controller"
  stop "$world" "loss $per_mille: world_manager"
  unset CYCLONEDDS_URI
  check_ledger "$dir" u || fail "loss $per_mille per mille: the ledger disagrees"
done

# 2. The link pulled down mid-press for 3 s (longer than the 2 s DDS lease) and brought back.
dir="$out/linkdown"; mkdir -p "$dir"
start_world "$dir" --coupling local
start_hands "$dir" u "press:x=0.03,surface_z=0.05,depth=0.01,hold=8"
for _ in $(seq 200); do grep -q "serves controller" "$dir/world.out" && break; sleep 0.05; done
sleep 2
ip -n "$hands_ns" link set "$hands_if" down
sleep 3
ip -n "$hands_ns" link set "$hands_if" up
wait "$device" || fail "link down: spidar_sim exited with status $?"
stop "$haptic" "link down: haptic_controller"
stop "$world" "link down: world_manager"
check_ledger "$dir" u || fail "link down: the ledger disagrees after the link came back"
/usr/bin/python3 - "$dir" <<'PY' || fail "link down: see above"
import csv, json, math, sys
dir = sys.argv[1]
haptic = json.load(open(f"{dir}/haptic_u.json"))["haptic"]
world = json.load(open(f"{dir}/world.json"))["world"]
# The controller held its last planes while no frame came (three world periods and more of the 3 s).
if haptic["stale_world_ticks"] < 1000:
    sys.exit(f"the controller called its planes stale for only {haptic['stale_world_ticks']} ticks")
# The world dropped the finger while no report came.
if world["stale_finger_steps"] < 20:
    sys.exit(f"the world dropped the finger for only {world['stale_finger_steps']} steps")
rows = list(csv.DictReader(open(f"{dir}/world.csv")))
fastest = max(math.sqrt(sum(float(r[f"cube.v{a}_mps"]) ** 2 for a in "xyz")) for r in rows)
if fastest > 0.1:
    sys.exit(f"the pressed cube reached {fastest} m/s: a burst")
print(f"{dir}: planes held {haptic['stale_world_ticks']} ticks, finger dropped {world['stale_finger_steps']} steps, "
      f"fastest cube {fastest:.4f} m/s")
PY
grep -q "is free again" "$dir/world.out" || fail "link down: the world never released the silent controller's slot"
[ "$(grep -c "serves controller" "$dir/world.out")" -ge 2 ] || fail "link down: the controller was not served again"

# 3. Four controllers on one world, pressing the cube's top near its corners.
dir="$out/four"; mkdir -p "$dir"
start_world "$dir"
ip netns exec "$hands_ns" "$build/viewer/viewer" "${link[@]:2}" --listen 127.0.0.1:0 --duration 6 \
  >"$dir/viewer.out" 2>"$dir/viewer.err" &
viewer=$!; pids+=("$viewer")
devices=() haptics=()
for user in a b c d; do
  case "$user" in a) x=0.015 y=-0.012 ;; b) x=0.045 y=-0.012 ;; c) x=0.015 y=0.012 ;; d) x=0.045 y=0.012 ;; esac
  start_hands "$dir" "$user" "press:x=$x,y=$y,surface_z=0.05,depth=0.01,hold=3"
  devices+=("$device"); haptics+=("$haptic")
done
for pid in "${devices[@]}"; do wait "$pid" || fail "four: a spidar_sim exited with status $?"; done
for pid in "${haptics[@]}"; do stop "$pid" "four: a haptic_controller"; done
stop "$world" "four: world_manager"
check_ledger "$dir" a b c d || fail "four controllers: the ledger disagrees"
wait "$viewer" || fail "four: the viewer exited with status $?"
grep -q "attached to the world at DDS domain 0 partition '$tag'" "$dir/viewer.err" ||
  fail "four: the viewer on the other host never saw the world: $(cat "$dir/viewer.err")"
echo "netns_test: passed"

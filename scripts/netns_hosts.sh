# SPDX-License-Identifier: Apache-2.0
# Two network hosts on this machine, for what crosses a network: network namespaces "<TAG>w" (the world's) and
# "<TAG>h" (the hands': controllers and devices), joined by a veth pair <TAG>a (10.231.0.1) – <TAG>b (10.231.0.2),
# with multicast routed over it (DDS discovery). Needs root and iproute2. Sourced, not run:
#
#   source scripts/netns_hosts.sh
#   make_hosts TAG || skip ...     sets world_ns, hands_ns, world_if, hands_if; returns 1 if namespaces cannot be made
#   ip netns exec "$world_ns" COMMAND ...
#   remove_hosts                   (also safe when make_hosts failed halfway)

make_hosts() {
  local tag="$1"
  world_ns="${tag}w" hands_ns="${tag}h" world_if="${tag}a" hands_if="${tag}b"
  [ "$(id -u)" -eq 0 ] || return 1
  command -v ip >/dev/null || return 1
  ip netns add "$world_ns" 2>/dev/null || return 1
  ip netns add "$hands_ns" &&
    ip link add "$world_if" type veth peer name "$hands_if" &&
    ip link set "$world_if" netns "$world_ns" &&
    ip link set "$hands_if" netns "$hands_ns" &&
    ip -n "$world_ns" addr add 10.231.0.1/24 dev "$world_if" &&
    ip -n "$hands_ns" addr add 10.231.0.2/24 dev "$hands_if" &&
    ip -n "$world_ns" link set lo up && ip -n "$hands_ns" link set lo up &&
    ip -n "$world_ns" link set "$world_if" up && ip -n "$hands_ns" link set "$hands_if" up &&
    ip -n "$world_ns" route add 224.0.0.0/4 dev "$world_if" &&
    ip -n "$hands_ns" route add 224.0.0.0/4 dev "$hands_if"
}

remove_hosts() {
  [ -n "${world_ns:-}" ] && ip netns del "$world_ns" 2>/dev/null
  [ -n "${hands_ns:-}" ] && ip netns del "$hands_ns" 2>/dev/null
  return 0
}

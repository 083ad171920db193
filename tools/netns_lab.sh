#!/usr/bin/env bash
# Several hosts on this machine: one Linux network namespace per host, each
# with its own network interface on one bridge (a switch), as a bench PC next
# to the device, a control PC and an observer laptop would be on one LAN.
# The stack's multicast crosses the bridge with ttl=1 exactly as it crosses a
# real switch. docs/operations.md, "Several hosts".
#
#   tools/netns_lab.sh up [HOST...]     (default hosts: device control observer)
#   tools/netns_lab.sh down
#   tools/netns_lab.sh status
#   tools/netns_lab.sh link HOST up|down   (a partition: the host's cable out)
#
# Names: namespace stw-HOST, its interface lab0 (10.77.0.N/24), the bridge
# stwbr0 (10.77.0.1) in this namespace, which also gets a route for the lab's
# multicast groups (239.255.77.0/24) so lcm-spy, the viewer and the launcher
# on this machine see the lab's bus. Other groups (239.255.76.67, the tests'
# private URLs) keep their routes. Needs root (CAP_NET_ADMIN). The tests run
# a lab of their own beside this one: STEWART_LAB_PREFIX, STEWART_LAB_SUBNET
# (three octets) and STEWART_LAB_GROUPS override the names.
set -euo pipefail

PREFIX=${STEWART_LAB_PREFIX:-stw}
BRIDGE=${PREFIX}br0
SUBNET=${STEWART_LAB_SUBNET:-10.77.0}
LAB_GROUPS=${STEWART_LAB_GROUPS:-239.255.77.0/24}

die() { echo "netns_lab: $*" >&2; exit 2; }
need_root() {
  [[ $(id -u) -eq 0 ]] || die "needs root (CAP_NET_ADMIN) to create namespaces and links"
  command -v ip >/dev/null || die "'ip' (iproute2) is missing: tools/setup.sh installs it"
}
lab_namespaces() { ip netns list 2>/dev/null | awk '{ print $1 }' | grep "^$PREFIX-" || true; }

up() {
  need_root
  local hosts=("$@")
  ((${#hosts[@]})) || hosts=(device control observer)
  ((${#hosts[@]} <= 200)) || die "at most 200 hosts"
  ip link show "$BRIDGE" >/dev/null 2>&1 && die "a lab is up already ('$0 down' first)"
  ip link add "$BRIDGE" type bridge
  # Without an IGMP querier a snooping bridge may stop forwarding a group:
  # a switch on a control LAN is usually set the same way, or has a querier.
  ip link set "$BRIDGE" type bridge mcast_snooping 0
  ip addr add "$SUBNET.1/24" dev "$BRIDGE"
  ip link set "$BRIDGE" up
  ip route add "$LAB_GROUPS" dev "$BRIDGE"
  local n=2 host ns
  for host in "${hosts[@]}"; do
    [[ $host =~ ^[a-z][a-z0-9]{0,7}$ ]] || die "host name '$host': 1-8 lower-case letters or digits"
    ns=$PREFIX-$host
    ip netns add "$ns"
    ip link add "$PREFIX-$host" type veth peer name lab0 netns "$ns"
    ip link set "$PREFIX-$host" master "$BRIDGE" up
    ip -n "$ns" link set lo up
    ip -n "$ns" addr add "$SUBNET.$n/24" dev lab0
    ip -n "$ns" link set lab0 up
    ip -n "$ns" route add 224.0.0.0/4 dev lab0
    echo "netns_lab: host $host: namespace $ns, $SUBNET.$n on lab0"
    n=$((n + 1))
  done
  echo "netns_lab: up; run a process on a host with: ip netns exec $PREFIX-HOST COMMAND"
  echo "netns_lab: the lab's LCM URL: udpm://239.255.77.1:7667?ttl=1"
}

down() {
  need_root
  local ns
  for ns in $(lab_namespaces); do
    # Processes left in a namespace keep it alive: stop them first.
    ip netns pids "$ns" 2>/dev/null | xargs -r kill -KILL 2>/dev/null || true
    ip netns del "$ns"
  done
  ip route del "$LAB_GROUPS" dev "$BRIDGE" 2>/dev/null || true
  ip link del "$BRIDGE" 2>/dev/null || true
  echo "netns_lab: down"
}

status() {
  if ! ip link show "$BRIDGE" >/dev/null 2>&1; then echo "netns_lab: down"; return 1; fi
  local ns
  for ns in $(lab_namespaces); do
    echo "$ns: $(ip -n "$ns" -brief addr show lab0 2>/dev/null | awk '{ print $2, $3 }')"
  done
}

link() {
  need_root
  local host=${1:-} state=${2:-}
  [[ -n $host && ($state == up || $state == down) ]] || die "usage: $0 link HOST up|down"
  ip link set "$PREFIX-$host" "$state"
  echo "netns_lab: $host's link $state"
}

case "${1:-}" in
  up) shift; up "$@" ;;
  down) down ;;
  status) status ;;
  link) shift; link "$@" ;;
  *) sed -n '2,20p' "$0" | sed 's/^# \{0,1\}//'; exit 2 ;;
esac

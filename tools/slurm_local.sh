#!/usr/bin/env bash
# A Slurm on this machine, to try `make grade ... ENGINE=slurm` before the university's cluster
# (docs/grading.md, "Grading on a Slurm cluster"); lab/test/grader/test_slurm.py starts and stops it too.
#
#   tools/slurm_local.sh start [--nodes N] [--cpus C]
#                                           # installs Debian's slurmctld, slurmd, slurm-client, munge if
#                                           # missing (root); N nodes, default 1; C CPUs each (below)
#   export SLURM_CONF=...                   # the line `start` prints: sbatch, squeue and the grader read it
#   tools/slurm_local.sh login COMMAND...   # COMMAND where the controller is reached (the "login node")
#   tools/slurm_local.sh status
#   tools/slurm_local.sh stop               # cancels what is queued, stops the daemons, waits until gone
#
# No systemd: munged, slurmctld and the slurmd run as children of this script's `start`, detached, in the
# foreground (-D), with every file they write (key, sockets, state, spool, logs, pids) in one folder:
# $EXAM_SLURM_DIR, default $EXAM_WS/slurm. One node: the controller and the node listen on 127.0.0.1
# only. Several nodes (--nodes 2): each slurmd in a network and UTS namespace of its own (hostname
# exam-nodeI, address 10.213.78.(I+1)), the controller in a third one (exam-ctl, 10.213.78.1) holding the
# bridge the nodes' veth pairs are joined to: addresses that exist nowhere else, on links this script
# makes and `stop` deletes; the file system is the machine's, shared as a cluster's would be. Each node
# gets its share of the machine's CPUs and memory, so one node and two offer the same CPUs, unless
# --cpus C gives each node C of them (1 to nproc: what its slurmd finds; each task takes one, so C is how
# many gradings a node runs at once, the local engine's JOBS for the cluster). sbatch and
# squeue reach the controller from its namespace (`login`). One munged and one key for all (its socket
# is in the folder: a munged of the machine, if any, is neither used nor disturbed). Jobs run as whoever
# submits them (the folder is readable by all, the key by root only): SlurmUser is root here (this
# script needs root to start the daemons); on a real cluster it is not.
set -euo pipefail

repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dir="${EXAM_SLURM_DIR:-${EXAM_WS:-$repo/.ws}/slurm}"
conf="$dir/slurm.conf"
#: The ports of the controller and the node (loopback only); change them when 6817/6818 are taken.
ctld_port="${EXAM_SLURM_PORT:-6817}"
slurmd_port=$((ctld_port + 1))
#: Seconds to wait for a daemon to come up, or to go.
wait_s=60
packages=(slurmctld slurmd slurm-client munge)
#: How long the controller waits for a silent slurmd before it declares the node DOWN and fails its
#: jobs (NODE_FAIL). Slurm's default is 300 s; a lost node costs the class that much more.
slurmd_timeout="${EXAM_SLURMD_TIMEOUT:-20}"
#: The private subnet of the several-node form: .1 the controller, .(I+1) node I.
subnet=10.213.78
#: The namespaces of this folder's cluster: one name per folder, so two folders' clusters never meet.
ns_prefix="exam_slurm_$(printf '%s' "$dir" | md5sum | cut -c1-8)"
nodes_file="$dir/nodes"
cpus_file="$dir/cpus"

say() { echo "slurm_local: $*"; }
die() { echo "slurm_local: $*" >&2; exit 1; }

alive() {  # alive NAME: the daemon whose pid file is $dir/NAME.pid runs
  local pid
  pid="$(cat "$dir/$1.pid" 2>/dev/null)" || return 1
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null
}

wait_until() {  # wait_until COMMAND...: retry COMMAND every 0.5 s for $wait_s s
  local deadline=$((SECONDS + wait_s))
  until "$@" >/dev/null 2>&1; do
    [ "$SECONDS" -lt "$deadline" ] || return 1
    sleep 0.5
  done
}

wait_up() {  # wait_up NAME COMMAND...: wait_until COMMAND succeeds, failing at once if the daemon NAME died
  local name="$1" deadline=$((SECONDS + wait_s))
  shift
  until "$@" >/dev/null 2>&1; do
    alive "$name" && [ "$SECONDS" -lt "$deadline" ] || return 1
    sleep 0.5
  done
}

nodes() { cat "$nodes_file" 2>/dev/null || echo 1; }
# The controller's network namespace, or nothing (one node: this machine's loopback).
ctl_ns() { [ "$(nodes)" -gt 1 ] && echo "${ns_prefix}_ctl" || true; }
in_ctl() {  # in_ctl COMMAND...: COMMAND where the controller is reached
  local ns
  ns="$(ctl_ns)"
  if [ -n "$ns" ]; then nsenter --net="/run/netns/$ns" -- "$@"; else "$@"; fi
}
daemon_names() {  # the pid files' names, the order `stop` ends them in
  local i
  if [ "$(nodes)" -gt 1 ]; then
    for ((i = 1; i <= $(nodes); i++)); do echo "slurmd-exam-node$i"; done
  else
    echo slurmd
  fi
  echo slurmctld
  echo munged
}
all_alive() {
  local name
  for name in $(daemon_names); do alive "$name" || return 1; done
}
nodes_idle() { [ "$(in_ctl sinfo -h -N -o '%t' | grep -cx 'idle')" -eq "$(nodes)" ]; }
queue_empty() { [ -z "$(in_ctl squeue -h -o '%A')" ]; }
gone() { ! kill -0 "$1" 2>/dev/null; }

write_conf() {  # write_conf N [CPUS]
  local n="$1" node ctl_host params i cpus="${2:-}" memory
  if [ "$n" -eq 1 ]; then
    # The node as slurmd itself sees it (CPUs, sockets, cores, RealMemory in MB), so Slurm never drains it.
    node="$(slurmd -C | head -1) NodeAddr=127.0.0.1 State=UNKNOWN"
    ctl_host="$(hostname)(127.0.0.1)"
    params=NoCtldInAddrAny,NoInAddrAny
  else
    # Each node its share of the machine (at least one CPU); the namespaces hold no other address, so
    # the daemons may listen on all of theirs.
    [ -n "$cpus" ] || { cpus=$(( $(nproc) / n )); [ "$cpus" -ge 1 ] || cpus=1; }
    memory=$(( $(slurmd -C | head -1 | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p') / n ))
    node=""
    for ((i = 1; i <= n; i++)); do
      node+="NodeName=exam-node$i NodeAddr=$subnet.$((i + 1)) CPUs=$cpus RealMemory=$memory State=UNKNOWN"$'\n'
    done
    ctl_host="exam-ctl($subnet.1)"
    params=""
  fi
  cat > "$conf" <<EOF
# Written by tools/slurm_local.sh: a Slurm of $n node(s) on this machine for trying the grader's Slurm engine.
ClusterName=examlocal
SlurmctldHost=$ctl_host
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
${params:+CommunicationParameters=$params}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool/%n
SlurmctldPidFile=$dir/slurmctld-own.pid
SlurmdPidFile=$dir/slurmd-%n-own.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd-%n.log
SlurmdTimeout=$slurmd_timeout
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
# A finished task stays visible to scontrol for 5 minutes: the grader reads why it failed there.
MinJobAge=300
$node
PartitionName=grading Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
}

make_network() {  # make_network N: the controller's namespace with its bridge, a namespace per node
  local n="$1" ctl="${ns_prefix}_ctl" i ns
  ip netns add "$ctl"
  ip -n "$ctl" link set lo up
  ip -n "$ctl" link add br0 type bridge
  ip -n "$ctl" addr add "$subnet.1/24" dev br0
  ip -n "$ctl" link set br0 up
  for ((i = 1; i <= n; i++)); do
    ns="${ns_prefix}_n$i"
    ip netns add "$ns"
    ip -n "$ns" link set lo up
    # Both ends made inside their namespaces: this machine's own network never sees them.
    ip link add "n$i" netns "$ctl" type veth peer name eth0 netns "$ns"
    ip -n "$ctl" link set "n$i" master br0 up
    ip -n "$ns" addr add "$subnet.$((i + 1))/24" dev eth0
    ip -n "$ns" link set eth0 up
  done
}

delete_network() {  # the namespaces of this folder's cluster, if any (deleting one deletes its veth)
  local ns
  for ns in $(ip netns list 2>/dev/null | awk '{print $1}' | grep "^${ns_prefix}_" || true); do
    ip netns del "$ns" 2>/dev/null || true
  done
}

launch() {  # launch NAME NAMESPACE HOSTNAME COMMAND...: a daemon detached, its pid in $dir/NAME.pid
  local name="$1" ns="$2" host="$3"
  shift 3
  if [ -z "$ns" ]; then
    setsid "$@" </dev/null >>"$dir/$name.out" 2>&1 &
  else
    # nsenter, unshare and sh each exec the next: the pid is the daemon's. nsenter enters the network
    # namespace only (`ip netns exec` would also remount /sys, hiding the cgroups a root box uses).
    setsid nsenter --net="/run/netns/$ns" -- unshare --uts -- sh -c 'hostname "$0" && exec "$@"' "$host" "$@" \
      </dev/null >>"$dir/$name.out" 2>&1 &
  fi
  echo $! > "$dir/$name.pid"
}

start() {
  local n=1 cpus="" i
  while [ $# -gt 0 ]; do
    case "$1" in
      --nodes) n="${2:-}"; shift 2 || die "--nodes needs a number" ;;
      --nodes=*) n="${1#--nodes=}"; shift ;;
      --cpus) cpus="${2:-}"; shift 2 || die "--cpus needs a number" ;;
      --cpus=*) cpus="${1#--cpus=}"; shift ;;
      *) die "start: unknown option $1 (start [--nodes N] [--cpus C])" ;;
    esac
  done
  [[ "$n" =~ ^[1-9][0-9]?$ ]] && [ "$n" -le 50 ] || die "--nodes takes 1 to 50, not '$n'"
  if [ -n "$cpus" ]; then
    [[ "$cpus" =~ ^[1-9][0-9]*$ ]] && [ "$cpus" -le "$(nproc)" ] ||
      die "--cpus takes 1 to $(nproc) (the CPUs a node's slurmd finds on this machine), not '$cpus'"
    [ "$n" -gt 1 ] || die "--cpus is for several nodes: one node offers what slurmd finds (slurmd -C)"
  fi
  if [ "$(nodes)" -eq "$n" ] && [ "$(cat "$cpus_file" 2>/dev/null)" = "$cpus" ] && all_alive; then
    say "already running ($dir)"
    echo "export SLURM_CONF=$conf"
    [ "$n" -eq 1 ] || echo "netns $(ctl_ns)"
    return 0
  fi
  [ "$(id -u)" -eq 0 ] || die "starting the daemons needs root (they run jobs as whoever submits them)"
  "$repo/tools/install_deps.sh" "${packages[@]}"
  for cmd in munged slurmctld slurmd sbatch nsenter unshare ip; do
    command -v "$cmd" >/dev/null || die "$cmd not found: install ${packages[*]} iproute2 util-linux"
  done
  stop_daemons  # what a crashed earlier start left
  delete_network
  mkdir -p "$dir/state" "$dir/spool"
  # Readable by all (a teacher's sbatch reads slurm.conf and reaches munge's socket); the key and the
  # controller's state are root's alone.
  chmod 755 "$dir" "$dir/spool"
  chmod 700 "$dir/state"
  # munge refuses a key others can read; 1 KB of randomness, as `mungekey` makes.
  if [ ! -s "$dir/munge.key" ]; then
    (umask 077 && dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 status=none)
  fi
  echo "$n" > "$nodes_file"
  echo "$cpus" > "$cpus_file"
  # A start that fails half way stops what it started.
  trap 'stop_daemons; delete_network' EXIT
  write_conf "$n" "$cpus"
  [ "$n" -eq 1 ] || make_network "$n"
  launch munged "" "" munged --foreground --force --key-file="$dir/munge.key" --socket="$dir/munge.socket" \
    --pid-file="$dir/munged-own.pid" --seed-file="$dir/munge.seed" --log-file="$dir/munged.log"
  wait_up munged test -S "$dir/munge.socket" || die "munged did not start: $(tail -3 "$dir/munged.log" 2>/dev/null)"
  export SLURM_CONF="$conf"
  launch slurmctld "$(ctl_ns)" exam-ctl slurmctld -D -f "$conf"
  wait_up slurmctld in_ctl scontrol ping ||
    die "slurmctld did not start (port $ctld_port taken? EXAM_SLURM_PORT chooses another): $(tail -3 "$dir/slurmctld.log")"
  if [ "$n" -eq 1 ]; then
    launch slurmd "" "" slurmd -D -f "$conf"
  else
    for ((i = 1; i <= n; i++)); do
      launch "slurmd-exam-node$i" "${ns_prefix}_n$i" "exam-node$i" slurmd -D -f "$conf"
    done
  fi
  wait_until nodes_idle ||
    die "the nodes did not become idle: $(in_ctl sinfo -h -N -o '%N %t %E' | tr '\n' ' ');" \
      "$(tail -5 "$dir"/slurmd*.log)"
  trap - EXIT
  say "running: $(in_ctl sinfo -h -N -o 'node %N, %c CPUs, %t' | tr '\n' ';' | sed 's/;$//') ($dir)"
  [ "$n" -eq 1 ] || say "the controller is reached from its namespace: $0 login COMMAND... (netns $(ctl_ns))"
  echo "export SLURM_CONF=$conf"
  [ "$n" -eq 1 ] || echo "netns $(ctl_ns)"
}

stop_daemons() {
  local name pid
  for name in $(daemon_names); do
    if alive "$name"; then
      pid="$(cat "$dir/$name.pid")"
      kill -TERM "$pid" 2>/dev/null || true
      if ! wait_until gone "$pid"; then
        say "$name (pid $pid) ignored SIGTERM for ${wait_s} s: killing it"
        kill -KILL "$pid" 2>/dev/null || true
      fi
    fi
    rm -f "$dir/$name.pid"
  done
}

stop() {
  if [ -f "$conf" ] && alive slurmctld; then
    export SLURM_CONF="$conf"
    # A job's step (slurmstepd and the task) outlives slurmd by design: cancel every job first.
    in_ctl scancel --full --quiet --partition=grading 2>/dev/null || true
    wait_until queue_empty || say "jobs still queued after ${wait_s} s: $(in_ctl squeue -h -o '%i %T' | tr '\n' ' ')"
  fi
  stop_daemons
  delete_network
  rm -f "$nodes_file" "$cpus_file"
  say "stopped"
}

status() {
  local name
  for name in $(daemon_names); do
    if alive "$name"; then echo "$name: running (pid $(cat "$dir/$name.pid"))"; else echo "$name: stopped"; fi
  done
  if [ -f "$conf" ] && alive slurmctld; then
    SLURM_CONF="$conf" in_ctl sinfo -N -o '%N %c %t %E'
    SLURM_CONF="$conf" in_ctl squeue
    echo "export SLURM_CONF=$conf"
  fi
}

login() {
  [ $# -gt 0 ] || set -- "${SHELL:-/bin/bash}"
  alive slurmctld || die "no Slurm running in $dir: $0 start first"
  SLURM_CONF="$conf" in_ctl "$@"
}

command="${1:-}"
shift || true
case "$command" in
  start) start "$@" ;;
  stop) stop ;;
  status) status ;;
  login) login "$@" ;;
  *) die "usage: $0 start [--nodes N] | login COMMAND... | status | stop" \
       "(state in \$EXAM_SLURM_DIR, default \$EXAM_WS/slurm)" ;;
esac

#!/usr/bin/env bash
# A single-node Slurm on this machine, to try `make grade ... ENGINE=slurm` before the university's cluster
# (docs/grading.md, "Grading on a Slurm cluster"); lab/test/grader/test_slurm.py starts and stops it too.
#
#   tools/slurm_local.sh start    # installs Debian's slurmctld, slurmd, slurm-client, munge if missing (root)
#   export SLURM_CONF=...         # the line `start` prints: sbatch, squeue and the grader read it
#   tools/slurm_local.sh status
#   tools/slurm_local.sh stop     # cancels what is still queued, stops the daemons, waits until they are gone
#
# No systemd: munged, slurmctld and slurmd run as children of this script's `start`, detached, with every
# file they write (key, sockets, state, spool, logs, pids) in one folder: $EXAM_SLURM_DIR, default
# $EXAM_WS/slurm. The controller and the node listen on 127.0.0.1 only; munge's socket is in that folder,
# so a munged of the machine (if any) is neither used nor disturbed. Jobs run as whoever submits them:
# SlurmUser is root here (this script needs root to start the daemons); on a real cluster it is not.
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

node_idle() { sinfo -h -o '%t' | grep -qx 'idle'; }
queue_empty() { [ -z "$(squeue -h -o '%A')" ]; }
gone() { ! kill -0 "$1" 2>/dev/null; }

write_conf() {
  # The node as slurmd itself sees it (CPUs, sockets, cores, RealMemory in MB), so Slurm never drains it.
  local node
  node="$(slurmd -C | head -1)"
  cat > "$conf" <<EOF
# Written by tools/slurm_local.sh: a single-node Slurm for trying the grader's Slurm engine.
ClusterName=examlocal
SlurmctldHost=$(hostname)(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
CommunicationParameters=NoCtldInAddrAny,NoInAddrAny
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld-own.pid
SlurmdPidFile=$dir/slurmd-own.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
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
$node NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=grading Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
}

start() {
  if alive munged && alive slurmctld && alive slurmd; then
    say "already running ($dir)"
    echo "export SLURM_CONF=$conf"
    return 0
  fi
  [ "$(id -u)" -eq 0 ] || die "starting the daemons needs root (they run jobs as whoever submits them)"
  "$repo/tools/install_deps.sh" "${packages[@]}"
  for cmd in munged slurmctld slurmd sbatch; do
    command -v "$cmd" >/dev/null || die "$cmd not found: install ${packages[*]}"
  done
  stop_daemons  # what a crashed earlier start left
  mkdir -p "$dir/state" "$dir/spool"
  chmod 700 "$dir"
  # munge refuses a key others can read; 1 KB of randomness, as `mungekey` makes.
  if [ ! -s "$dir/munge.key" ]; then
    (umask 077 && dd if=/dev/urandom of="$dir/munge.key" bs=1024 count=1 status=none)
  fi
  write_conf
  setsid munged --foreground --force --key-file="$dir/munge.key" --socket="$dir/munge.socket" \
    --pid-file="$dir/munged-own.pid" --seed-file="$dir/munge.seed" --log-file="$dir/munged.log" \
    </dev/null >>"$dir/munged.out" 2>&1 &
  echo $! > "$dir/munged.pid"
  # A start that fails half way stops what it started.
  trap 'stop_daemons' EXIT
  wait_up munged test -S "$dir/munge.socket" || die "munged did not start: $(tail -3 "$dir/munged.log" 2>/dev/null)"
  export SLURM_CONF="$conf"
  setsid slurmctld -D -f "$conf" </dev/null >>"$dir/slurmctld.out" 2>&1 &
  echo $! > "$dir/slurmctld.pid"
  wait_up slurmctld scontrol ping ||
    die "slurmctld did not start (port $ctld_port taken? EXAM_SLURM_PORT chooses another): $(tail -3 "$dir/slurmctld.log")"
  setsid slurmd -D -f "$conf" </dev/null >>"$dir/slurmd.out" 2>&1 &
  echo $! > "$dir/slurmd.pid"
  wait_up slurmd node_idle ||
    die "the node did not become idle: $(sinfo -h -N -o '%N %t %E'); $(tail -5 "$dir/slurmd.log")"
  trap - EXIT
  say "running: $(sinfo -h -N -o 'node %N, %c CPUs, %t') ($dir)"
  echo "export SLURM_CONF=$conf"
}

stop_daemons() {
  local name pid
  for name in slurmd slurmctld munged; do
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
    scancel --full --quiet --partition=grading 2>/dev/null || true
    wait_until queue_empty || say "jobs still queued after ${wait_s} s: $(squeue -h -o '%i %T' | tr '\n' ' ')"
  fi
  stop_daemons
  say "stopped"
}

status() {
  local name
  for name in munged slurmctld slurmd; do
    if alive "$name"; then echo "$name: running (pid $(cat "$dir/$name.pid"))"; else echo "$name: stopped"; fi
  done
  if [ -f "$conf" ] && alive slurmctld; then
    SLURM_CONF="$conf" sinfo -N -o '%N %c %t %E'
    SLURM_CONF="$conf" squeue
    echo "export SLURM_CONF=$conf"
  fi
}

case "${1:-}" in
  start) start ;;
  stop) stop ;;
  status) status ;;
  *) die "usage: $0 start|stop|status   (state in \$EXAM_SLURM_DIR, default \$EXAM_WS/slurm)" ;;
esac

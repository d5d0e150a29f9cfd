#!/usr/bin/env bash
# `make soak` (not part of `make test`): the default flight of mydrone with the exam node for
# SOAK_MINUTES (default 30), recorded to a bag while the exam node's memory is sampled, then checked
# offline by lab/soak/soak_check.py (LED changes and calls against an independent debounce oracle applied
# to the published /altitude, nothing lost or repeated, no memory growth). Prints the figures.
#   SOAK_MINUTES=3 make soak    a short run (the default flight loops every 100 s: 3 min hold 2 WARNINGs)
#   SOAK_DIR=/some/dir          where the bag, memory samples and logs go (default .ws/soak/<UTC time>)
# It runs on a master of its own (free port) and stops every process it started, whatever happens.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
source "$repo/tools/env.sh"

minutes="${SOAK_MINUTES:-30}"
threshold=1300
delay=5
dir="${SOAK_DIR:-$EXAM_WS/soak/$(date -u +%Y%m%dT%H%M%SZ)}"
mkdir -p "$dir/log"
port="$(/usr/bin/python3 -c \
  'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')"
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_LOG_DIR="$dir/log"

groups=()
descendants() {
  local child
  for child in $(ps -o pid= --ppid "$1"); do echo "$child"; descendants "$child"; done
}
# Ctrl-C a process group as a terminal would; SIGKILL it after 20 s. roslaunch puts each node in a
# session of its own, so the fallback also kills every descendant found before the Ctrl-C.
stop_group() {
  local pgid=$1 i family
  family="$(descendants "$pgid")"
  kill -INT -- "-$pgid" 2>/dev/null || return 0
  for i in $(seq 200); do
    kill -0 -- "-$pgid" 2>/dev/null || return 0
    sleep 0.1
  done
  # shellcheck disable=SC2086  # one pid per word
  kill -KILL -- "-$pgid" $family 2>/dev/null || true
}
cleanup() {
  local status=$? i
  trap - EXIT INT TERM
  for (( i=${#groups[@]}-1; i>=0; i-- )); do stop_group "${groups[i]}"; done
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM
# Each in a session of its own, so its group id is its pid and stopping the group stops its children.
start() { local name=$1; shift; setsid "$@" > "$dir/$name.out" 2>&1 & groups+=($!); }

echo "soak: $minutes min of the default flight, threshold $threshold m, delay $delay s; output in $dir"
start roscore roscore -p "$port"
/usr/bin/python3 "$repo/exam/test/ops/probe.py" --node /rosout --timeout 30 > /dev/null \
  || { echo "soak: the master did not come up, see $dir/roscore.out" >&2; exit 1; }
# Recording starts before the flight, so the LED's initial GREEN and the first readings are in the bag.
start record rosbag record -O "$dir/soak.bag" /temperature /pressure /altitude /alt_warn_led /rosout \
  /diagnostics __name:=soak_record
start launch roslaunch exam exam.launch threshold:="$threshold" delay:="$delay"
/usr/bin/python3 "$repo/lab/soak/soak_check.py" sample --seconds "$((minutes * 60))" --csv "$dir/rss.csv"

# Stop the flight, then the recorder (SIGINT lets it close the bag), then the master.
for (( i=${#groups[@]}-1; i>=0; i-- )); do stop_group "${groups[i]}"; done
groups=()
/usr/bin/python3 "$repo/lab/soak/soak_check.py" check --bag "$dir/soak.bag" --rss "$dir/rss.csv" \
  --threshold "$threshold" --delay "$delay"

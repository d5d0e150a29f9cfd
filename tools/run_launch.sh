#!/usr/bin/env bash
# `make run` and `make run-submarine`: roslaunch one of exam's launch files in the workspace
# environment, after printing what to type in a second shell to watch it. Both nodes are required, so
# the launch ends when one of them stops; roslaunch then exits 0 all the same and its last lines are
# its own shutdown messages. So when a required node died, this script prints the node's FATAL message
# (a bad parameter: the node names it and its value) as its last line and exits 1.
# Usage: tools/run_launch.sh exam.launch|exam_submarine.launch [roslaunch arguments, e.g. delay:=3]
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
source "$repo/tools/env.sh"
launch="$1"
shift

case "$launch" in
  exam.launch) output=altitude led=alt_warn_led label="ALT WARN" loop="the flight repeats" ;;
  exam_submarine.launch) output=depth led=depth_warn_led label="DEPTH WARN" loop="the dive repeats" ;;
  *) echo "usage: $0 exam.launch|exam_submarine.launch [name:=value ...]" >&2; exit 2 ;;
esac
# Measured with the default arguments (README): RED about 47 s after the drone starts, GREEN at 70 s.
when="the $label LED: GREEN"
if [ $# -eq 0 ]; then
  when="$when, RED about 50 s from now, GREEN again about 22 s later; $loop every 100 s"
fi

# What a second shell needs to reach the same workspace and master.
env_line="source $repo/tools/env.sh"
if [ "$EXAM_WS" != "$repo/.ws" ]; then
  env_line="export EXAM_WS=$EXAM_WS && $env_line"
fi
if [ "$ROS_MASTER_URI" != "http://localhost:11311" ]; then
  env_line="export ROS_MASTER_URI=$ROS_MASTER_URI && $env_line"
fi
cat <<EOF
Running: roslaunch exam $launch${*:+ $*} (Ctrl-C stops it)
To watch it, in a second shell:
  $env_line
  rostopic echo /$output    # the estimate (m), 10 times a second
  rostopic echo /$led    # $when
EOF

# A log directory of this run alone (a master already running would share its run_id directory).
log_root="${ROS_LOG_DIR:-${ROS_HOME:-$HOME/.ros}/log}"
export ROS_LOG_DIR="$log_root/make-run-$(date -u +%Y%m%dT%H%M%SZ)-$$"
status=0
roslaunch exam "$launch" "$@" || status=$?

# The run's logs: <ROS_LOG_DIR>/<run_id>/*.log (find skips the symbolic link `latest`).
mapfile -d '' -t logs < <(find "$ROS_LOG_DIR" -type f -name '*.log' -print0 2>/dev/null)
[ "${#logs[@]}" -gt 0 ] || exit "$status"
# roslaunch logs its own messages too: "REQUIRED process [mydrone-2] has died!".
died="$(grep -ho 'REQUIRED process \[[^]]*\] has died' "${logs[@]}" | head -n 1 || true)"
if [ -z "$died" ]; then
  exit "$status"
fi
# rospy writes a node's logfatal to its log file as "[rosout][CRITICAL] <date> <time>: <message>".
reasons="$(grep -h '^\[rosout\]\[CRITICAL\]' "${logs[@]}" \
  | sed 's/^\[rosout\]\[CRITICAL\] [^ ]* [^ ]*: //' || true)"
echo "================================================================================"
if [ -n "$reasons" ]; then
  echo "The launch stopped: ${died#REQUIRED }. Its FATAL message (logs: $ROS_LOG_DIR):"
  echo "$reasons"
else
  echo "The launch stopped: ${died#REQUIRED } without a FATAL message (its output is above;" \
    "logs: $ROS_LOG_DIR)"
fi
exit 1

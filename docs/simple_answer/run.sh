#!/usr/bin/env bash
# `make run-simple [SHEET=altitude|depth] [ARGS='threshold:=1200']`: the simple answer of docs/report.md
# (docs/simple_answer/exam) built and run on its own, as a student has it.
# It is a second package named `exam`, so the repository's workspace never builds it (CATKIN_IGNORE):
# it gets a catkin workspace of its own, $EXAM_WS/simple_answer (.ws/simple_answer by default), whose
# src/ links to the drones, drone_sim and node_kit (what they share) and the simple answer, as in question 1 of the report. No other
# workspace is its underlay, so `roslaunch exam ...` there can only find the simple answer's `exam`.
# Then tools/run_launch.sh runs the sheet's launch file in that workspace (Ctrl-C stops it).
# Usage: docs/simple_answer/run.sh [--build-only] altitude|depth [roslaunch arguments, e.g. threshold:=1200]
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
build_only=""
if [ "${1:-}" = "--build-only" ]; then
  build_only=1
  shift
fi
case "${1:-}" in
  altitude) launch=exam.launch ;;
  depth) launch=exam_submarine.launch ;;
  *) echo "usage: $0 [--build-only] altitude|depth [name:=value ...] (got: ${1:-nothing})" >&2; exit 2 ;;
esac
shift

ws="${EXAM_WS:-$repo/.ws}/simple_answer"
# Forget every workspace of this shell (the repository's .ws/ has its own `exam`): only ROS itself stays.
unset CMAKE_PREFIX_PATH ROS_PACKAGE_PATH PYTHONPATH ROS_DISTRO
export PATH="/usr/bin:/bin:$PATH"
if [ -f /opt/ros/noetic/setup.bash ]; then
  set +u
  source /opt/ros/noetic/setup.bash
  set -u
fi

mkdir -p "$ws/src"
for package in node_kit drone_sim mydrone submarinedrone docs/simple_answer/exam; do
  ln -sfn "$repo/$package" "$ws/src/$(basename "$package")"
done
cd "$ws"
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 > "$ws/build.log" 2>&1 \
  || { tail -n 40 "$ws/build.log"; echo "run-simple: catkin_make failed, full log in $ws/build.log" >&2; exit 1; }
echo "run-simple: the simple answer built in $ws"
[ -n "$build_only" ] && exit 0
EXAM_WS="$ws" exec "$repo/tools/run_launch.sh" "$launch" "$@"

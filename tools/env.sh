# Sourced (never run) by the Makefile's recipes and scripts: the ROS environment of the workspace.
# ROS 1 needs the system interpreter: a pyenv or venv `python3` first on PATH has no rospy, and
# rostest's hztest (#!/usr/bin/env python3) dies under it. So /usr/bin goes first.
export PATH="/usr/bin:/bin:$PATH"
# ROS's setup scripts read unset variables: relax `set -u` while sourcing them.
_nounset=$([[ $- == *u* ]] && echo 1 || true)
set +u
if [ -f /opt/ros/noetic/setup.bash ] && [ -z "${ROS_DISTRO:-}" ]; then
  source /opt/ros/noetic/setup.bash
fi
_repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export EXAM_WS="${EXAM_WS:-$_repo/.ws}"
if [ -f "$EXAM_WS/devel/setup.bash" ]; then
  source "$EXAM_WS/devel/setup.bash"
fi
[ -n "$_nounset" ] && set -u
unset _repo _nounset

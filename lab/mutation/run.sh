#!/usr/bin/env bash
# make mutation: mutation testing of the answer's code with cosmic-ray (lab/mutation/mutation.toml).
# cosmic-ray writes each mutant into the file on disk, so everything runs in a scratch copy of the
# repository with a catkin workspace of its own, under $EXAM_WS/mutation/; the working tree is never
# touched, and a crash leaves a mutant only in the scratch copy, which the next run makes anew.
# cosmic-ray lives in a virtual environment that sees Debian's rospy (--system-site-packages).
# Usage: lab/mutation/run.sh [group name ...]   (default: every group)
# Report: $EXAM_WS/mutation/report.md.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
source "$repo/tools/env.sh"
COSMIC_RAY_VERSION=8.7.0
venv="$EXAM_WS/mutation-venv"
out="$EXAM_WS/mutation"

if [ "$("$venv/bin/cosmic-ray" --version 2>/dev/null)" != "cosmic-ray, version $COSMIC_RAY_VERSION" ]; then
  echo "mutation: installing cosmic-ray $COSMIC_RAY_VERSION into $venv"
  /usr/bin/python3 -m venv --system-site-packages "$venv"
  "$venv/bin/python" -m pip install -q "cosmic-ray==$COSMIC_RAY_VERSION" > "$EXAM_WS/mutation-venv.log" 2>&1 \
    || { tail -n 20 "$EXAM_WS/mutation-venv.log"; echo "mutation: pip failed: $EXAM_WS/mutation-venv.log" >&2
         exit 1; }
fi

# The scratch copy: the files git tracks or would track (new files included, .ws/ and caches not).
rm -rf "$out"
mkdir -p "$out/tree" "$out/ros_home"
(cd "$repo" && git ls-files -z --cached --others --exclude-standard | tar -cf - --null -T -) \
  | tar -xf - -C "$out/tree"
# Its own workspace, so every import and every rosrun of the tests resolves to the scratch copy; the
# caller's workspace must not leak in.
unset PYTHONPATH ROS_PACKAGE_PATH CMAKE_PREFIX_PATH
EXAM_WS="$out/ws" "$out/tree/tools/build_ws.sh"
export EXAM_WS="$out/ws"
source "$out/tree/tools/env.sh"
# Logs and standalone rostest results stay in the scratch directory; no stale bytecode of a mutant.
export ROS_HOME="$out/ros_home" PYTHONDONTWRITEBYTECODE=1

cd "$out/tree"
start=$(date +%s)
"$venv/bin/python" "$repo/lab/mutation/run.py" "$repo/lab/mutation/mutation.toml" \
  "$repo/lab/mutation/known_mutants.toml" "$out" "$@"
echo "mutation: $(( ($(date +%s) - start) / 60 )) min $(( ($(date +%s) - start) % 60 )) s"

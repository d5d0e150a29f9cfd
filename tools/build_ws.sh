#!/usr/bin/env bash
# Builds the catkin workspace .ws/ (gitignored) whose src/ links to each package of this repo.
# Links go to the packages, not to the repo root, so catkin never walks into .ws/ again.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
source "$repo/tools/env.sh"

mkdir -p "$EXAM_WS/src"
# A user who clones this repo into their own workspace's src/ must not see .ws/ packages twice.
touch "$EXAM_WS/CATKIN_IGNORE"
for pkg in "$repo"/*/package.xml; do
  dir="$(dirname "$pkg")"
  ln -sfn "$dir" "$EXAM_WS/src/$(basename "$dir")"
done
# Drop links to packages that no longer exist.
find "$EXAM_WS/src" -maxdepth 1 -xtype l -delete

cd "$EXAM_WS"
catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCATKIN_ENABLE_TESTING=ON "$@" > "$EXAM_WS/build.log" 2>&1 \
  || { tail -n 40 "$EXAM_WS/build.log"; echo "build_ws: catkin_make failed, full log in $EXAM_WS/build.log" >&2; exit 1; }
echo "build_ws: workspace built in $EXAM_WS"

#!/usr/bin/env bash
# `make soak` (not part of `make test`): the default flight of mydrone with the exam node for
# SOAK_MINUTES (default 30), recorded to a bag while the exam node's memory is sampled, then checked
# offline by lab/soak/soak_check.py (LED changes and calls against an independent debounce oracle applied
# to the published /altitude, nothing lost or repeated, no memory growth). Prints the figures.
#   SOAK_MINUTES=3 make soak    a short run (the default flight loops every 100 s: 3 min hold 2 WARNINGs)
#   SOAK_DIR=/some/dir          where the bag, memory samples and logs go (default $EXAM_WS/soak/<UTC time>)
# It runs on a master of its own (free port) and stops every process it started, whatever happens:
# lab/soak/soak.py runs them under exam_lab's supervisor, and the trap ends what it could not.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
source "$repo/tools/env.sh"

dir="$(realpath -m "${SOAK_DIR:-$EXAM_WS/soak/$(date -u +%Y%m%dT%H%M%SZ)}")"
mkdir -p "$dir"
# Every process of the run carries its folder in its environment.
trap '/usr/bin/python3 -m exam_lab.harness.supervisor --cleanup "$dir"' EXIT
trap 'exit 130' INT TERM
/usr/bin/python3 "$repo/lab/soak/soak.py" --dir "$dir" --minutes "${SOAK_MINUTES:-30}"

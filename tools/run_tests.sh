#!/usr/bin/env bash
# Runs the catkin test targets (every package's pytest unit tests and rostests) and prints the summary
# line `N passed, N failed, N skipped`; exits non-zero when anything failed or no test ran.
# Usage: tools/run_tests.sh [catkin target...]   (default run_tests; several run in one go, one summary)
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
source "$repo/tools/env.sh"
targets=("${@:-run_tests}")
results="$EXAM_WS/build/test_results"

rm -rf "$results"
cd "$EXAM_WS"
# catkin's run_tests exits 0 even when tests fail: the verdict comes from the JUnit files below.
catkin_make "${targets[@]}" -j1 2>&1 | tee "$EXAM_WS/test.log" | grep -E "^\[(ROSTEST|ROSUNIT)\]|^ *\[(PASSED|FAILED)\]|^SUMMARY|^ \* RESULT|^FAILURE|^ERROR|passed|failed" || true
/usr/bin/python3 "$repo/tools/test_summary.py" "$results"

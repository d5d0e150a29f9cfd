#!/usr/bin/env bash
# `make bench`: measures the exam node against lab/bench/baseline_exam_node.py and writes
# docs/benchmarks.md and docs/figures/bench_fleet.png (80 minutes measured with BENCH_PROFILE=1 on two cores
# on 2026-11-27: the node's stages 13 minutes, then the grader's stage, which grades every test package alone
# and a class of 60 twice, 67 minutes).
#   BENCH_QUICK=1    a few seconds per stage; results go to $EXAM_WS/bench-quick/, docs/ is untouched
#   BENCH_STAGES=rate,fleet  only these stages (rate latency slow max_rate fleet grader), also to $EXAM_WS/bench-quick/
#   BENCH_FLEET_SIZES=5,20,50  the fleet sizes of ours (default 1,5,10,20,50,100: 200 nodes and the
#                    master's CPU at 100 pairs need a machine with the cores and about 8 GB for them)
# A full run ends with the grader's speed (lab/bench/grader_bench.py: a class of 60 at JOBS 4 and 6,
# 2140 s on two cores with --jobs 4 alone on 2026-12-02, a second class more at JOBS 6), recorded in lab/bench/grader.md and rendered into docs/benchmarks.md.
#   BENCH_PROFILE=1  also profile ours with py-spy (installed from PyPI into a throwaway directory)
#   BENCH_RENDER_ONLY=1  measure nothing: render the docs again from the last results
# Every process it starts carries the run's log folder in its environment (exam_lab's supervisor); the
# trap ends exactly those on exit, error or Ctrl-C, so nothing outlives the run.
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
source "$repo/tools/env.sh"

scratch="$(mktemp -d /tmp/exam-bench.XXXXXX)"
bench_pid=""

cleanup() {
  local status=$?
  trap - EXIT INT TERM
  if [ -n "$bench_pid" ] && kill -0 "$bench_pid" 2>/dev/null; then
    kill -TERM "$bench_pid" 2>/dev/null || true
    wait "$bench_pid" 2>/dev/null || true
  fi
  # Whatever bench.py could not stop itself (it was killed hard): every process marked with its logs.
  /usr/bin/python3 -m exam_lab.harness.supervisor --cleanup "$scratch/logs" || true
  if [ "$status" -eq 0 ]; then
    rm -rf "$scratch"
  else
    echo "bench: failed (status $status); node logs kept in $scratch/logs" >&2
  fi
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

mkdir -p "$scratch/logs"
args=(--log-dir "$scratch/logs")
# The exact command, as the report prints it: the BENCH_ variables change what is measured.
command="$({ env | grep -E '^BENCH_(QUICK|PROFILE|STAGES|FLEET_SIZES)=' || true; } | sort | tr '\n' ' ')make bench"
if [ "$EXAM_WS" != "$repo/.ws" ]; then
  command="EXAM_WS=$EXAM_WS $command"
fi
# The grader's stage is grader_bench.py, run after bench.py: a full run records it; BENCH_STAGES=grader
# runs it alone into bench-quick/; BENCH_QUICK skips it (its reference pass alone takes minutes).
grader=""
stages="${BENCH_STAGES:-}"
if [ -z "$stages" ] && [ "${BENCH_QUICK:-0}" != 1 ]; then
  grader=record
elif [[ ",$stages," == *,grader,* ]]; then
  grader=quick
  stages="$(echo ",$stages," | sed 's/,grader,/,/g; s/^,//; s/,$//')"
fi
if [ -n "$stages" ]; then
  args+=(--stages "$stages")
fi
if [ -n "${BENCH_FLEET_SIZES:-}" ]; then
  args+=(--fleet-sizes "$BENCH_FLEET_SIZES")
fi
if [ "${BENCH_QUICK:-0}" = 1 ] || [ -n "${BENCH_STAGES:-}" ]; then
  out="$EXAM_WS/bench-quick"
  mkdir -p "$out"
  if [ "${BENCH_QUICK:-0}" = 1 ]; then
    args+=(--quick)
  fi
  args+=(--out "$out" --figure "$out/bench_fleet.png" --json "$out/bench_results.json"
         --command "$command")
else
  args+=(--out "$repo/docs" --figure "$repo/docs/figures/bench_fleet.png"
         --json "$repo/lab/bench/results.json" --command "$command")
fi

if [ "${BENCH_RENDER_ONLY:-0}" = 1 ]; then
  # After editing lab/bench/analysis.md or report.py: the same numbers, rendered again.
  /usr/bin/python3 "$repo/lab/bench/bench.py" "${args[@]}" --render-only
  exit 0
fi
if [ "${BENCH_PROFILE:-0}" = 1 ]; then
  echo "bench: installing py-spy into $scratch/py-spy (BENCH_PROFILE=1)"
  /usr/bin/python3 -m pip install --quiet --disable-pip-version-check --root-user-action=ignore --target "$scratch/py-spy" py-spy
  args+=(--py-spy "$scratch/py-spy/bin/py-spy")
fi

# In the background so the trap runs at once on Ctrl-C instead of after the stage in progress.
if [ -n "${BENCH_STAGES:-}" ] && [ -z "$stages" ]; then
  : # only the grader's stage was asked for
else
  /usr/bin/python3 "$repo/lab/bench/bench.py" "${args[@]}" &
  bench_pid=$!
  wait "$bench_pid"
fi
if [ "$grader" = record ]; then
  echo "bench: the grader's speed (lab/bench/grader_bench.py, about 50 minutes)"
  /usr/bin/python3 "$repo/lab/bench/grader_bench.py" --out "$scratch/grader" --record &
  bench_pid=$!
  wait "$bench_pid"
  # Its raw results beside the section, so that `grader_bench.py --from-results` can render it again
  # after a change of its words, without grading anything (the scratch folder goes at the end).
  cp "$scratch/grader/results.json" "$repo/lab/bench/grader_results.json"
  # docs/benchmarks.md again, now with the new lab/bench/grader.md appended.
  /usr/bin/python3 "$repo/lab/bench/bench.py" "${args[@]}" --render-only
  # The reports' reading time and the same class of 60 without and with a report each
  # (lab/bench/report_bench.py, reader47's piece: about 30 minutes), lab/bench/reports.md.
  /usr/bin/python3 "$repo/lab/bench/report_bench.py" --out "$scratch/reports" --record &
  bench_pid=$!
  wait "$bench_pid"
elif [ "$grader" = quick ]; then
  /usr/bin/python3 "$repo/lab/bench/report_bench.py" --repeat 2 --class-size 2 --out "$out/reports" &
  bench_pid=$!
  wait "$bench_pid"
  /usr/bin/python3 "$repo/lab/bench/grader_bench.py" --students 4 --jobs 2 --out "$out/grader" &
  bench_pid=$!
  wait "$bench_pid"
fi

#!/usr/bin/env python3
"""`make bench`: the exam node against the naive baseline, stage by stage, into docs/benchmarks.md.

Run it through lab/bench/run.sh, which prepares the ROS environment and the log directory, and whose
trap ends every process of the run should this one die without doing it. BENCH_QUICK=1 shrinks every
window to a few seconds (a smoke run while developing) and writes to a scratch directory instead of
docs/, so a smoke run never replaces the real numbers.
"""

import argparse
import importlib.metadata
import json
import os
import platform
import signal
import subprocess
import sys
import time

from exam_lab.grader.publish.provenance import grader_version
from exam_lab.harness.supervisor import Supervisor

import driver
import procs
import profiling
import report
import stages
from stages import progress

FULL = {
    'rate_window': 60, 'floor_window': 20,
    'crossings': 22, 'delay': 1.0, 'hold': 0.6, 'slow_crossings': 3, 'slow_hold': 2.5,
    'rates': [10, 100, 500, 1000], 'max_rate_window': 10,
    'fleet_sizes': [1, 5, 10, 20, 50, 100], 'baseline_fleet_sizes': [1, 5, 10, 20], 'fleet_window': 20,
    'jitter_rounds': 2, 'jitter_window': 20, 'profile_window': 30,
}
QUICK = {
    'rate_window': 4, 'floor_window': 3,
    'crossings': 3, 'delay': 0.5, 'hold': 0.4, 'slow_crossings': 1, 'slow_hold': 2.5,
    'rates': [10, 100, 500, 1000], 'max_rate_window': 3,
    'fleet_sizes': [1, 3], 'baseline_fleet_sizes': [1], 'fleet_window': 3,
    'jitter_rounds': 1, 'jitter_window': 3, 'profile_window': 5,
}
SEED = 5


class Stop(Exception):
    """SIGTERM, turned into an exception so every `finally` stops its processes."""


def _on_sigterm(_signum, _frame):
    raise Stop('SIGTERM')


def machine():
    with open('/proc/meminfo') as f:
        mem_kb = int(f.readline().split()[1])
    model = 'unknown CPU'
    with open('/proc/cpuinfo') as f:
        for line in f:
            if line.startswith('model name'):
                model = line.split(':', 1)[1].strip()
                break
    return {
        'nproc': os.cpu_count(), 'cpu_model': model, 'mem_gb': mem_kb / 1024.0 / 1024.0,
        'kernel': 'Linux ' + platform.release(), 'python': platform.python_version(),
        'rospy': importlib.metadata.version('rospy'),
        'commit': grader_version(),  # the repository's commit, "+changes" when its files differ
        'loadavg_start': procs.loadavg(),
    }


def guarded(label, fn, *args, **kwargs):
    """Run one stage; a failure is recorded (and reported) instead of ending the whole benchmark."""
    progress(label)
    started = time.monotonic()
    try:
        result = fn(*args, **kwargs)
    except (RuntimeError, OSError, subprocess.SubprocessError) as e:
        progress('  FAILED: %s' % e)
        return {'error': str(e)}
    progress('  done in %.0f s%s' % (time.monotonic() - started,
                                       ': ' + _headline(result) if isinstance(result, dict) else ''))
    return result


def _headline(result):
    keys = ('rate_hz', 'sd_ms', 'max_gap_ms', 'cpu_percent', 'rss_mb', 'highest_hz',
            'min_rate_hz', 'anomaly_count')
    parts = ['%s=%.3g' % (k, result[k]) for k in keys
             if isinstance(result.get(k), (int, float))]
    for which in ('warning', 'normal'):
        if which in result:
            parts.append('%s p99=%s ms' % (which, report._fmt(result[which]['p99_ms'], 1)))
    if 'stream' in result:
        parts.append('gap=%s ms' % report._fmt(result['stream']['max_gap_ms'], 0))
    return ', '.join(parts)


STAGES = ('rate', 'latency', 'slow', 'max_rate', 'fleet')


def run_stages(lab, cfg, kinds, profiler, wanted=STAGES):
    """Every stage in ``wanted`` for every kind; the profile last, since it reads their results."""
    results = {kind: {} for kind in ('ours', 'baseline', 'floor')}
    if 'rate' in wanted:
        for kind in kinds:
            results[kind]['rate'] = guarded(
                '%s: /altitude rate, CPU and RSS at 10 Hz over %d s' % (kind, cfg['rate_window']),
                stages.rate_and_cost, lab, kind, cfg['rate_window'])
        results['floor'] = guarded('floor: bare rospy node at 10 Hz over %d s' % cfg['floor_window'],
                                   stages.rate_and_cost, lab, 'floor', cfg['floor_window'])
        results['memory_floor'] = guarded('floor: RSS of python3, import rospy, init_node',
                                          stages.memory_floor, lab)
        if 'ours' in kinds:
            results['ours_without_numpy'] = guarded(
                'ours without numpy (lab/bench/without_numpy.py): rate, CPU and RSS over %d s'
                % cfg['floor_window'],
                stages.rate_and_cost, lab, 'ours_without_numpy', cfg['floor_window'])
    if 'latency' in wanted:
        for kind in kinds:
            results[kind]['latency'] = guarded(
                '%s: warning latency over %d excursions' % (kind, cfg['crossings']),
                stages.latency, lab, kind, cfg['crossings'], cfg['delay'], cfg['hold'], SEED)
        if 'ours' in kinds:
            # The memory experiment must still warn correctly, or its RSS proves nothing.
            results['ours_without_numpy_latency'] = guarded(
                'ours without numpy: warning latency over %d excursions' % cfg['crossings'],
                stages.latency, lab, 'ours_without_numpy', cfg['crossings'], cfg['delay'],
                cfg['hold'], SEED)
    if 'slow' in wanted:
        for kind in kinds:
            results[kind]['slow'] = guarded(
                '%s: /altitude gaps while the service takes 2 s per call' % kind,
                stages.latency, lab, kind, cfg['slow_crossings'], cfg['delay'], cfg['slow_hold'],
                SEED, slow=2.0)
    if 'max_rate' in wanted and 'ours' in kinds:
        results['ours']['max_rate'] = guarded(
            'ours: highest sustained ~rate among %s Hz' % cfg['rates'],
            stages.max_rate, lab, 'ours', cfg['rates'], cfg['max_rate_window'])
    if 'fleet' in wanted and not stages.available(stages.SIMULATOR):
        progress('fleet: skipped, %s is missing' % stages.SIMULATOR)
    elif 'fleet' in wanted:
        for kind, sizes in (('ours', cfg['fleet_sizes']), ('baseline', cfg['baseline_fleet_sizes'])):
            if kind not in kinds:
                continue
            results[kind]['fleet'] = {}
            for n in sizes:
                results[kind]['fleet'][str(n)] = guarded(
                    '%s: fleet of %d drone + node pairs over %d s' % (kind, n, cfg['fleet_window']),
                    stages.fleet, lab, kind, n, cfg['fleet_window'])
    if profiler and 'ours' in kinds:
        results['profile'] = profiler.profile_missed(lab, results)
    return results


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument('--quick', action='store_true', help='a few seconds per stage (smoke run)')
    parser.add_argument('--out', required=True, help='directory that receives benchmarks.md')
    parser.add_argument('--figure', required=True, help='path of the fleet plot (PNG)')
    parser.add_argument('--json', required=True, help='path of the raw results (JSON)')
    parser.add_argument('--log-dir', help='where the nodes write their output (required to measure)')
    parser.add_argument('--py-spy', default=None, help='py-spy executable: profile missed goals')
    parser.add_argument('--stages', default=','.join(STAGES),
                        help='comma-separated subset of %s (a targeted experiment)' % ', '.join(STAGES))
    parser.add_argument('--render-only', action='store_true',
                        help='measure nothing: render the report again from --json')
    parser.add_argument('--command', default='make bench', help='command shown in the report')
    parser.add_argument('--fleet-sizes', default=None,
                        help='comma-separated fleet sizes of ours (default 1,5,10,20,50,100): what a '
                             'smaller machine can hold')
    args = parser.parse_args(argv)
    unknown = set(args.stages.split(',')) - set(STAGES)
    if unknown:
        parser.error('unknown stage(s) %s; choose among %s' % (', '.join(sorted(unknown)),
                                                               ', '.join(STAGES)))
    if args.render_only:
        with open(args.json) as f:
            write_report(json.load(f), args)
        return 0
    if not args.log_dir:
        parser.error('--log-dir is required to measure')
    cfg = dict(QUICK if args.quick else FULL)
    if args.fleet_sizes:
        cfg['fleet_sizes'] = [int(n) for n in args.fleet_sizes.split(',')]
    signal.signal(signal.SIGTERM, _on_sigterm)

    t0 = time.monotonic()
    date = time.strftime('%Y-%m-%d %H:%M', time.gmtime())
    info = machine()
    kinds = ['ours', 'baseline']
    if not stages.available(stages.SCRIPTS['ours']):
        progress('ours: %s is missing, measuring the baseline only' % stages.SCRIPTS['ours'])
        kinds = ['baseline']
    supervisor = Supervisor(args.log_dir)
    try:
        master = supervisor.start_master()
        progress('master at %s, node output in %s' % (master.uri, args.log_dir))
        driver.init(master.uri)
        lab = stages.Lab(supervisor, master)
        profiler = None
        if args.py_spy:
            profiler = profiling.Profiler(args.py_spy, args.log_dir, cfg['profile_window'],
                                          cfg['jitter_rounds'], cfg['jitter_window'], args.quick)
        results = run_stages(lab, cfg, kinds, profiler, args.stages.split(','))
    finally:
        import rospy
        rospy.signal_shutdown('bench over')
        supervisor.close()
    info['loadavg_end'] = procs.loadavg()
    results.update(machine=info, config=cfg, quick=args.quick, date=date, command=args.command,
                   duration_s=time.monotonic() - t0)
    with open(args.json, 'w') as f:
        json.dump(results, f, indent=1, sort_keys=True)
    write_report(results, args)
    failed = report.failed_stages(results)
    if failed:
        progress('%d stage(s) failed: %s' % (len(failed), '; '.join(failed)))
    return 1 if failed else 0


def write_report(results, args):
    results['analysis'] = _read_analysis()
    os.makedirs(args.out, exist_ok=True)
    report.plot_fleet(results, args.figure)
    md = os.path.join(args.out, 'benchmarks.md')
    figure_rel = os.path.relpath(args.figure, args.out)
    with open(md, 'w') as f:
        f.write(report.render(results, figure_rel))
    progress('wrote %s and %s' % (md, args.figure))


def _read_analysis():
    """Hand-written findings (what bounds each missed goal) kept beside the code that measures them.

    They come from profiles and experiments the generated numbers cannot explain by themselves; the
    report prints them under the table so a reader sees both.
    """
    path = os.path.join(stages.BENCH, 'analysis.md')
    if os.path.exists(path):
        with open(path) as f:
            return f.read()
    return None


if __name__ == '__main__':
    try:
        sys.exit(main(sys.argv[1:]))
    except (KeyboardInterrupt, Stop):
        progress('interrupted: every process started was stopped')
        sys.exit(130)
    except subprocess.SubprocessError as e:
        progress('failed: %s' % e)
        sys.exit(1)

"""Renders the results of `make bench` as docs/benchmarks.md and docs/figures/bench_fleet.png.

Pure formatting of the dict that bench.py collects: the goals and their met/missed verdicts live here,
next to the table that prints them, so a reader can check each verdict against its numbers.
"""

import os
import re

import stats

RATE_TOLERANCE = 0.001
FLEET_TOLERANCE = 0.01


def _fmt(value, digits=2):
    if value is None:
        return 'n/a'
    return '%.*f' % (digits, value)


def _ratio(ours, baseline):
    # A ratio of signed latencies (the baseline warns early: negative) would read as nonsense.
    if ours is None or baseline is None or ours < 0 or baseline <= 0:
        return 'n/a'
    return '%.2f' % (ours / baseline)


def _kb(mib):
    """VmRSS is read in kB of 1024 bytes and stored in MiB (kB / 1024): the kB it was measured in."""
    return '%.0f' % (mib * 1024.0)


def _mib(mib):
    """A memory size in MiB with the kB it was measured in: ``47.36 MiB (48496 kB)``."""
    return '%s MiB (%s kB)' % (_fmt(mib), _kb(mib))


#: The memory goal: the exam node within this many MiB of the bare rospy node (lab/bench/floor_node.py)
#: measured in the same run. An absolute goal would measure rospy's and numpy's imports, not the node.
RSS_MARGIN_MIB = 1.0


#: The first line of lab/bench/analysis.md: the date of the run its numbers come from.
ANALYSIS_RUN = re.compile(r'^<!-- run: (\d{4}-\d\d-\d\d \d\d:\d\d)[^\n]*-->\n')


def analysis_run(text):
    """The date (``YYYY-MM-DD HH:MM``, as results.json's ``date``) of the run ``text`` was written from."""
    found = ANALYSIS_RUN.match(text)
    return found.group(1) if found else None


def _verdict(met):
    if met is None:
        return 'not measured'
    return 'met' if met else '**missed**'


def _get(results, *path):
    """Nested lookup that yields None where a stage failed or was skipped."""
    node = results
    for key in path:
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node


def goal_rows(r):
    """Rows (metric, ours, baseline, ratio, goal, verdict) of the main table."""
    rows = []

    def row(metric, path, goal, check, digits=2, ratio=True, verdict=None):
        ours, base = _get(r, 'ours', *path), _get(r, 'baseline', *path)
        if path[0] == 'fleet' and ours is None and base is None:
            return  # a fleet size this run did not fly (BENCH_FLEET_SIZES): no row of n/a
        met = check(ours) if check is not None and ours is not None else None
        shown = verdict(ours) if verdict is not None and met is not None else _verdict(met)
        rows.append((metric, _fmt(ours, digits), _fmt(base, digits),
                     _ratio(ours, base) if ratio is True else ratio if isinstance(ratio, str) else 'n/a', goal,
                     shown if goal != '' else ''))

    row('/altitude mean rate (Hz)', ('rate', 'rate_hz'), '10 Hz within 0.1 %',
        lambda v: stats.within(v, 10.0, RATE_TOLERANCE), 4)
    row('/altitude interval sd (ms)', ('rate', 'sd_ms'), '<= 0.5 ms', lambda v: v <= 0.5, 3)
    row('/altitude interval off the mean, median (ms)', ('rate', 'dev_p50_ms'), '', None, 3)
    row('/altitude interval off the mean, p99 (ms)', ('rate', 'dev_p99_ms'), '', None, 3)
    row('/altitude max gap (ms)', ('rate', 'max_gap_ms'), '', None, 1)
    # Machine-wide load is context (any process), not a property of either node: no ratio.
    row('machine busy during that window (% of all cores, any process: context, not a property of '
        'the node)', ('rate', 'machine_busy_percent'), '', None, 0, ratio='')
    for which, label in (('warning', 'WARNING'), ('normal', 'NORMAL')):
        # The baseline's WARNING comes early (negative latency): a ratio of errors of opposite
        # sign would mean nothing, so that block shows none.
        signed = which == 'warning'
        row('%s latency median (ms)' % label, ('latency', which, 'median_ms'), '', None, 1,
            not signed)
        row('%s latency p99 (ms)' % label, ('latency', which, 'p99_ms'), '<= 20 ms',
            lambda v: v <= 20.0, 1, not signed)
        row('%s latency min (ms; < 0 is early)' % label, ('latency', which, 'min_ms'),
            '>= 0 (never early)', lambda v: v >= 0.0, 1, not signed)
        row('%s latency max (ms)' % label, ('latency', which, 'max_ms'), '', None, 1, not signed)
    row('wrong or missing calls (count)', ('latency', 'anomaly_count'), '0', lambda v: v == 0, 0)
    row('max /altitude gap, service 2 s per call (ms)', ('slow', 'stream', 'max_gap_ms'),
        '<= 110 ms', lambda v: v <= 110.0, 1)
    row('CPU at 10 Hz (% of one core)', ('rate', 'cpu_percent'), '<= 0.5 %', lambda v: v <= 0.5, 2)
    floor_mib = _get(r, 'floor', 'rss_mb')
    if floor_mib is not None and 'error' not in r.get('floor', {}):
        row('RSS at 10 Hz (MiB)', ('rate', 'rss_mb'),
            'within %g MiB of the bare rospy node (%s MiB)' % (RSS_MARGIN_MIB, _fmt(floor_mib)),
            lambda v: v - floor_mib <= RSS_MARGIN_MIB, 2,
            verdict=lambda v: '%s (%+.2f MiB)' % (_verdict(v - floor_mib <= RSS_MARGIN_MIB), v - floor_mib))
    else:
        row('RSS at 10 Hz (MiB)', ('rate', 'rss_mb'), 'within %g MiB of the bare rospy node (not measured)'
            % RSS_MARGIN_MIB, None, 2)
    row('highest sustained ~rate (Hz)', ('max_rate', 'highest_hz'), '>= 500 Hz',
        lambda v: v >= 500, 0)
    row('fleet of 20: slowest pair (Hz)', ('fleet', '20', 'min_rate_hz'), 'all within 1 % of 10 Hz',
        lambda v: stats.within(v, 10.0, FLEET_TOLERANCE), 3)
    row('fleet of 20: fastest pair (Hz)', ('fleet', '20', 'max_rate_hz'), 'all within 1 % of 10 Hz',
        lambda v: stats.within(v, 10.0, FLEET_TOLERANCE), 3)
    row('fleet of 100: slowest pair (Hz)', ('fleet', '100', 'min_rate_hz'), 'all within 1 % of 10 Hz',
        lambda v: stats.within(v, 10.0, FLEET_TOLERANCE), 3)
    row('fleet of 100: master CPU (% of one core)', ('fleet', '100', 'master_cpu_percent'), '< 10 %',
        lambda v: v < 10.0, 1)
    return rows


def _table(header, rows):
    lines = ['| ' + ' | '.join(header) + ' |', '|' + '---|' * len(header)]
    lines += ['| ' + ' | '.join(str(c) for c in row) + ' |' for row in rows]
    return '\n'.join(lines)


#: The header line lab/bench/grader_bench.py writes on top of lab/bench/grader.md.
GRADER_RUN = re.compile(r'_Measured by `(?P<command>[^`]+)` on (?P<date>\d{4}-\d\d-\d\d \d\d:\d\d) \(UTC\)'
                        r'(?: in (?P<seconds>\d+) s)? at commit (?P<commit>[0-9a-f]+|unknown)')


def grader_run(section):
    """``{command, date, seconds, commit}`` of the grader section's run, or None when it has no header."""
    found = GRADER_RUN.search(section or '')
    if found is None:
        return None
    run = found.groupdict()
    run['seconds'] = int(run['seconds']) if run['seconds'] else None
    return run


def _minutes(date):
    """``YYYY-MM-DD HH:MM`` as minutes since the epoch (UTC), to compare two runs' dates."""
    import calendar
    import time
    return calendar.timegm(time.strptime(date, '%Y-%m-%d %H:%M')) // 60


def one_run(r, grader):
    """True when the grader section was measured by the same `make bench` as the node stages: the same
    commit, and started within ten minutes of the node stages' end (run.sh starts it right after)."""
    if grader is None or r.get('quick') or grader['commit'] != r['machine'].get('commit'):
        return False
    gap = _minutes(grader['date']) - _minutes(r['date']) - r['duration_s'] / 60.0
    return -1 <= gap <= 10


def _header(r, grader):
    """The first line: which run (or runs) this document shows, each with its date, duration and commit.
    A document that joins two runs says so, rather than lending one run's header to the other's numbers."""
    commit = r['machine'].get('commit', 'unknown (not recorded)')
    if grader is None:
        return ('_Generated by `%s` on %s (UTC) in %.0f s, at commit %s. Do not edit by hand: run it again._'
                % (r['command'], r['date'], r['duration_s'], commit))
    if one_run(r, grader):
        return ('_Generated by one `%s` run on %s (UTC), at commit %s: the node\'s stages %.0f s, then the '
                'grader\'s stage %s s. Do not edit by hand: run it again._'
                % (r['command'], r['date'], commit, r['duration_s'], grader['seconds'] or '?'))
    return ('_Two runs, not one: the node\'s stages by `%s` on %s (UTC) in %.0f s, at commit %s, without the '
            'grader\'s stage; [the grader](#the-grader) by `%s` on %s (UTC)%s, at commit %s. A full `make bench` '
            'measures both in one run and says so here. Do not edit by hand: run it again._'
            % (r['command'], r['date'], r['duration_s'], commit, grader['command'], grader['date'],
               ' in %d s' % grader['seconds'] if grader['seconds'] else '', grader['commit']))


def _grader_section():
    """lab/bench/grader.md: the grader's section, measured by lab/bench/grader_bench.py --record."""
    path = os.path.join(os.path.dirname(os.path.realpath(__file__)), 'grader.md')
    if not os.path.isfile(path):
        return None
    with open(path) as f:
        return f.read()


def render(r, figure_rel, grader_section=None):
    """The whole markdown document; ``grader_section`` defaults to lab/bench/grader.md."""
    m = r['machine']
    if grader_section is None:
        grader_section = _grader_section()
    grader = grader_run(grader_section)
    out = ['# Benchmarks: the exam node against a naive baseline', '', _header(r, grader), '']
    if r.get('quick'):
        out += ['**BENCH_QUICK=1 smoke run: windows of a few seconds, not representative.**', '']
    out += ['## Machine', '',
            '- %s, %d cores (`nproc`), %.1f GiB memory; %s; Python %s, rospy %s.'
            % (m['cpu_model'], m['nproc'], m['mem_gb'], m['kernel'], m['python'], m['rospy']),
            '- Load average (1, 5, 15 min) at the start of the node\'s stages %s, at their end %s (the '
            'grader\'s stage says its own). The machine is shared: other '
            'engineers ran builds and tests meanwhile, so CPU figures include their interference.'
            % (m['loadavg_start'], m['loadavg_end']), '']
    out += ['## Summary', '',
            '"ours" is `exam/scripts/exam_node.py`; "baseline" is `lab/bench/baseline_exam_node.py`, the '
            'naive node of the seed\'s grader solution (globals, one `rospy.Rate(10)` loop that '
            'publishes and calls the service synchronously, the delay as a count of iterations). '
            'Ratio is ours/baseline.' + (
                ' `EXAM_WS` only moved the build workspace, so that this run\'s `make build` could '
                'not disturb builds of other work on the shared machine.'
                if 'EXAM_WS=' in r['command'] else ''), '',
            _table(['metric', 'ours', 'baseline', 'ratio', 'goal', 'ours vs goal'], goal_rows(r)), '']
    if grader is None or one_run(r, grader):
        took = ('this run, `%s`, took %.0f s on this shared machine%s.' % (
            r['command'], r['duration_s'] + (grader['seconds'] or 0 if grader else 0),
            ' (the node\'s stages %.0f s, the grader\'s %s s)' % (r['duration_s'], grader['seconds'] or '?')
            if grader else ''))
    else:
        took = ('this run of the node\'s stages, `%s`, took %.0f s on this shared machine, without the '
                'grader\'s stage, which a full run measures last (measured apart: %s s, below).'
                % (r['command'], r['duration_s'], grader['seconds'] or 'its time not recorded'))
    out += ['## How to run', '',
            '`make bench` prints one line per stage; ' + took + ' `BENCH_PROFILE=1 make bench` also profiles the exam node with py-spy and, when '
            'the interval sd misses its goal, runs the jitter experiment. `BENCH_QUICK=1 make bench` '
            'is a smoke run (a few seconds per stage) that writes to `$EXAM_WS/bench-quick/` (`.ws/` '
            'by default) and leaves this file alone, as does `BENCH_STAGES=rate,latency make bench` (a '
            'subset of rate, latency, slow, max_rate, fleet). `BENCH_RENDER_ONLY=1 make bench` renders '
            'this file again from `lab/bench/results.json`. The benchmark is not part of `make test`; '
            'its statistics have unit tests: `lab/test/unit/test_bench_stats.py`.', '']
    out += _method(r)
    out += _floor(r)
    out += _max_rate(r)
    out += _fleet(r, figure_rel)
    out += _errors(r)
    if r.get('analysis'):
        out += ['## What bounds each result (hand-written: lab/bench/analysis.md)', '']
        written_from = analysis_run(r['analysis'])
        if written_from != r['date']:
            # A new run rewrites every table, but not the hand-written text: say which run it quotes.
            out += ['**Written from the run of %s, not from this one (%s): its numbers are that run\'s '
                    'until lab/bench/analysis.md is read again against the tables above.**'
                    % (written_from or 'an unknown date', r['date']), '']
        out += [ANALYSIS_RUN.sub('', r['analysis']).strip(), '']
    if r.get('profile'):
        out += _profile(r['profile'])
    # The grader's section: the last stage of a full run, lab/bench/grader_bench.py --record.
    if grader_section:
        out += [grader_section.strip(), '']
    return '\n'.join(out) + '\n'


def _method(r):
    c = r['config']
    return ['## Method', '',
            '- One rospy process (`/bench`) plays the drone: it publishes `temperature` (0.778 Hz) and '
            '`pressure` (2 Hz, the simulator\'s rates, plus each scripted step the moment it is due) '
            'in the node\'s namespace, '
            'serves a fake `altitude_warning` that stamps each call on arrival, and subscribes '
            '`altitude` with `tcp_nodelay`. All stamps are ROS time (`rospy.get_time()`), readings '
            'stamped right before publishing. Each measurement has its own namespace and node process.',
            '- Rate, CPU, RSS: steady readings below the threshold, %d s window after 1 s of warm-up; '
            'CPU from utime+stime in /proc/<pid>/stat over the window, RSS = VmRSS at its end. '
            'VmRSS is in kB of 1024 bytes; MiB = kB / 1024 exactly.' % c['rate_window'],
            '- Latency: %d excursions from %d m to %d m (threshold %d m) with `~delay` %.1f s, each '
            'held %.1f s past the delay and followed by %.1f s below, start times jittered by 0..0.2 s '
            'per step so crossings fall at every phase of a 10 Hz tick. WARNING latency = call '
            'arrival - (first reading above + delay); NORMAL latency = call arrival - first reading '
            'back. Transport and service connection time are included, as a user sees them.'
            % (c['crossings'], 1000, 1600, 1300, c['delay'], c['hold'], c['hold']),
            '- Slow service: the fake service sleeps 2 s per call during %d excursions held %.1f s '
            'above and below (so each 2 s call ends within its excursion); the max gap between '
            '/altitude messages over the whole stage is reported.'
            % (c['slow_crossings'], c.get('slow_hold', c['hold'])),
            '- Highest rate: `~rate` %s Hz, %d s each; sustained = mean rate within 1 %% and interval '
            'sd < 1 ms. The baseline has no `~rate` (10 Hz is hard-coded).'
            % (', '.join(str(x) for x in c['rates']), c['max_rate_window']),
            '- Fleet: N pairs of the real simulator (`mydrone/scripts/mydrone_node.py`) and a node, '
            'each pair in its own namespace on one master, %d s window after all pairs publish. The '
            'bench starts the nodes itself, in namespaces never reused, instead of through '
            '`lab/scripts/fleet_launch.py`, whose names repeat from one fleet to the next: see '
            '`fleet()` in lab/bench/stages.py for the rospy hazard that made a reused name kill a node '
            'of the next fleet.' % c['fleet_window'], '']


def _floor(r):
    f = r.get('floor')
    if not f or 'error' in f:
        return []
    out = ['## Floor: the cheapest rospy node', '',
           '`lab/bench/floor_node.py` subscribes both inputs and publishes a constant at 10 Hz with a '
           '`rospy.Timer`, nothing else: CPU %s %% of a core, RSS %s, interval sd %s ms (%d s '
           'window). No rospy node doing this job with rospy\'s usual imports can cost less here: it '
           'is the "bare rospy node" of the memory goal.'
           % (_fmt(f['cpu_percent']), _mib(f['rss_mb']), _fmt(f['sd_ms'], 3), f['window_s']), '']
    steps = r.get('memory_floor')
    if isinstance(steps, list):
        out += ['RSS of a fresh process after each step every rospy node takes:', '',
                _table(['step', 'RSS (MiB)', 'RSS (kB)'], [(label, _fmt(mib), _kb(mib)) for label, mib in steps]),
                '']
    lean = r.get('ours_without_numpy')
    if isinstance(lean, dict) and 'error' not in lean:
        out += ['The exam node itself run through `lab/bench/without_numpy.py` (numpy unimportable, so '
                'genpy takes its fallback; an experiment, not how the product runs): RSS %s, CPU %s %% '
                'of a core, rate %s Hz, interval sd %s ms (%d s window).'
                % (_mib(lean['rss_mb']), _fmt(lean['cpu_percent']),
                                          _fmt(lean['rate_hz'], 4), _fmt(lean['sd_ms'], 3),
                                          lean['window_s']), '']
    calls = r.get('ours_without_numpy_latency')
    if isinstance(calls, dict) and 'error' not in calls:
        out += ['Its warnings over the same %d excursions as the latency stage: %d wrong or missing '
                'calls, WARNING p99 %s ms, NORMAL p99 %s ms.'
                % (calls['excursions'], calls['anomaly_count'], _fmt(calls['warning']['p99_ms'], 1),
                   _fmt(calls['normal']['p99_ms'], 1)), '']
    return out


def _max_rate(r):
    runs = _get(r, 'ours', 'max_rate', 'runs')
    if not runs:
        return []
    rows = [(x['target_hz'], _fmt(x.get('rate_hz'), 3), _fmt(x.get('sd_ms'), 3),
             _fmt(x.get('max_gap_ms'), 1), _fmt(x.get('cpu_percent'), 1),
             _fmt(x.get('machine_busy_percent'), 0),
             x.get('error') or ('yes' if x['sustained'] else 'no')) for x in runs]
    return ['## Highest sustained rate (ours)', '',
            _table(['~rate (Hz)', 'measured (Hz)', 'interval sd (ms)', 'max gap (ms)',
                    'CPU (% core)', 'machine busy (%)', 'sustained'], rows), '']


def _fleet(r, figure_rel):
    rows = []
    for kind in ('ours', 'baseline'):
        for n, f in sorted((_get(r, kind, 'fleet') or {}).items(), key=lambda kv: int(kv[0])):
            if 'error' in f:
                rows.append((kind, n, f['error'], '', '', '', '', '', '', '', ''))
                continue
            cpu, rss = f['cpu_percent'], f['rss_mb']
            rows.append((kind, n, _fmt(f['min_rate_hz'], 3), _fmt(f['max_rate_hz'], 3),
                         _fmt(f['max_gap_ms'], 0), _fmt(cpu.get('exam'), 1),
                         _fmt(sum(cpu.values()), 1), _fmt(rss.get('exam'), 1),
                         _fmt(sum(rss.values()), 1), _fmt(f.get('master_cpu_percent'), 1),
                         _fmt(f.get('machine_busy_percent'), 0)))
    if not rows:
        return []
    return ['## Fleet scale', '',
            'CPU in %% of one core (the machine has %d cores); "all" adds the simulators; "master" '
            'is rosmaster alone (goal: under 10 %% at 100 pairs). RSS is '
            'the sum over the processes. '
            '"Machine busy" is the share of all cores in use by anyone (these nodes, the bench, other '
            'work on the shared machine) during the window, from /proc/stat.'
            % r['machine']['nproc'], '',
            _table(['node', 'pairs', 'slowest (Hz)', 'fastest (Hz)', 'max gap (ms)',
                    'CPU exam nodes', 'CPU all', 'RSS exam nodes (MiB)', 'RSS all (MiB)',
                    'CPU master', 'machine busy (%)'], rows), '',
            '![fleet cost against N](%s)' % figure_rel, '']


def failed_stages(r):
    """One line per stage that raised instead of measuring."""
    failed = []
    for kind in ('ours', 'baseline', 'floor'):
        entry = r.get(kind) or {}
        if 'error' in entry:
            failed.append('%s: %s' % (kind, entry['error']))
        entries = [(name, v) for name, v in entry.items() if isinstance(v, dict) and name != 'fleet']
        if kind == 'floor':
            entries += [(name, r[name]) for name in ('memory_floor', 'ours_without_numpy',
                                                     'ours_without_numpy_latency')
                        if isinstance(r.get(name), dict)]
        entries += [('fleet %s' % n, v) for n, v in (entry.get('fleet') or {}).items()]
        failed += ['%s %s: %s' % (kind, name, v['error']) for name, v in entries if 'error' in v]
    return failed


def _errors(r):
    lines = ['- ' + line for line in failed_stages(r)]
    for kind in ('ours', 'baseline'):
        anomalies = _get(r, kind, 'latency', 'anomalies') or []
        lines += ['- %s, latency: %s' % (kind, a) for a in anomalies[:10]]
    return (['## Stages that failed or misbehaved', ''] + lines + ['']) if lines else []


def _profile(p):
    out = ['## Profile (py-spy, ours)', '']
    for label, top in p.items():
        if label == 'jitter' and isinstance(top, list):
            out += _jitter(top)
            continue
        if isinstance(top, str):
            out += ['- %s: %s' % (label, top)]
            continue
        out += ['%s: %d samples; functions holding the most samples (self, then inclusive):' %
                (label, top['samples']), '']
        out += _table(['function', 'self %', 'inclusive %'],
                      [(name, _fmt(s, 1), _fmt(i, 1)) for name, s, i in top['functions']]).split('\n')
        out += ['']
    return out


def _jitter(runs):
    rows = [(x.get('variant'), _fmt(x.get('sd_ms'), 3), _fmt(x.get('dev_p50_ms'), 3),
             _fmt(x.get('dev_p99_ms'), 3), _fmt(x.get('max_gap_ms'), 1), _fmt(x.get('cpu_percent'), 2),
             _fmt(x.get('machine_busy_percent'), 0)) for x in runs]
    return ['Jitter experiment: each variant at 10 Hz, %d s each, variants interleaved round by round '
            '(floor, synchronous publish = `lab/bench/floor_node.py _synchronous:=true`):'
            % runs[0].get('window_s', 0), '',
            _table(['variant', 'interval sd (ms)', 'off the mean, median (ms)',
                    'off the mean, p99 (ms)', 'max gap (ms)', 'CPU (% core)',
                    'machine busy (% of all cores)'], rows),
            '']


def plot_fleet(r, path):
    """CPU and memory of the fleet against N, ours and baseline (matplotlib, Agg backend)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    fig, (ax_cpu, ax_mem, ax_rate) = plt.subplots(1, 3, figsize=(13, 4))
    for kind, style, color in (('ours', 'o-', 'tab:blue'), ('baseline', 's--', 'tab:orange')):
        fleet = {int(n): f for n, f in (_get(r, kind, 'fleet') or {}).items() if 'error' not in f}
        if not fleet:
            continue
        ns = sorted(fleet)
        ax_cpu.plot(ns, [fleet[n]['cpu_percent'].get('exam', 0) for n in ns], style, color=color,
                    label='%s: exam nodes' % kind)
        ax_cpu.plot(ns, [sum(fleet[n]['cpu_percent'].values()) for n in ns], style, color=color,
                    alpha=0.4, label='%s: all processes' % kind)
        ax_mem.plot(ns, [fleet[n]['rss_mb'].get('exam', 0) for n in ns], style, color=color,
                    label='%s: exam nodes' % kind)
        ax_mem.plot(ns, [sum(fleet[n]['rss_mb'].values()) for n in ns], style, color=color,
                    alpha=0.4, label='%s: all processes' % kind)
        ax_rate.plot(ns, [fleet[n]['min_rate_hz'] for n in ns], style, color=color,
                     label='%s: slowest pair' % kind)
    ax_cpu.set(xlabel='pairs N', ylabel='CPU (% of one core)', title='CPU')
    ax_mem.set(xlabel='pairs N', ylabel='RSS (MiB)', title='Memory')
    ax_rate.axhspan(9.9, 10.1, color='green', alpha=0.15, label='10 Hz +/- 1 %')
    ax_rate.set(xlabel='pairs N', ylabel='/altitude rate (Hz)', title='Slowest pair')
    for ax in (ax_cpu, ax_mem, ax_rate):
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle('Fleet cost against N (%s, %d cores)' % (r['machine']['cpu_model'],
                                                          r['machine']['nproc']))
    fig.tight_layout()
    os.makedirs(os.path.dirname(path), exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)

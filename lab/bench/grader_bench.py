#!/usr/bin/env python3
"""The grader's speed, and whether grading students side by side keeps its timing checks fair.

    python3 lab/bench/grader_bench.py [--students 60] [--jobs 4,6] [--out DIR] [--record] [--no-alone]
    python3 lab/bench/grader_bench.py --from-results DIR/results.json [--record]

(from the repository, after ``make build`` and ``source tools/env.sh``; about 36 minutes on two cores with --jobs 4 (2140 s on 2026-12-02)). A full
``make bench`` runs it last and records it; ``BENCH_STAGES=grader make bench`` runs a class of 4 into
``$EXAM_WS/bench-quick/grader``. Phases:

1. *alone*: each distinct package (the flawed and good student packages of lab/test/grader, and our
   exam node) graded one at a time (JOBS=1): the reference points and timings, and one submission's
   wall time;
2. for each JOBS value, a class of ``--students`` made of copies of those packages, graded side by
   side: its wall time, and for every student the points and the timings the rubric judges (rate,
   WARNING latency, NORMAL latency) against the same package graded alone.

Each grading times its own stages (``OUT/<student>/logs/timings.json``: :mod:`exam_lab.grader.host.timings`),
read here, never timed again from outside; the legs' wall times are the probe's schedule
(``probe-main.json``); while a class is graded, the machine's CPU use is sampled every BUSY_PERIOD_S
(``/proc/stat``: every process of the machine, the other work's too). ``--no-alone`` skips phase 1 (a
class measured against another, by the ratio of its stages).

Prints a Markdown section and writes ``results.json`` in --out; ``--record`` also writes the section
to lab/bench/grader.md, which lab/bench/report.py appends to docs/benchmarks.md ("The grader").
"""
import argparse
import datetime
import json
import os
import resource
import shutil
import sys
import tempfile
import threading
import time

from exam_lab.grader import class_run
from exam_lab.grader.host import underlay
from exam_lab.grader.publish.provenance import grader_version

HERE = os.path.dirname(os.path.realpath(__file__))
SUBMISSIONS = os.path.join(HERE, '..', 'test', 'grader', 'submissions')
OUR_EXAM = os.path.realpath(os.path.join(HERE, '..', '..', 'exam'))


#: A class of 60 at the default JOBS on two cores: its goal (issue 48: six minutes; it was 15).
CLASS_GOAL_S = 360

#: The packages whose WARNING is meant to miss the 5 s window: left out of its spread.
NOT_ON_TIME = ('no_delay', 'late_warning')


def packages():
    """{kind: its package folder}: each folder of submissions/ holds one package (``exam``, or the name the
    student gave it), and ours."""
    found = {}
    for name in sorted(os.listdir(SUBMISSIONS)):
        inside = sorted(d for d in os.listdir(os.path.join(SUBMISSIONS, name))
                        if os.path.isdir(os.path.join(SUBMISSIONS, name, d)))
        found[name] = os.path.join(SUBMISSIONS, name, inside[0])
    found['ours'] = OUR_EXAM
    return found


def make_class(folder, count, kinds):
    """``count`` student folders cycling through ``kinds``: {student: kind}."""
    students = {}
    names = sorted(kinds)
    for i in range(count):
        kind = names[i % len(names)]
        student = 's%02d_%s' % (i + 1, kind)
        shutil.copytree(kinds[kind], os.path.join(folder, student, os.path.basename(kinds[kind])),
                        ignore=shutil.ignore_patterns('__pycache__', '.grader-*'))
        students[student] = kind
    return students


def timings(out_dir, student):
    """What the rubric's timing checks measured for one student: rate (Hz), WARNING and NORMAL
    latency (s) of the main run, or None each."""
    path = os.path.join(out_dir, student, 'logs', 'probe-main.json')
    if not os.path.isfile(path):
        return {'hz': None, 'warning_s': None, 'normal_s': None}
    with open(path) as f:
        probe = json.load(f)
    schedule, calls = probe.get('schedule') or {}, probe.get('calls', [])
    result = {'hz': (probe.get('rate') or {}).get('hz'), 'warning_s': None, 'normal_s': None}
    if 'long_up' in schedule:
        warn = [t for t, s in calls if s == 'WARNING' and schedule['long_up'] <= t <= schedule['long_down']]
        normal = [t for t, s in calls if s == 'NORMAL' and t >= schedule['long_down']]
        result['warning_s'] = warn[0] - schedule['long_up'] if warn else None
        result['normal_s'] = normal[0] - schedule['long_down'] if normal else None
    return result


#: The legs of the main run, in the order flown (the probe's schedule): each one's wall time.
LEGS = ('rest', 'short_up', 'short_down', 'long_up', 'long_down', 'deep_down')
#: Seconds between two samples of the machine's CPU use.
BUSY_PERIOD_S = 5.0


def stage_times(out_dir, student):
    """One grading's stages as it timed them (``{stage: {"wall", "cpu"}}``, s) with its main run's legs
    (``leg:<name>``, wall only, from the probe's schedule): {} when it wrote none."""
    try:
        with open(os.path.join(out_dir, student, 'logs', 'timings.json')) as f:
            stages = dict(json.load(f).get('stages') or {})
    except (OSError, ValueError):
        return {}
    try:
        with open(os.path.join(out_dir, student, 'logs', 'probe-main.json')) as f:
            schedule = json.load(f).get('schedule') or {}
    except (OSError, ValueError):
        schedule = {}
    ends = LEGS[1:] + ('end',)
    for leg, end in zip(LEGS, ends):
        if leg in schedule and end in schedule:
            stages['leg:%s' % leg] = {'wall': round(schedule[end] - schedule[leg], 3), 'cpu': None}
    return stages


class Busy(object):
    """The machine's CPU use (0 to 1, all cores) every BUSY_PERIOD_S while it runs: ``samples`` is
    ``[[s since the start, use, load average]]``."""

    def __init__(self):
        self.samples, self._stop = [], threading.Event()
        self._thread = threading.Thread(target=self._loop, daemon=True)

    @staticmethod
    def _stat():
        with open('/proc/stat') as f:
            values = [int(x) for x in f.readline().split()[1:]]
        return sum(values), values[3] + values[4]  # idle and iowait

    def _loop(self):
        start, (total, idle) = time.monotonic(), self._stat()
        while not self._stop.wait(BUSY_PERIOD_S):
            now_total, now_idle = self._stat()
            self.samples.append([round(time.monotonic() - start, 1),
                                 round(1.0 - (now_idle - idle) / float(max(1, now_total - total)), 3),
                                 round(os.getloadavg()[0], 2)])
            total, idle = now_total, now_idle

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join()
        return False


def children_cpu():
    """CPU seconds (user + system) of every process this one has waited for, its descendants' too: a
    grading's boxes, judges and tools all end before it returns, so the difference around it is its CPU."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def grade(folder, out, jobs):
    """Grade the class in ``folder``: ``(wall s, CPU s of the whole class, {student: record}, the
    machine's CPU use meanwhile)``. The class's CPU is its gradings' own count (their boxes' too)."""
    start = time.monotonic()
    with Busy() as busy:
        records = class_run.grade_class(folder, out, jobs=jobs)
    cpu = sum((stage_times(out, r['student']).get('session') or {}).get('cpu') or 0.0 for r in records) + sum(
        (stage_times(out, r['student']).get(name) or {}).get('cpu') or 0.0 for r in records
        for name in ('prepare', 'staging', 'inspection', 'logs', 'grade'))
    return time.monotonic() - start, cpu, {r['student']: r for r in records}, busy.samples


def points(record):
    return {i['id']: i['points'] for i in record['items']}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--students', type=int, default=60)
    parser.add_argument('--jobs', default='4,6', help='the JOBS values to grade the class with (default: the '
                        'default JOBS of two cores, and half as many again)')
    parser.add_argument('--out', default=None)
    parser.add_argument('--record', action='store_true', help='write the section to lab/bench/grader.md')
    parser.add_argument('--from-results', help='render the section of an earlier run\'s results.json')
    parser.add_argument('--no-alone', action='store_true', help='skip grading each package alone')
    args = parser.parse_args(argv)
    if args.from_results:
        with open(args.from_results) as f:
            return publish(json.load(f), args.record)
    started = time.monotonic()
    out = args.out or tempfile.mkdtemp(prefix='grader-bench-')
    kinds = packages()
    underlay.ensure_underlay(underlay.default_underlay())
    results = {'alone': {}, 'classes': [], 'date': datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M'),
               'commit': grader_version(),
               'load_start': list(os.getloadavg()), 'command': 'python3 lab/bench/grader_bench.py '
               '--students %d --jobs %s' % (args.students, args.jobs)}

    if not args.no_alone:
        alone_dir = os.path.join(out, 'alone-class')
        os.makedirs(alone_dir)
        alone_students = make_class(alone_dir, len(kinds), kinds)
        wall, cpu, records, _ = grade(alone_dir, os.path.join(out, 'alone'), 1)
        for student, kind in alone_students.items():
            results['alone'][kind] = {'points': points(records[student]), 'seconds': records[student]['seconds'],
                                      'timing': timings(os.path.join(out, 'alone'), student),
                                      'stages': stage_times(os.path.join(out, 'alone'), student)}
        results['alone_wall'], results['alone_cpu'] = wall, cpu

    for jobs in [int(j) for j in args.jobs.split(',')]:
        folder = os.path.join(out, 'class-%d' % jobs)
        os.makedirs(folder)
        students = make_class(folder, args.students, kinds)
        wall, cpu, records, busy = grade(folder, os.path.join(out, 'graded-%d' % jobs), jobs)
        rows = []
        for student, kind in sorted(students.items()):
            alone = results['alone'].get(kind)
            rows.append({'student': student, 'kind': kind, 'points': points(records[student]),
                         'same_points': None if alone is None else points(records[student]) == alone['points'],
                         'seconds': records[student]['seconds'],
                         'timing': timings(os.path.join(out, 'graded-%d' % jobs), student),
                         'stages': stage_times(os.path.join(out, 'graded-%d' % jobs), student)})
        results['classes'].append({'jobs': jobs, 'students': args.students, 'wall': wall, 'cpu': cpu, 'rows': rows,
                                   'busy': busy})
        print('JOBS=%d: %d students in %.0f s' % (jobs, args.students, wall), file=sys.stderr)

    results['load_end'] = list(os.getloadavg())
    results['total_s'] = time.monotonic() - started
    with open(os.path.join(out, 'results.json'), 'w') as f:
        json.dump(results, f, indent=1, sort_keys=True)
    return publish(results, args.record)


def publish(results, record):
    section = render(results)
    print(section)
    if record:
        with open(os.path.join(HERE, 'grader.md'), 'w') as f:
            f.write(section + '\n')
    return 0


def _spread(values):
    values = [v for v in values if v is not None]
    return '-' if not values else ('%.2f' % values[0] if len(values) == 1 else '%.2f-%.2f' % (min(values), max(values)))


def render(results):
    """The "The grader" section of docs/benchmarks.md."""
    alone = results['alone']
    one = [v['seconds'] for v in alone.values()]
    rows = ['| graded | wall time | per student | CPU per student | same points as alone | rate [Hz] | '
            'WARNING after [s] | NORMAL after [s] |', '|---|---|---|---|---|---|---|---|']
    if alone:
        rows.append('| each of %d packages alone (JOBS=1) | %.0f s | %.0f-%.0f s | %s | (reference) | %s | %s | %s |' % (
            len(alone), results['alone_wall'], min(one), max(one), _cpu(results.get('alone_cpu'), len(alone)),
            _spread([v['timing']['hz'] for v in alone.values()]),
            _spread([v['timing']['warning_s'] for k, v in alone.items() if k not in NOT_ON_TIME]),
            _spread([v['timing']['normal_s'] for v in alone.values()])))
    for klass in results['classes']:
        graded = klass['rows']
        rows.append('| class of %d, JOBS=%d | %.0f s | %.0f-%.0f s | %s | %d of %d | %s | %s | %s |' % (
            klass['students'], klass['jobs'], klass['wall'], min(r['seconds'] for r in graded),
            max(r['seconds'] for r in graded), _cpu(klass.get('cpu'), len(graded)),
            len([r for r in graded if r['same_points']]), len(graded),
            _spread([r['timing']['hz'] for r in graded]),
            _spread([r['timing']['warning_s'] for r in graded if r['kind'] not in NOT_ON_TIME]),
            _spread([r['timing']['normal_s'] for r in graded])))
    differ = ['%s (JOBS=%d): %s' % (r['student'], k['jobs'], ', '.join(
        '%s %s instead of %s' % (item, r['points'][item], alone[r['kind']]['points'][item])
        for item in sorted(r['points']) if r['points'][item] != alone[r['kind']]['points'][item]))
        for k in results['classes'] for r in k['rows'] if r['same_points'] is False]
    largest = max([abs(sum(r['points'].values()) - sum(alone[r['kind']]['points'].values()))
                   for k in results['classes'] for r in k['rows'] if r['kind'] in alone] or [0.0])
    kinds = ['| %s | %s | %.0f s |' % (kind, _total(v['points']), v['seconds']) for kind, v in sorted(alone.items())]
    when = results.get('date', '?')
    load = ''
    if results.get('load_start'):
        load = ' Load average (1, 5, 15 min) at start %s, at end %s, on 2 cores (the work of anything else running counts too).' % (
            ', '.join('%.2f' % x for x in results['load_start']),
            ', '.join('%.2f' % x for x in results.get('load_end', [])))
    default = class_run.default_jobs()
    at_default = [k for k in results['classes'] if k['jobs'] == default]
    verdict = ''
    if at_default:
        moved = [r for r in at_default[0]['rows'] if r['same_points'] is False]
        verdict = ' At that JOBS the class of %d %s.' % (
            at_default[0]['students'], 'kept every point of every student' if not moved else
            'moved the points of %d student(s): the default is too high for this machine' % len(moved))
        above = [k for k in results['classes'] if k['jobs'] > default]
        if above and not moved:
            kept = not any(r['same_points'] is False for r in above[0]['rows'])
            verdict += (' So did JOBS=%d, the margin the default keeps for a machine that also does other work.'
                        if kept else ' JOBS=%d moved points: the default is the largest JOBS measured to move none.') \
                % above[0]['jobs']
    slow = sorted(kind for kind, v in alone.items() if v['seconds'] > 90)
    stages = stages_table(results)
    goals = []
    for klass in results['classes']:
        goals.append('class of %d at JOBS=%d: %.1f min%s' % (
            klass['students'], klass['jobs'], klass['wall'] / 60.0,
            '' if klass['students'] != 60 else (' (goal met)' if klass['wall'] <= CLASS_GOAL_S else ' (goal missed)')))
    return '\n'.join([
        '## The grader', '',
        '_Measured by `%s --record` on %s (UTC)%s at commit %s, after `make build` and `source tools/env.sh`; '
        'the last stage of a full `make bench`, or alone._%s' % (
            results.get('command', 'python3 lab/bench/grader_bench.py'), when,
            ' in %.0f s' % results['total_s'] if results.get('total_s') else '',
            results.get('commit', 'unknown (not recorded)'), load), '',
        'What `make grade` costs ([docs/grading.md](grading.md)), and whether grading students side by side '
        '(`JOBS`, each student on a master of its own) keeps its timing checks fair. The packages are our '
        'exam node and the student packages of `lab/test/grader/submissions/`; a class cycles through '
        'them. "Same points as alone": every item of the student equals that of its package graded alone. '
        '"CPU per student": the CPU time of the whole class over its students, as each grading counted it '
        '(its boxes\' cgroups, its judge, the grader\'s own thread: `timings.json`). '
        'The timings are those the rubric judges, over every student of the row: the output rate '
        '(10 Hz +- 10 % passes), the WARNING after the first reading above the threshold (the rubric times it '
        'from the node\'s own value and passes 4.7 s up to the delay, one period of the slowest input and a tick: '
        '`score/flight.py` `warning_window`; the packages warning at once or 50 s late left out) and the NORMAL after the first reading back (<= 0.5 s).', '']
        + rows + ['',
        'Goals: one submission in at most 90 s (%s), a class of 60 in at most %d minutes on two cores (issue 48), no point '
        'moved. Measured: %s. %s' % (
            'every package' if not slow else 'every package but %s, whose flights wait for a call that comes late or never'
            % ', '.join(slow), CLASS_GOAL_S // 60, '; '.join(goals), (
            'Every student got the points of its package alone (the largest difference of a total: 0).' if not differ else
            'Points that differed: %s. The largest difference of a total: %s point(s).' % (
                '; '.join(differ), _total({'': largest})))), '',
        '`JOBS` defaults to what fills %.0f %% of the cores at %.1f s of CPU in %.1f s a grading, within the memory '
        '(`exam_lab.grader.class_run.default_jobs`: %d on this machine).%s' % (
            100 * class_run.CPU_SHARE, class_run.GRADING_CPU_S, class_run.GRADING_WALL_S, default, verdict), '',
        'Why side by side stays fair: each student has a master, a network namespace and processes of its own, '
        'so the only thing shared is the CPU, and the rubric\'s timings need little of it: each box is held to '
        'its part of the machine (cores/JOBS, at least half a core), the judge\'s master and probe weigh four '
        'times a box. A correct 10 Hz node publishes on its own `rospy.Rate` whatever the load, its WARNING '
        'comes between the first tick after 5 s and the next, its NORMAL within a tick: they sit 0.2 s and '
        'more inside the windows. Builds (CMake, a few seconds of CPU) are what the jobs contend for; a run\'s '
        'timing suffers only if its node is starved of the CPU for more than 0.2 s, which the spreads above '
        'would show.', ''] + stages + [
        '| package | points alone | wall time alone |', '|---|---|---|'] + kinds)


#: The stages of one grading as the table lists them (:mod:`exam_lab.grader.host.timings`), then the legs.
STAGES = ('prepare', 'staging', 'inspection', 'session', 'launch_check', 'build', 'runs', 'main', 'threshold',
          'logs', 'grade') + tuple('leg:%s' % leg for leg in LEGS)


def stages_table(results):
    """Where one grading's time goes, stage by stage (each grading's own timings.json), alone and in
    each class: the mean wall and CPU time over the gradings that had the stage; and the machine's CPU
    use while each class was graded."""
    columns = ([('alone', list(results['alone'].values()))] if results['alone'] else []) + [
        ('class of %d, JOBS=%d' % (k['students'], k['jobs']), k['rows']) for k in results['classes']]
    if not any(row.get('stages') for _, rows in columns for row in rows):
        return []
    lines = ['Where a grading\'s time goes (mean wall / CPU s over the gradings that had the stage; "runs" are '
             'the two runs together, "main" and "threshold" each run, side by side when `side_by_side`; the legs '
             'are the main run\'s, wall only; CPU counts the boxes\' cgroups, the judge and the grader\'s '
             'own thread):', '', '| stage | ' + ' | '.join(name for name, _ in columns) + ' |',
             '|---|' + '---|' * len(columns)]
    for stage in STAGES:
        cells = []
        for _, rows in columns:
            had = [row['stages'][stage] for row in rows if stage in (row.get('stages') or {})]
            if not had:
                cells.append('-')
                continue
            wall = sum(h['wall'] for h in had) / len(had)
            cpu = [h['cpu'] for h in had if h.get('cpu') is not None]
            cells.append('%.1f / %s' % (wall, '%.1f' % (sum(cpu) / len(cpu)) if cpu else '-'))
        lines.append('| %s | %s |' % (stage, ' | '.join(cells)))
    for klass in results['classes']:
        busy = klass.get('busy') or []
        if busy:
            lines.append('')
            lines.append('The machine\'s CPU use while the class of %d was graded at JOBS=%d (every %.0f s, all of '
                         'the machine\'s work: %s): mean %.0f %%, %d of %d samples above 90 %%.' % (
                             klass['students'], klass['jobs'], BUSY_PERIOD_S,
                             ' '.join('%.0f' % (100 * b[1]) for b in busy), 100 * sum(b[1] for b in busy) / len(busy),
                             len([b for b in busy if b[1] > 0.9]), len(busy)))
    return lines + ['']


def _cpu(seconds, students):
    """The mean CPU of one student's grading (its box, its judge, the grader's own work), or '-' for a
    run recorded before it was measured."""
    return '-' if seconds is None else '%.0f s' % (seconds / max(students, 1))


def _total(points):
    return ('%.1f' % sum(points.values())).rstrip('0').rstrip('.')


if __name__ == '__main__':
    sys.exit(main())

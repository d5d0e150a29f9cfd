#!/usr/bin/env python3
"""The grader's speed, and whether grading students side by side keeps its timing checks fair.

    python3 lab/bench/grader_bench.py [--students 20] [--jobs 2,3] [--out DIR]

(from the repository, after ``make build`` and ``source tools/env.sh``; runs standalone). Three phases:

1. *alone*: each distinct package (the flawed and good student packages of lab/test/grader, and our
   exam node) graded one at a time (JOBS=1): the reference points and timings, and one submission's
   wall time;
2. for each JOBS value, a class of ``--students`` made of copies of those packages, graded side by
   side: its wall time, and for every student the points and the timings the rubric judges (rate,
   WARNING latency, NORMAL latency) against the same package graded alone.

Prints a Markdown section (docs/benchmarks.md, "The grader") and writes ``results.json`` in --out.
"""
import argparse
import json
import os
import shutil
import sys
import tempfile
import time

from exam_lab.grader import runner

HERE = os.path.dirname(os.path.abspath(__file__))
SUBMISSIONS = os.path.join(HERE, '..', 'test', 'grader', 'submissions')
OUR_EXAM = os.path.realpath(os.path.join(HERE, '..', '..', 'exam'))


def packages():
    found = {name: os.path.join(SUBMISSIONS, name, 'exam') for name in sorted(os.listdir(SUBMISSIONS))}
    found['ours'] = OUR_EXAM
    return found


def make_class(folder, count, kinds):
    """``count`` student folders cycling through ``kinds``: {student: kind}."""
    students = {}
    names = sorted(kinds)
    for i in range(count):
        kind = names[i % len(names)]
        student = 's%02d_%s' % (i + 1, kind)
        shutil.copytree(kinds[kind], os.path.join(folder, student, 'exam'),
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


def grade(folder, out, jobs):
    start = time.monotonic()
    records = runner.grade_class(folder, out, jobs=jobs)
    wall = time.monotonic() - start
    return wall, {r['student']: r for r in records}


def points(record):
    return {i['id']: i['points'] for i in record['items']}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--students', type=int, default=20)
    parser.add_argument('--jobs', default='2,3')
    parser.add_argument('--out', default=None)
    args = parser.parse_args(argv)
    out = args.out or tempfile.mkdtemp(prefix='grader-bench-')
    kinds = packages()
    runner.ensure_underlay(runner.default_underlay())
    results = {'alone': {}, 'classes': []}

    alone_dir = os.path.join(out, 'alone-class')
    os.makedirs(alone_dir)
    alone_students = make_class(alone_dir, len(kinds), kinds)
    wall, records = grade(alone_dir, os.path.join(out, 'alone'), 1)
    for student, kind in alone_students.items():
        results['alone'][kind] = {'points': points(records[student]), 'seconds': records[student]['seconds'],
                                  'timing': timings(os.path.join(out, 'alone'), student)}
    results['alone_wall'] = wall

    for jobs in [int(j) for j in args.jobs.split(',')]:
        folder = os.path.join(out, 'class-%d' % jobs)
        os.makedirs(folder)
        students = make_class(folder, args.students, kinds)
        wall, records = grade(folder, os.path.join(out, 'graded-%d' % jobs), jobs)
        rows = []
        for student, kind in sorted(students.items()):
            rows.append({'student': student, 'kind': kind, 'points': points(records[student]),
                         'same_points': points(records[student]) == results['alone'][kind]['points'],
                         'seconds': records[student]['seconds'],
                         'timing': timings(os.path.join(out, 'graded-%d' % jobs), student)})
        results['classes'].append({'jobs': jobs, 'students': args.students, 'wall': wall, 'rows': rows})
        print('JOBS=%d: %d students in %.0f s' % (jobs, args.students, wall), file=sys.stderr)

    with open(os.path.join(out, 'results.json'), 'w') as f:
        json.dump(results, f, indent=1, sort_keys=True)
    print(render(results))
    return 0


def _spread(values):
    values = [v for v in values if v is not None]
    return '-' if not values else ('%.2f' % values[0] if len(values) == 1 else '%.2f-%.2f' % (min(values), max(values)))


def render(results):
    alone = results['alone']
    one = [v['seconds'] for v in alone.values()]
    lines = ['| graded | wall time | per student | all points as alone | rate [Hz] | WARNING after [s] | NORMAL after [s] |',
             '|---|---|---|---|---|---|---|']
    lines.append('| each of %d packages alone (JOBS=1) | %.0f s | %.0f-%.0f s | (reference) | %s | %s | %s |' % (
        len(alone), results['alone_wall'], min(one), max(one),
        _spread([v['timing']['hz'] for v in alone.values()]),
        _spread([v['timing']['warning_s'] for k, v in alone.items() if k != 'no_delay']),
        _spread([v['timing']['normal_s'] for v in alone.values()])))
    for klass in results['classes']:
        rows = klass['rows']
        lines.append('| class of %d, JOBS=%d | %.0f s | %.0f-%.0f s | %d of %d | %s | %s | %s |' % (
            klass['students'], klass['jobs'], klass['wall'], min(r['seconds'] for r in rows),
            max(r['seconds'] for r in rows), len([r for r in rows if r['same_points']]), len(rows),
            _spread([r['timing']['hz'] for r in rows]),
            _spread([r['timing']['warning_s'] for r in rows if r['kind'] != 'no_delay']),
            _spread([r['timing']['normal_s'] for r in rows])))
    return '\n'.join(lines)


if __name__ == '__main__':
    sys.exit(main())

#!/usr/bin/env python3
"""How long a student's report takes to read, in its real box (issue 47 point 8): the grader's stage's
report part (reader47's piece of make bench, beside grader_bench.py).

    python3 lab/bench/report_bench.py [--repeat 5] [--out DIR] [--record]

(from the repository, after ``make build`` and ``source tools/env.sh``). Each text-layer report of
lab/test/unit/data/reports (LibreOffice's PDFs, one a .docx converted in the box) and a 10-page scan
(the French report's pages, made an image-only PDF as make_reports.py makes its scan) are read
``--repeat`` times by :func:`exam_lab.grader.host.reports.read_report`, box included; the median and
the worst wall clock of each kind, against the goals (a text report under 5 s, a 10-page scan under 30 s
on two cores), its CPU (user + sys of this process, its children and the box's cgroup: on a shared
machine the wall clock is also the others' load, shown), and what a class of 60 adds at the default JOBS.
Then a class of ``--class-size`` (60) copies of the good student's package is graded as make grade grades
a class, without reports, then each with a text report beside it: the two wall clocks, and each grading's
own report stage. Prints a Markdown section and writes
``reports_results.json`` in --out; ``--record`` also writes the section to lab/bench/reports.md and keeps
the results beside it (lab/bench/reports_results.json).
"""
import argparse
import datetime
import json
import os
import shutil
import statistics
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.realpath(__file__))
DATA = os.path.join(HERE, '..', 'test', 'unit', 'data', 'reports')
GOOD = os.path.join(HERE, '..', 'test', 'grader', 'submissions', 'good_student', 'exam')
sys.path.insert(0, os.path.join(HERE, '..', 'test', 'reports'))

from exam_lab.grader import class_run  # noqa: E402
from exam_lab.grader.host import reports, timings  # noqa: E402
import make_reports  # noqa: E402

TEXT = ('fr_odt.pdf', 'en_docx_table.pdf', 'en_docx_table.docx')
GOALS = {'text': 5.0, 'scan': 30.0}
CLASS = 60


def measure(path, scratch, repeat):
    """``{"seconds": [wall s], "cpu": [CPU s], "load": [1-minute load average before each]}`` of each
    reading of the report ``path`` (a student's folder holding it)."""
    row = {'seconds': [], 'cpu': [], 'load': []}
    for n in range(repeat):
        folder = os.path.join(scratch, 'student%d' % n)
        os.makedirs(folder)
        shutil.copyfile(path, os.path.join(folder, os.path.basename(path)))
        row['load'].append(round(os.getloadavg()[0], 1))
        watch = timings.Stopwatch()
        with watch.stage('report'):
            record = reports.read_report(folder, os.path.join(scratch, 'out%d' % n), watch=watch)
        if record.state != 'read':
            raise SystemExit('report_bench: %s not read: %s' % (path, record.why))
        row['seconds'].append(record.seconds)
        row['cpu'].append(watch.stages['report']['cpu'])
        shutil.rmtree(folder)
        reports.remove_read_only(os.path.join(scratch, 'out%d' % n))
    return row


def class_with_reports(scratch, count):
    """The same class of ``count`` copies of the good student's package graded twice as ``make grade
    CLASS=`` grades one (:func:`exam_lab.grader.class_run.grade_class`, the default JOBS): first without
    a report, then each student with one of the text reports beside it (the three of :data:`TEXT` in
    turn: a .docx is converted in its box). ``{"students", "jobs", "seconds"`` (the class with reports,
    wall clock), ``"seconds_without"`` (the same class without), ``"report"`` (each student's report
    stage, wall s, as its grading timed it in ``logs/timings.json``), ``"read"`` (the reports read)``}``."""
    seconds = {}
    for with_reports in (False, True):
        folder = os.path.join(scratch, 'class-%s' % with_reports)
        out = os.path.join(scratch, 'class-out-%s' % with_reports)
        for n in range(count):
            student = os.path.join(folder, 's%02d' % (n + 1))
            shutil.copytree(GOOD, os.path.join(student, 'exam'), ignore=shutil.ignore_patterns('__pycache__'))
            if with_reports:
                name = TEXT[n % len(TEXT)]
                shutil.copyfile(os.path.join(DATA, name), os.path.join(student, 'rapport' + os.path.splitext(name)[1]))
        jobs = class_run.default_jobs()
        start = time.monotonic()
        graded = class_run.grade_class(folder, out, jobs=jobs)
        seconds[with_reports] = round(time.monotonic() - start, 1)
        print('report_bench: a class of %d %s reports: %s s' % (count, 'with' if with_reports else 'without',
                                                                 seconds[with_reports]), flush=True)
    walls, read = [], 0
    for record in graded:
        with open(os.path.join(out, record['student'], 'logs', timings.FILE)) as f:
            walls.append(json.load(f)['stages']['report']['wall'])
        with open(os.path.join(out, record['student'], 'report.json')) as f:
            read += json.load(f)['state'] == 'read'
    return {'students': count, 'jobs': jobs, 'seconds': seconds[True], 'seconds_without': seconds[False],
            'report': walls, 'read': read}


def section(results):
    jobs = class_run.default_jobs()
    lines = ['### Reading the reports', '',
             'Each report read in its own box (`host/reports.read_report`: staged, boxed, read, copied back), '
             '%d times, on %s (%d cores; `lab/bench/report_bench.py`, %s).' % (
                 results['repeat'], results['host'], results['cores'], results['date']), '',
             '| report | pages | median s | worst s | goal | CPU s, median | CPU s, worst | load average |',
             '|---|---|---|---|---|---|---|---|']
    for name, row in results['reports'].items():
        lines.append('| %s | %d | %.1f | %.1f | under %.0f s%s | %.1f | %.1f | %.1f-%.1f |' % (
            name, row['pages'], statistics.median(row['seconds']), max(row['seconds']), GOALS[row['kind']],
            '' if max(row['seconds']) < GOALS[row['kind']] else ' (**missed**)', statistics.median(row['cpu']),
            max(row['cpu']), min(row['load']), max(row['load'])))
    text = [s for row in results['reports'].values() if row['kind'] == 'text' for s in row['seconds']]
    lines += ['', 'CPU: user + sys of the bench, the tools it waited for and the box\'s cgroup. Load average: the '
              'machine\'s, over one minute, before each reading (%d cores: above that, the wall clock is also '
              'what the other processes took).' % results['cores'],
              '', 'Text reports: median %.1f s, worst %.1f s. A class of %d with a text report each adds about '
              '%.0f s to its grading at the default JOBS=%d (the reports are read side by side as the students '
              'are graded: %d x median / JOBS).' % (statistics.median(text), max(text), CLASS,
                                                     CLASS * statistics.median(text) / jobs, jobs, CLASS), '']
    graded = results.get('class')
    if graded:
        added = sum(graded['report']) / graded['jobs']
        lines += ['In a class: %d copies of the good student\'s package graded as `make grade CLASS=` grades one, '
                  'at the default JOBS=%d, first without a report (%.0f s), then each with a text report beside it '
                  '(the three above in turn) in %.0f s: %+.0f s; %d of %d reports read. Each student\'s report stage '
                  '(its own `logs/timings.json`) took median %.1f s, worst %.1f s, read while the other slots fly: '
                  'their sum / JOBS is %.0f s.' % (
                      graded['students'], graded['jobs'], graded['seconds_without'], graded['seconds'],
                      graded['seconds'] - graded['seconds_without'], graded['read'], graded['students'],
                      statistics.median(graded['report']), max(graded['report']), added), '']
    return '\n'.join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--repeat', type=int, default=5)
    parser.add_argument('--out', default=None)
    parser.add_argument('--record', action='store_true')
    parser.add_argument('--class-size', type=int, default=CLASS,
                        help='students of the class graded with a report each (0: none)')
    args = parser.parse_args(argv)
    out = args.out or tempfile.mkdtemp(prefix='report-bench-')
    os.makedirs(out, exist_ok=True)
    scratch = tempfile.mkdtemp(prefix='report-bench-scratch-')
    try:
        scan = os.path.join(scratch, 'scan_10_pages.pdf')
        make_reports.scan(os.path.join(DATA, 'fr_odt.pdf'), scan, pages=range(10))
        results = {'repeat': args.repeat, 'host': os.uname()[1], 'cores': os.cpu_count(),
                   'date': datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M UTC'), 'reports': {}}
        for name, path, kind, pages in [(n, os.path.join(DATA, n), 'text', 2) for n in TEXT] + \
                [('scan, 10 pages', scan, 'scan', 10)]:
            work = os.path.join(scratch, kind + str(len(results['reports'])))
            os.makedirs(work)
            results['reports'][name] = dict({'kind': kind, 'pages': pages}, **measure(path, work, args.repeat))
            print('report_bench: %s: %s s, CPU %s s' % (name, results['reports'][name]['seconds'],
                                                        results['reports'][name]['cpu']), flush=True)
        if args.class_size:
            results['class'] = class_with_reports(scratch, args.class_size)
            print('report_bench: a class of %d: %s' % (args.class_size, results['class']), flush=True)
    finally:
        reports.remove_read_only(scratch)
        shutil.rmtree(scratch, ignore_errors=True)
    with open(os.path.join(out, 'reports_results.json'), 'w') as f:
        json.dump(results, f, indent=1)
    text = section(results)
    print(text)
    if args.record:  # the section and the raw results it was rendered from, kept together
        with open(os.path.join(HERE, 'reports.md'), 'w') as f:
            f.write(text)
        shutil.copyfile(os.path.join(out, 'reports_results.json'), os.path.join(HERE, 'reports_results.json'))
    return 0


if __name__ == '__main__':
    sys.exit(main())

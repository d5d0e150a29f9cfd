#!/usr/bin/env python3
"""`make fairness`: grade generated student answers as one class and say which were graded unfairly.

    fairness.py [--out DIR] [--jobs N] [--correct N] [--seed S] [--docs docs/grading.md | --no-docs]
                [--only NAME[,NAME...]]

The answers (lab/src/exam_lab/fairness/generator.py): ``--correct`` correct answers to both sheets, a
pairwise covering sample of the styles students write, and one one-mistake variant per rule of the
rubric. They are graded in ONE class run by the grader (class_run.grade_class, JOBS side by side), each
grade held to what the answer must get. The report goes between its markers in docs/grading.md (with
the date and commit) and into OUT/fairness.md; OUT keeps the class, the grades and fairness.json.

The last line reads ``fairness: A of B correct answers got 17/17; C of D one-mistake answers lost their
item only``; exits 1 when A < B or C < D, 2 when the grader could not run. ``--only`` grades the answers
of the matrix whose names start with one of the given names (``--only c18,m17``), as they are in the
whole run, to check a change on them; such a partial run never writes the docs.
"""
import argparse
import collections
import datetime
import json
import os
import re
import subprocess
import sys
import tempfile
import time

from exam_lab.fairness import generator
from exam_lab.grader import class_run

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..'))
BEGIN = '<!-- fairness: written by `make fairness` (lab/scripts/fairness.py); do not edit -->'
END = '<!-- end of fairness -->'


def commit():
    try:
        return subprocess.check_output(['git', '-C', REPO, 'describe', '--always', '--dirty'],
                                       stderr=subprocess.DEVNULL).decode().strip()
    except (OSError, subprocess.CalledProcessError):
        return 'unknown'


def judge(answers, records):
    """``[(answer, record or None, fair, how)]`` in the answers' order."""
    by_name = {r['student']: r for r in records}
    out = []
    for answer in answers:
        record = by_name.get(answer.name)
        if record is None:
            out.append((answer, None, False, 'no grade in the class run'))
            continue
        fair, how = generator.verdict(answer, record)
        out.append((answer, record, fair, how))
    return out


def summary(judged):
    right = [j for j in judged if j[0].mistake is None]
    wrong = [j for j in judged if j[0].mistake is not None]
    return (len([j for j in right if j[2]]), len(right), len([j for j in wrong if j[2]]), len(wrong))


def _cell(text):
    return str(text).replace('|', '\\|').replace('\n', ' ')


def report(judged, header):
    """The report in Markdown: the summary, correct answers by style value, the unfair grades of
    correct answers, and every one-mistake answer."""
    a, b, c, d = summary(judged)
    lines = [header, '', '**fairness: %d of %d correct answers got 17/17; %d of %d one-mistake answers lost their '
             'item only**' % (a, b, c, d), '']
    right = [j for j in judged if j[0].mistake is None]
    lines += ['Correct answers by style (17/17 "graded" of those with that style):', '',
              '| axis | ' + ' | '.join('value %d' % (n + 1) for n in range(max(len(v) for v in generator.AXES.values())))
              + ' |', '|---|' + '---|' * max(len(v) for v in generator.AXES.values())]
    for axis, values in generator.AXES.items():
        cells = []
        for value in values:
            having = [j for j in right if getattr(j[0].style, axis) == value]
            cells.append('%s: %d of %d' % (value, len([j for j in having if j[2]]), len(having)))
        cells += [''] * (max(len(v) for v in generator.AXES.values()) - len(cells))
        lines.append('| %s | %s |' % (axis, ' | '.join(cells)))
    unfair = [j for j in right if not j[2]]
    lines += ['', 'Correct answers graded wrong (%d):' % len(unfair), '']
    if unfair:
        lines += ['| answer | points | what differs |', '|---|---|---|']
        for answer, record, _, how in unfair:
            lines.append('| %s | %s | %s |' % (answer.name, '%g' % record['total'] if record else '-', _cell(how)))
    else:
        lines.append('none')
    lines += ['', 'One-mistake answers (each made from a correct answer; "base fair": that correct style got '
              '17/17 here):', '', '| answer | mistake | wanted | points | fair | base fair | how |',
              '|---|---|---|---|---|---|---|']
    fair_styles = set(j[0].style for j in right if j[2])
    right_styles = set(j[0].style for j in right)
    for answer, record, fair, how in judged:
        if answer.mistake is None:
            continue
        wanted = 'flagged' if answer.expected == generator.FLAGGED else ', '.join(
            '%s %s' % (item, generator.points_words(points)) for item, points in sorted(answer.expected.items()))
        base = ('yes' if answer.style in fair_styles else 'no') if answer.style in right_styles else 'not in the run'
        lines.append('| %s | %s | %s | %s | %s | %s | %s |' % (
            answer.name, _cell(generator.MISTAKES[answer.mistake].words), wanted,
            '%g' % record['total'] if record else '-', 'yes' if fair else '**no**', base, _cell(how)))
    return '\n'.join(lines) + '\n'


def selected(answers, prefixes):
    """The answers whose names start with one of ``prefixes`` (empty ones ignored), in the matrix's order."""
    prefixes = tuple(p.strip() for p in prefixes if p.strip())
    return [a for a in answers if prefixes and a.name.startswith(prefixes)]


def read_grades(grades):
    records = []
    for name in sorted(os.listdir(grades)):
        path = os.path.join(grades, name, 'grade.json')
        if os.path.isfile(path):
            with open(path) as f:
                records.append(json.load(f))
    return records


def write_docs(path, section):
    with open(path) as f:
        text = f.read()
    block = '%s\n%s%s' % (BEGIN, section, END)
    if BEGIN in text and END in text:
        text = re.sub(re.escape(BEGIN) + r'.*?' + re.escape(END), lambda m: block, text, flags=re.S)
    else:
        text = text.rstrip('\n') + '\n\n' + block + '\n'
    with open(path, 'w') as f:
        f.write(text)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--out', help='where the class, its grades and the report go (default: a new temp folder)')
    parser.add_argument('--jobs', type=int, default=None, help='gradings side by side (default: the grader\'s)')
    parser.add_argument('--correct', type=int, default=40, help='correct answers (at least the pairwise covering)')
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--docs', default=os.path.join(REPO, 'docs', 'grading.md'),
                        help='the file whose fairness section is rewritten')
    parser.add_argument('--no-docs', action='store_true', help='leave the docs alone')
    parser.add_argument('--judge-only', action='store_true',
                        help='judge the grades already in OUT/grades again (after a change of the expectations)')
    parser.add_argument('--only', help='grade only the answers whose names start with one of these (comma '
                        'separated: c18,m17); the docs are then left alone')
    args = parser.parse_args(argv)
    out = args.out or tempfile.mkdtemp(prefix='fairness-')
    answers = generator.answers(args.correct, args.seed)
    if args.only:
        answers = selected(answers, args.only.split(','))
        if not answers:
            parser.error('--only %s: no answer of the matrix has such a name' % args.only)
        args.no_docs = True
    jobs = args.jobs or class_run.default_jobs()
    start = time.time()
    run = {'commit': commit(), 'date': datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M'), 'jobs': jobs,
           'seed': args.seed}
    if args.judge_only:
        records = read_grades(os.path.join(out, 'grades'))
        with open(os.path.join(out, 'run.json')) as f:
            run = json.load(f)
    else:
        klass = generator.write_class(answers, os.path.join(out, 'class'))
        print('fairness: %d answers (%d correct, %d one-mistake) written to %s; grading them as one class, JOBS=%d'
              % (len(answers), len([a for a in answers if a.mistake is None]),
                 len([a for a in answers if a.mistake is not None]), klass, jobs), flush=True)
        try:
            records = class_run.grade_class(klass, os.path.join(out, 'grades'), jobs=jobs)
        except Exception as err:  # the grader could not run at all: no verdict on fairness
            print('fairness: the grader could not run: %s' % err, file=sys.stderr)
            return 2
        run['seconds'] = time.time() - start
        with open(os.path.join(out, 'run.json'), 'w') as f:
            json.dump(run, f)
    judged = judge(answers, records)
    header = ('Generated by `make fairness` from a class run of %s UTC, the grader at commit %s: %d answers '
              '(seed %d) graded as one class in %.0f s at JOBS=%d.' % (
                  run['date'], run['commit'], len(answers), run['seed'], run['seconds'], run['jobs']))
    text = report(judged, header)
    with open(os.path.join(out, 'fairness.md'), 'w') as f:
        f.write(text)
    with open(os.path.join(out, 'fairness.json'), 'w') as f:
        json.dump([{'name': a.name, 'style': a.style._asdict(), 'mistake': a.mistake, 'expected': a.expected,
                    'fair': fair, 'how': how, 'total': record['total'] if record else None,
                    'status': record['status'] if record else None,
                    'items': {i['id']: i['points'] for i in record['items']} if record else None}
                   for a, record, fair, how in judged], f, indent=1)
    if not args.no_docs:
        write_docs(args.docs, text)
    for answer, record, fair, how in judged:
        if not fair:
            print('unfair: %s: %s' % (answer.name, how))
    print('report: %s' % os.path.join(out, 'fairness.md'))
    a, b, c, d = summary(judged)
    print('fairness: %d of %d correct answers got 17/17; %d of %d one-mistake answers lost their item only'
          % (a, b, c, d))
    return 0 if (a == b and c == d) else 1


if __name__ == '__main__':
    sys.exit(main())

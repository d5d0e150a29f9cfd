"""Stand-ins for the output of reader47 (``OUT/<student>/report.json``, ``report/`` with the PDF and its
page images, ``code/``) and of answers47 (``OUT/proposals.csv``, ``OUT/<student>/proposals.json``), written
by the shapes of /work/wt/REPORT_CONTRACT.md into an OUT that the grader's real code made, so that the
review page is tested before their work is merged. Once it is, the review's tests read what make grade
itself writes, and this module goes.

The report is a real one of its kind: a PDF and its page drawn by matplotlib from the student's
answers (the passages proposals.json quotes), the page a PNG; the code is a real package copied, made
read-only as the reader keeps it.
"""
import csv
import json
import os
import shutil
import stat

from exam_lab.grader.publish import grades, hand
from exam_lab.grader.score.records import ReportRecord
from exam_lab.grader.score.sheets import HAND_ITEMS

COLUMNS = ['participant', 'student', 'item', 'points', 'max', 'state', 'evidence']


def proposal(item, points, state, passage='', evidence=None, page=1, checks=()):
    """One proposal of proposals.json's shape."""
    return {'item': item, 'points': points, 'max': HAND_ITEMS[item][0], 'state': state,
            'evidence': evidence if evidence is not None else ('p.%d: %s' % (page, passage.split('\n')[0][:60])
                                                               if passage else 'no passage'),
            'checks': [{'name': name, 'ok': ok, 'detail': detail} for name, ok, detail in checks],
            'page': page if passage else None, 'passage': passage}


def _draw_report(folder, passages):
    """OUT/<student>/report/: report.pdf and page-1.png of one page holding the passages."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt
    report = os.path.join(folder, 'report')
    os.makedirs(report, exist_ok=True)
    figure = plt.figure(figsize=(8.27, 11.69))
    text = '\n\n'.join(passages) or '(empty page)'
    figure.text(0.06, 0.96, text[:3000], va='top', family='monospace', fontsize=7, wrap=True)
    figure.savefig(os.path.join(report, 'report.pdf'))
    figure.savefig(os.path.join(report, 'page-1.png'), dpi=60)
    plt.close(figure)
    return text


def _read_only(path):
    for top, dirs, files in os.walk(path, topdown=False):
        for name in files:
            full = os.path.join(top, name)
            if not os.path.islink(full):
                os.chmod(full, stat.S_IRUSR | stat.S_IRGRP | stat.S_IROTH)
        os.chmod(top, stat.S_IRUSR | stat.S_IXUSR | stat.S_IRGRP | stat.S_IXGRP | stat.S_IROTH | stat.S_IXOTH)


def write(out, proposals, code=None, report_state=None):
    """Write the stand-ins into ``out`` (a graded OUT: its grade.json files).

    :param proposals: ``{student: [proposal]}`` (:func:`proposal`); a student not named gets "not read"
        for every item (its report missing).
    :param code: ``{student: the package folder to keep as its code}``.
    :param report_state: ``{student: why}`` of reports not read.
    """
    rows = []
    for folder, record in grades.records_in(out, with_folders=True):
        name = record['student']
        mine = proposals.get(name)
        why = (report_state or {}).get(name)
        if mine is None:
            why = why or 'no report handed in'
            mine = [proposal(item, None, 'not read', evidence='report not read: %s' % why) for item in HAND_ITEMS]
        if why:
            report = ReportRecord.not_read(why)
        else:
            text = _draw_report(folder, [p['passage'] for p in mine if p['passage']])
            report = ReportRecord.make({
                'version': 1, 'state': 'read', 'why': '', 'seconds': 0.5,
                'files': [{'name': 'report.pdf', 'kind': 'pdf', 'converted': False, 'pages': 1, 'note': '',
                           'state': 'read', 'copy': 'report/report.pdf'}],
                'pages': [{'file': 0, 'number': 1, 'source': 'text', 'text': text, 'layout': '', 'pictures': 0,
                           'confidence': None, 'unsure': [], 'image': 'report/page-1.png'}],
                'notes': []})
        with open(os.path.join(folder, ReportRecord.FILE), 'w') as f:
            json.dump(report.value, f)
        with open(os.path.join(folder, 'proposals.json'), 'w') as f:
            json.dump(mine, f)
        if code and name in code:
            target = os.path.join(folder, 'code', os.path.basename(code[name].rstrip('/')))
            shutil.copytree(code[name], target, symlinks=True, ignore=shutil.ignore_patterns('__pycache__'))
            _read_only(os.path.join(folder, 'code'))
        key = hand.key(record)
        for p in mine:
            rows.append({'participant': key if isinstance(key, int) else '', 'student': name, 'item': p['item'],
                         'points': '' if p['points'] is None else p['points'], 'max': p['max'], 'state': p['state'],
                         'evidence': p['evidence'].replace('\n', ' ')})
    with open(os.path.join(out, 'proposals.csv'), 'w', newline='') as f:
        writer = csv.DictWriter(f, COLUMNS)
        writer.writeheader()
        writer.writerows(rows)

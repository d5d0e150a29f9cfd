"""The teacher's hand points beside the machine's: ``hand.csv``. No rospy here.

The machine judges 17 of the sheets' 30 points (:data:`~exam_lab.grader.score.sheets.ITEMS`); the
other 13 (:data:`~exam_lab.grader.score.sheets.HAND_ITEMS`: the report's questions 4-9, the comments,
the code quality) are the teacher's. ``make grade`` writes ``hand.csv`` beside ``grades.csv``: one
row per student, one empty column per hand item, the machine's subtotal for reference, and a first
row ``(max)`` with each column's maximum. The teacher fills it in any spreadsheet (a decimal comma is
read as well as a point) and saves it as CSV; :func:`combine` then adds the two.

Nothing the teacher wrote is ever lost: writing ``hand.csv`` again (a second run, a rescore) keeps
every row and cell already there, updates only the machine's column and adds rows for new students.
An empty cell is a point not given yet, never a 0: :func:`combine` lists it as missing.
"""
import collections
import csv
import io
import os

from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS

FILE = 'hand.csv'
#: The row that shows each column's maximum to the teacher (skipped when read).
MAX_ROW = '(max)'
COLUMNS = ['student', 'participant', 'sheet', 'machine'] + list(HAND_ITEMS) + ['remark']
MACHINE_MAX = sum(points for points, _ in ITEMS.values())
HAND_MAX = sum(points for points, _ in HAND_ITEMS.values())

Hand = collections.namedtuple('Hand', 'student points remark')


class HandError(Exception):
    """hand.csv cannot be read as the teacher meant it: every problem, with its line and column."""


def _points(x):
    return ('%.2f' % x).rstrip('0').rstrip('.')


def _max_row():
    row = {c: '' for c in COLUMNS}
    row.update({'student': MAX_ROW, 'machine': _points(MACHINE_MAX)})
    row.update({item: _points(points) for item, (points, _) in HAND_ITEMS.items()})
    return row


def _rows(path):
    """The rows of an existing hand.csv as dicts (a spreadsheet may add a BOM or use ';')."""
    with open(path, newline='', encoding='utf-8-sig') as f:
        text = f.read()
    try:
        dialect = csv.Sniffer().sniff(text.split('\n', 1)[0], delimiters=',;\t')
    except csv.Error:
        dialect = csv.excel
    reader = csv.DictReader(io.StringIO(text), dialect=dialect)
    missing = [c for c in ['student'] + list(HAND_ITEMS) if c not in (reader.fieldnames or [])]
    if missing:
        raise HandError('%s: no column %s (the header must keep the names make grade wrote: %s)'
                        % (path, ', '.join(missing), ', '.join(COLUMNS)))
    return [(number, row) for number, row in enumerate(reader, start=2)]


def write(path, records):
    """Write ``hand.csv`` for ``records`` (grade records), keeping what the teacher already filled.

    :returns: how many students were added.
    """
    kept, order = {}, []
    if os.path.isfile(path):
        for _, row in _rows(path):
            name = (row.get('student') or '').strip()
            if name and name != MAX_ROW and name not in kept:
                kept[name] = row
                order.append(name)
    added = 0
    for record in records:
        name = record['student']
        row = kept.get(name)
        if row is None:
            row = {c: '' for c in COLUMNS}
            row['student'] = name
            kept[name] = row
            order.append(name)
            added += 1
        row['participant'] = '' if record.get('participant') is None else str(record['participant'])
        row['sheet'] = record.get('sheet', '')
        row['machine'] = _points(record['total'])
    columns = COLUMNS + sorted({c for row in kept.values() for c in row if c and c not in COLUMNS})
    temporary = path + '.new'
    with open(temporary, 'w', newline='', encoding='utf-8') as f:
        writer = csv.DictWriter(f, columns, extrasaction='ignore')
        writer.writeheader()
        writer.writerow(_max_row())
        for name in order:
            writer.writerow({c: kept[name].get(c) or '' for c in columns})
    os.replace(temporary, path)
    return added


def _number(text):
    try:
        return float(text.strip().replace(',', '.'))
    except ValueError:
        return None


def read(path):
    """``{student: Hand}`` from a filled hand.csv; a point not filled in is None.

    :raises HandError: with every cell that is not a number between 0 and its item's maximum, and
        every student named twice (nothing is guessed).
    """
    hands, problems = {}, []
    for line, row in _rows(path):
        name = (row.get('student') or '').strip()
        if not name or name == MAX_ROW:
            continue
        if name in hands:
            problems.append('line %d: %s is already on another line' % (line, name))
            continue
        points = collections.OrderedDict()
        for item, (top, _) in HAND_ITEMS.items():
            cell = (row.get(item) or '').strip()
            value = _number(cell) if cell else None
            if cell and (value is None or not 0.0 <= value <= top):
                problems.append('line %d (%s), column %s: %r is not a number from 0 to %s'
                                % (line, name, item, cell, _points(top)))
            points[item] = value
        hands[name] = Hand(name, points, (row.get('remark') or '').strip())
    if problems:
        raise HandError('%s:\n  %s' % (path, '\n  '.join(problems)))
    return hands


def combine(record, hand):
    """The whole grade of one student: the machine's record with the hand items after its own.

    :param hand: the student's :class:`Hand`, or None when hand.csv has no row for it.
    :returns: a copy of ``record`` with ``items`` (machine then hand, each hand item's evidence
        ``by hand``), ``total``/``max`` out of 30, ``machine_total`` and ``missing`` (the hand items
        not filled in: the total counts them as nothing and says so).
    """
    combined = dict(record)
    items = [dict(entry, by='machine') for entry in record['items']]
    missing = []
    for item, (top, what) in HAND_ITEMS.items():
        value = hand.points.get(item) if hand else None
        if value is None:
            missing.append(item)
        items.append({'id': item, 'points': value or 0.0, 'max': top, 'by': 'hand',
                      'evidence': what if value is not None else 'not filled in hand.csv'})
    combined.update(items=items, machine_total=record['total'], max=MACHINE_MAX + HAND_MAX,
                    total=record['total'] + sum(v for v in (hand.points.values() if hand else ()) if v is not None),
                    missing=missing, remark=hand.remark if hand else '')
    return combined

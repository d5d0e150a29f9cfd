"""The teacher's hand points beside the machine's: ``hand.csv``. No rospy here.

The machine judges 17 of the sheets' 30 points (:data:`~exam_lab.grader.score.sheets.ITEMS`); the
other 13 (:data:`~exam_lab.grader.score.sheets.HAND_ITEMS`: the report's questions 4-9, the comments,
the code quality) are the teacher's. ``make grade`` writes ``hand.csv`` beside ``grades.csv``: one
row per student, one empty column per hand item, the machine's subtotal for reference, and a first
row ``(max)`` with each column's maximum. The teacher fills it in any spreadsheet (a decimal comma is
read as well as a point) and saves it as CSV; :func:`combine` then adds the two.

Nothing the teacher wrote is ever lost: writing ``hand.csv`` again (a second run, a rescore) keeps
every row and cell already there, updates only the machine's columns (and the name shown) and adds
rows for new students. An empty cell is a point not given yet, never a 0: :func:`combine` lists it as
missing.

A row is the student's by Moodle's participant number where the class has one (the ``participant``
column, from the "download all submissions" name: :func:`exam_lab.grader.score.identity.identity`),
by the name only where there is none; the name is shown, never matched, so two students whose names
clean to the same (``Jane Doe`` and ``Jane Doe.``), or who really share a name, never share or swap a
row, even when a late submission renames one of them. :func:`match` gives each graded student its row
and stops at a row that could be another student's (both named). Every cell is written as one no
spreadsheet runs and read back as it was (:mod:`~exam_lab.grader.publish.cells`).
"""
import collections
import csv
import io

from exam_lab.grader import contract
from exam_lab.grader.publish import cells
from exam_lab.grader.score.identity import identity
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS

FILE = 'hand.csv'
#: Most bytes of hand.csv read: a class of a thousand students with long remarks fits many times over.
MAX_BYTES = 8 << 20
#: The row that shows each column's maximum to the teacher (skipped when read).
MAX_ROW = '(max)'
COLUMNS = ['student', 'participant', 'sheet', 'machine'] + list(HAND_ITEMS) + ['remark']
MACHINE_MAX = sum(points for points, _ in ITEMS.values())
HAND_MAX = sum(points for points, _ in HAND_ITEMS.values())

#: One row of hand.csv: ``participant`` (int or None) and ``line`` say which row it is.
Hand = collections.namedtuple('Hand', 'student points remark participant line')
Hand.__new__.__defaults__ = (None, None)


class HandError(Exception):
    """hand.csv cannot be read as the teacher meant it: every problem, with its line and column."""


def key(record):
    """What a grade record's row in hand.csv is keyed by: its participant number (an int) where it
    has one, else its name (a str)."""
    who = identity(record)
    return who.participant if who.participant is not None else record['student']


def _who(key_):
    return 'participant %d' % key_ if isinstance(key_, int) else key_


def _points(x):
    return ('%.2f' % x).rstrip('0').rstrip('.')


def points_cell(x):
    """Points as hand.csv holds them (``1.5``, ``0.25``, ``2``); empty for None (not given)."""
    return '' if x is None else _points(x)


def _max_row():
    row = {c: '' for c in COLUMNS}
    row.update({'student': MAX_ROW, 'machine': _points(MACHINE_MAX)})
    row.update({item: _points(points) for item, (points, _) in HAND_ITEMS.items()})
    return row


def _rows(path):
    """The rows of an existing hand.csv as dicts (a spreadsheet may add a BOM or use ';'), read through
    the contract (no link, a regular file, capped, UTF-8): HandError naming the file otherwise."""
    try:
        text = contract.read_text(path, MAX_BYTES)
    except contract.ContractError as err:
        raise HandError('%s: %s' % (path, str(err).split(': ', 1)[-1]))
    try:  # only the delimiter: a header without quotes makes the sniffer turn doubled quotes off
        delimiter = csv.Sniffer().sniff(text.split('\n', 1)[0], delimiters=',;\t').delimiter
    except csv.Error:
        delimiter = ','
    reader = csv.DictReader(io.StringIO(text), delimiter=delimiter)
    missing = [c for c in ['student'] + list(HAND_ITEMS) if c not in (reader.fieldnames or [])]
    if missing:
        raise HandError('%s: no column %s (the header must keep the names make grade wrote: %s)'
                        % (path, ', '.join(missing), ', '.join(COLUMNS)))
    return [(number, {name: cells.read_cell(value) if isinstance(value, str) else value
                      for name, value in row.items()})
            for number, row in enumerate(reader, start=2)]


def _row_key(line, row):
    """The key of a row of hand.csv (see :func:`key`); HandError for a participant that is no number."""
    number = (row.get('participant') or '').strip()
    if not number:
        return (row.get('student') or '').strip()
    if not number.isdigit():
        raise HandError('line %d (%s), column participant: %r is not a participant number (Moodle\'s, from the '
                        'submission\'s folder): leave it as make grade wrote it' % (line, row.get('student'), number))
    return int(number)


def _kept_rows(path):
    """``{key: (line, row)}`` of an existing hand.csv, in its order; HandError for a student twice."""
    kept, problems = collections.OrderedDict(), []
    for line, row in _rows(path):
        name = (row.get('student') or '').strip()
        if not name or name == MAX_ROW:
            continue
        try:
            found = _row_key(line, row)
        except HandError as err:
            problems.append(str(err))
            continue
        if found in kept:
            problems.append('line %d: %s is already on another line (line %d)' % (
                line, name if isinstance(found, str) else '%s (%s)' % (name, _who(found)), kept[found][0]))
            continue
        kept[found] = (line, row)
    if problems:
        raise HandError('%s:\n  %s' % (path, '\n  '.join(problems)))
    return kept


def newest(records):
    """``(records, notes)``: one record per student (its :func:`key`), the newest graded where one
    participant has several (two archives of a flat download, two folders of OUT after a student was
    renamed in Moodle between two runs: by the grade's provenance date, the later folder on a tie),
    in their order; ``notes`` says, for each such participant, which grade is used and which are not.
    That participant's matter, never the class's: hand.csv, the worksheet and the feedback zip are
    written for everyone, that participant with its newest grade."""
    by_key = collections.OrderedDict()
    for index, record in enumerate(records):
        by_key.setdefault(key(record), []).append((str((record.get('provenance') or {}).get('date') or ''), index))
    chosen = {max(graded)[1] for graded in by_key.values()}
    notes = []
    for found, graded in by_key.items():
        if len(graded) > 1:
            used = records[max(graded)[1]]
            notes.append('%s has %d grades (%s): the newest, %s\'s, is used; %s not (two archives or two folders of '
                         'one participant: remove the stale one and run make rescore)' % (
                             _who(found), len(graded), ', '.join(records[i]['student'] for _, i in graded),
                             used['student'], ', '.join(records[i]['student'] for _, i in graded
                                                        if records[i] is not used)))
    return [record for index, record in enumerate(records) if index in chosen], notes


def write(path, records):
    """Write ``hand.csv`` for ``records`` (grade records), keeping what the teacher already filled:
    each record's row is found by its :func:`key`, never by its name.

    :returns: how many students were added.
    :raises HandError: the existing file holds a student twice or a participant that is no number
        (nothing is written then). One participant of several records has the row of its newest
        (:func:`newest`).
    """
    records, _ = newest(records)
    kept = _kept_rows(path) if contract.exists(path) else collections.OrderedDict()
    rows = collections.OrderedDict((found, row) for found, (_, row) in kept.items())
    added = 0
    for record in records:
        found = key(record)
        row = rows.get(found)
        if row is None:
            row = rows[found] = {c: '' for c in COLUMNS}
            added += 1
        row['student'] = record['student']
        row['participant'] = '' if not isinstance(found, int) else str(found)
        row['sheet'] = record.get('sheet', '')
        row['machine'] = _points(record['total'])
    _save(path, rows)
    return added


def _save(path, rows):
    """``rows`` (``{key: row}``) into ``path`` at once: the columns make grade wrote, then any the
    teacher added, each cell one no spreadsheet runs."""
    columns = COLUMNS + sorted({c for row in rows.values() for c in row if c and c not in COLUMNS})
    text = io.StringIO(newline='')
    writer = csv.DictWriter(text, columns, extrasaction='ignore')
    writer.writeheader()
    writer.writerow(_max_row())
    for row in rows.values():
        writer.writerow({c: cells.cell(row.get(c) or '') for c in columns})
    contract.write_text(path, text.getvalue())


def give(path, records, given):
    """Write points the teacher gave elsewhere than in the spreadsheet (the review page,
    :mod:`~exam_lab.grader.publish.review`) into ``hand.csv``, each only over the cell it was decided on.

    :param given: ``[(key, item, value, was)]``: the student's :func:`key`, a hand item, the points (a
        float, or None to empty the cell: a point not given) and the cell's text when the teacher
        decided (``''`` for empty): a cell that holds anything else now (typed in the spreadsheet
        meanwhile, or by another decision) is left as it is.
    :returns: ``(written, kept)``: the ``(key, item)`` written, and ``(key, item, cell now)`` of those
        left as they were.
    :raises HandError: as :func:`write` (nothing is written then); also an item that is no hand item,
        a value outside its item's range, a key no record has.
    """
    keys = {key(record) for record in records}
    for found, item, value, _ in given:
        if item not in HAND_ITEMS:
            raise HandError('%s is no hand item (%s)' % (item, ', '.join(HAND_ITEMS)))
        if value is not None and not 0.0 <= value <= HAND_ITEMS[item][0]:
            raise HandError('%s: %s is not a number from 0 to %s' % (item, value, _points(HAND_ITEMS[item][0])))
        if found not in keys:
            raise HandError('%s is no graded student of this run' % _who(found))
    if not contract.exists(path) or any(found not in _kept_rows(path) for found, _, _, _ in given):
        write(path, records)  # the student's row added, every cell kept (else the machine's column is left as it is)
    rows = collections.OrderedDict((found, row) for found, (_, row) in _kept_rows(path).items())
    written, kept = [], []
    for found, item, value, was in given:
        now = (rows[found].get(item) or '').strip()
        if not _same(now, (was or '').strip()):
            kept.append((found, item, now))
            continue
        rows[found][item] = '' if value is None else _points(value)
        written.append((found, item))
    if written:
        _save(path, rows)
    return written, kept


def _same(cell, other):
    """Whether two cells hold one value (``1,5`` is ``1.5``; empty is only empty)."""
    return cell == other or (bool(cell) and bool(other) and _number(cell) is not None
                             and _number(cell) == _number(other))


def _number(text):
    try:
        return float(text.strip().replace(',', '.'))
    except ValueError:
        return None


def read(path):
    """``{key: Hand}`` from a filled hand.csv (the key: :func:`key`, the participant number where the
    row has one, else the name); a point not filled in is None.

    :raises HandError: with every cell that is not a number between 0 and its item's maximum, and
        every student named twice (nothing is guessed).
    """
    hands, problems = {}, []
    try:
        kept = _kept_rows(path)
    except HandError as err:
        kept, problems = {}, [str(err).split(':\n  ', 1)[-1]]
    for found, (line, row) in kept.items():
        name = (row.get('student') or '').strip()
        points = collections.OrderedDict()
        for item, (top, _) in HAND_ITEMS.items():
            cell = (row.get(item) or '').strip()
            value = _number(cell) if cell else None
            if cell and (value is None or not 0.0 <= value <= top):
                problems.append('line %d (%s), column %s: %r is not a number from 0 to %s'
                                % (line, name, item, cell, _points(top)))
            points[item] = value
        hands[found] = Hand(name, points, (row.get('remark') or '').strip(),
                            found if isinstance(found, int) else None, line)
    if problems:
        raise HandError('%s:\n  %s' % (path, '\n  '.join(problems)))
    return hands


def match(hands, records):
    """Each record's row of hand.csv, by its :func:`key` only.

    :param hands: :func:`read`'s answer.
    :returns: ``(rows, notes)``: ``rows`` the :class:`Hand` of each record, in order (None when it has
        no row yet), ``notes`` lines for the teacher (a row whose shown name is not the student's
        name today; a row no graded student has).
    :raises HandError: a row whose participant no longer matches: a row with a participant number no
        graded student has, shown with the name of a graded student who is another participant, or
        a row with no number shown with the name of a student who has one. Its points could be that
        student's or not: both are named, nothing is guessed. One participant of several records
        (:func:`newest`): the row is its newest's, the others have none.
    """
    chosen = {id(record) for record in newest(records)[0]}
    by_key = {key(record): record for record in records if id(record) in chosen}
    by_name = {}
    for record in records:
        by_name.setdefault(record['student'], []).append(record)
    problems, notes = [], []
    for found, row in sorted(hands.items(), key=lambda item: item[1].line or 0):
        record = by_key.get(found)
        if record is not None:
            if record['student'] != row.student:
                notes.append('hand.csv line %s: %s is shown as %s there and graded as %s today: its points are '
                             '%s\'s' % (row.line, _who(found), row.student, record['student'], _who(found)))
            continue
        others = [r for r in by_name.get(row.student, []) if key(r) != found]
        if others:
            other = others[0]
            problems.append('hand.csv line %s (%s, %s) and the graded student %s (%s, folder %s) share the name '
                            'but not the participant: the row is not that student\'s. Put the participant '
                            'number of the student the points are for on line %s (or empty the row), then run '
                            'this again' % (row.line, row.student, _who(found) if isinstance(found, int) else
                                            'no participant number', other['student'], _who(key(other)),
                                            other.get('folder') or '-', row.line))
        elif any(v is not None for v in row.points.values()) or row.remark:
            notes.append('hand.csv line %s: %s (%s) is no graded student of this run: its points are not used'
                         % (row.line, row.student, _who(found)))
    if problems:
        raise HandError('\n  '.join(problems))
    return [hands.get(key(record)) if id(record) in chosen else None for record in records], notes


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

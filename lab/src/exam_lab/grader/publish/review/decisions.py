"""The teacher's decisions on the review page: points into hand.csv, and what was decided against the
proposal into ``OUT/review.json``. No rospy, no server.

hand.csv stays the one place the hand points are (make worksheet reads it, a spreadsheet edits it):
a decision writes its cell through :func:`exam_lab.grader.publish.hand.give`, only over the cell it
was made on, so a point typed in the spreadsheet meanwhile is never overwritten; a re-run of make grade
(or make rescore) keeps every cell. Nothing is written before the teacher decides: a proposal is shown,
never a point, until confirmed.

review.json keeps, per student and item, the last decision (the points given, the proposal it was
made on, by a group or for the student alone, when) and every decision in order (``history``), so that
what the teacher changed against the proposals is reported, item by item (:func:`agreement`): the rules
of the proposals are improved where the teacher disagrees with them.

A group's points go to each member whose cell is empty, or still holds what that group's last decision
wrote: a member decided alone, or typed in the spreadsheet, keeps its points (the page lists them).
"""
import collections
import datetime
import json
import os

from exam_lab.grader import contract
from exam_lab.grader.publish import hand
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.sheets import HAND_ITEMS

FILE = 'review.json'
VERSION = 1
CAP = 32 << 20


class ReviewError(Exception):
    """review.json cannot be read as the page wrote it: nothing is written over it."""


def empty():
    return {'version': VERSION, 'cells': {}, 'history': []}


def cell_key(key, item):
    """The key of a student's item in review.json: ``participant 101/Q5``, or ``student <name>/Q5``."""
    return '%s/%s' % ('participant %d' % key if isinstance(key, int) else 'student %s' % key, item)


def load(path):
    """review.json's content (:func:`empty` when there is none), read through the contract (no link
    followed, a regular file only, at most CAP bytes); ReviewError when it is not the page's."""
    if not contract.exists(path):
        return empty()
    try:
        state = json.loads(contract.read_text(path, CAP))
    except contract.ContractError as err:
        raise ReviewError('%s: not read (%s): move it away to start the review again' % (path, err))
    except ValueError as err:
        raise ReviewError('%s is no JSON (%s): move it away to start the review again' % (path, err))
    if not (isinstance(state, dict) and state.get('version') == VERSION and isinstance(state.get('cells'), dict)
            and isinstance(state.get('history'), list)):
        raise ReviewError('%s is not a review of version %d: move it away to start the review again' % (path, VERSION))
    return state


def save(path, state):
    """review.json written whole by the contract's writer (never through an entry there)."""
    contract.write_text(path, json.dumps(state, indent=1, sort_keys=True, ensure_ascii=False))


def parse_points(text, item):
    """The points typed for ``item`` (``1,5`` as ``1.5``; empty: None, the point not given); ValueError
    with the reason for anything else."""
    text = (text or '').strip()
    if not text:
        return None
    try:
        value = float(text.replace(',', '.'))
    except ValueError:
        raise ValueError('%r is not a number' % safe_text.one_line(text)[:40])
    top = HAND_ITEMS[item][0]
    if not 0.0 <= value <= top or value != value:
        raise ValueError('%s is not from 0 to %s for %s' % (text, hand.points_cell(top), item))
    if round(value * 4) != value * 4:
        raise ValueError('%s: points are given in quarters at most' % text)
    return value


def cells_now(path):
    """``{key: {item: cell text}}`` of hand.csv as the teacher's file holds it now (empty when there is
    none); HandError when it cannot be read (the page says why, and writes nothing)."""
    if not os.path.isfile(path):
        return {}
    return {found: {item: hand.points_cell(value) for item, value in row.points.items()}
            for found, row in hand.read(path).items()}


def give(out, records, state, decided, by, group=None, now=None):
    """Write decisions into OUT/hand.csv and ``state`` (then OUT/review.json).

    :param decided: ``[(student, item, value, was)]``: the student (a
        :class:`~exam_lab.grader.publish.review.folder.Student`), the item, the points (None: empty the
        cell) and the cell's text the decision was made on.
    :param by: ``'group'`` or ``'student'``; ``group``: the group's id.
    :returns: ``(written, kept)``: the students written, and ``(student, cell now)`` of those kept.
    :raises HandError: hand.csv cannot be read or written (nothing is).
    """
    path = os.path.join(out, hand.FILE)
    by_key = {student.key: student for student, _, _, _ in decided}
    written, kept = hand.give(path, records, [(s.key, item, value, was) for s, item, value, was in decided])
    written = set(written)
    at = (now or datetime.datetime.now(datetime.timezone.utc)).isoformat(timespec='seconds')
    done, left = [], []
    for student, item, value, was in decided:
        if (student.key, item) not in written:
            continue
        proposal = student.proposals.get(item)
        entry = {'student': student.name, 'participant': student.participant, 'item': item, 'given': value,
                 'was': was, 'proposed': proposal['points'] if proposal else None,
                 'state': proposal['state'] if proposal else 'no proposal', 'by': by, 'group': group, 'at': at}
        state['cells'][cell_key(student.key, item)] = entry
        state['history'].append(entry)
        done.append(student)
    for found, item, now_cell in kept:
        left.append((by_key[found], now_cell))
    save(os.path.join(out, FILE), state)
    return done, left


def group_targets(group_id, item, members, cells, state):
    """Which members of a group its decision writes: ``(to write [(student, was)], kept [(student, cell)])``.
    A member is written when its cell is empty or still holds what this group's last decision wrote."""
    write, keep = [], []
    for student in members:
        now = cells.get(student.key, {}).get(item, '')
        last = state['cells'].get(cell_key(student.key, item))
        ours = last is not None and last.get('by') == 'group' and last.get('group') == group_id \
            and now == hand.points_cell(last.get('given'))
        if not now or ours:
            write.append((student, now))
        else:
            keep.append((student, now))
    return write, keep


Agreement = collections.namedtuple('Agreement', 'item decided agreed changed unproposed')
Agreement.__doc__ = """One item's agreement: how many cells the page decided, how many as proposed,
``changed`` ``[(student, proposed, given, state)]``, ``unproposed`` decided where nothing was proposed."""


def agreement(state):
    """The agreement of the teacher with the proposals, per hand item, from the last decision of each
    cell (a cell emptied again is not counted)."""
    found = collections.OrderedDict((item, Agreement(item, 0, 0, [], 0)) for item in HAND_ITEMS)
    for entry in state['cells'].values():
        item = entry.get('item')
        if item not in found or entry.get('given') is None:
            continue
        old = found[item]
        proposed = entry.get('proposed')
        if proposed is None:
            found[item] = old._replace(decided=old.decided + 1, unproposed=old.unproposed + 1)
        elif proposed == entry['given']:
            found[item] = old._replace(decided=old.decided + 1, agreed=old.agreed + 1)
        else:
            found[item] = old._replace(decided=old.decided + 1, changed=old.changed + [
                (entry.get('student'), proposed, entry['given'], entry.get('state'))])
    return list(found.values())


def agreement_lines(state):
    """:func:`agreement` as lines for the terminal: each item, then each change."""
    lines = []
    for entry in agreement(state):
        compared = entry.decided - entry.unproposed
        share = ' (%d%%)' % round(100.0 * entry.agreed / compared) if compared else ''
        lines.append('%-8s %d decided: %d as proposed%s, %d changed, %d without a proposal' % (
            entry.item, entry.decided, entry.agreed, share, len(entry.changed), entry.unproposed))
        for student, proposed, given, why in entry.changed:
            lines.append('  %s: proposed %s (%s), given %s' % (safe_text.one_line(student or ''), hand.points_cell(proposed),
                                                               why, hand.points_cell(given)))
    return lines

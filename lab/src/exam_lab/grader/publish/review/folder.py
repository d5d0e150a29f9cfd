"""What the review page reads of a run's OUT, and nothing else: each student's grade record, its
proposals, its report's record and page images, its code. No rospy.

Every file here is the grader's own output, but what is in it came from a student: the text of a
report, the names of files, the code itself. So each is read as data, capped, each field checked for
its type and cleaned (:mod:`~exam_lab.grader.score.safe_text`) before the page shows it; and nothing
is read through a link: :func:`read_inside` reads by the contract's one reader, which opens each
component of the path below the student's folder without following one, so a link planted among the copies of a student's files
(``code/notes -> /etc``) is never read, and a path with ``..`` is refused before anything is opened.

The report is read as make rescore and the proposals read it, through its record
(:func:`~exam_lab.grader.publish.proposals.kept_report`, through the contract: capped, checked
against its schema, a record that is none said as a report "not read"); proposals.csv through the proposals' own reader
(:func:`~exam_lab.grader.publish.proposals.rows`), each of its rows and of proposals.json checked field by
field again (a field of another type is dropped, with a note): the page trusts no file of OUT.
"""
import collections
import json
import os

from exam_lab.grader import contract
from exam_lab.grader.publish import grades
from exam_lab.grader.publish import hand, proposals as proposals_csv
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.sheets import HAND_ITEMS

PROPOSALS_CSV = 'proposals.csv'
PROPOSALS_JSON = 'proposals.json'
REPORT_JSON = 'report.json'
CODE = 'code'
STATES = ('proposed', 'to check', 'no answer found', 'not read')
#: Caps of what is read (bytes): a record, the class's proposals, a page image, a code file, the code.
RECORD_CAP = 8 << 20
CSV_CAP = 32 << 20
IMAGE_CAP = 16 << 20
CODE_FILE_CAP = 256 << 10
CODE_CAP = 4 << 20
CODE_FILES = 80
#: Caps of the text kept of a field (characters).
PASSAGE_CAP = 6000
EVIDENCE_CAP = 2000
PAGE_TEXT_CAP = 20000
#: The code shown as text (the rest is listed by name).
CODE_ENDINGS = ('.py', '.launch', '.xml', '.txt', '.yaml', '.yml', '.cfg', '.srv', '.msg', '.md', '.sh',
                '.rst', '.ini', '.json', '.test')
PNG = b'\x89PNG\r\n\x1a\n'

Student = collections.namedtuple('Student', 'index record key name participant sheet status folder '
                                            'proposals report')
Student.__doc__ = """One student of the page: ``index`` its place (its URL), ``key`` its row of hand.csv
(:func:`~exam_lab.grader.publish.hand.key`), ``proposals`` ``{item: proposal}``, ``report`` its
report's record as read (a dict; None when there is none); its code is read when shown (:func:`code_files`)."""


class Refused(Exception):
    """A path the page does not open: outside the student's folder, through a link, not a file."""


def read_inside(base, relative, cap):
    """The bytes of ``base/relative``, read by the contract's one reader (never through a link nor
    outside ``base``, a regular file only, at most ``cap`` bytes); Refused otherwise."""
    parts = relative.replace('\\', '/').split('/')
    if not relative or relative.startswith('/') or any(p in ('', '.', '..') for p in parts) or '\0' in relative:
        raise Refused('%r is no path inside the student\'s folder' % relative)
    try:
        return contract.read_bytes(os.path.join(base, *parts), cap, under=base)
    except contract.ContractError as err:
        raise Refused(str(err))


def _text(value, cap):
    return safe_text.clean(value)[:cap] if isinstance(value, str) else ''


def _number(value):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value)


def proposal(raw, notes, where):
    """A proposal (a dict of proposals.json's or a row of proposals.csv) checked field by field: None
    when it is none (no hand item, no state); a note for each field dropped."""
    if not isinstance(raw, dict):
        return None
    item = raw.get('item')
    state = raw.get('state')
    if item not in HAND_ITEMS or state not in STATES:
        notes.append('%s: a proposal that is none (item %r, state %r): left out'
                     % (where, safe_text.one_line(str(item))[:40], safe_text.one_line(str(state))[:40]))
        return None
    top = HAND_ITEMS[item][0]
    points = raw.get('points')
    if isinstance(points, str):  # the CSV's cell
        try:
            points = float(points.strip().replace(',', '.')) if points.strip() else None
        except ValueError:
            points = None
    points = _number(points)
    if points is not None and not 0.0 <= points <= top:
        notes.append('%s %s: proposed %s, outside 0-%s: shown as no points' % (where, item, points, top))
        points = None
    checks = []
    for check in raw.get('checks') or [] if isinstance(raw.get('checks'), list) else []:
        if isinstance(check, dict):
            ok = check.get('ok')
            checks.append({'name': _text(check.get('name'), 200), 'ok': ok if isinstance(ok, bool) else None,
                           'detail': _text(check.get('detail'), EVIDENCE_CAP)})
    page = raw.get('page')
    if isinstance(page, str) and page.strip().isdigit():
        page = int(page)
    return {'item': item, 'points': points, 'max': top, 'state': state,
            'evidence': _text(raw.get('evidence'), EVIDENCE_CAP),
            'checks': checks[:40], 'page': page if isinstance(page, int) and not isinstance(page, bool) else None,
            'passage': _text(raw.get('passage'), PASSAGE_CAP)}


def _class_proposals(out, notes):
    """``{participant or name: {item: proposal}}`` of OUT/proposals.csv."""
    path = os.path.join(out, PROPOSALS_CSV)
    if not os.path.isfile(path):
        return {}
    try:
        text = read_inside(out, PROPOSALS_CSV, CSV_CAP).decode('utf-8-sig', 'replace')
    except Refused as err:
        notes.append('proposals.csv not read: %s' % err)
        return {}
    found = {}
    for number, row in enumerate(proposals_csv.rows(text), start=2):
        where = 'proposals.csv line %d' % number
        participant = (row.get('participant') or '').strip()
        who = int(participant) if participant.isdigit() else (row.get('student') or '').strip()
        checked = proposal(row, notes, where)
        if checked is not None:
            found.setdefault(who, {})[checked['item']] = checked
    return found


def _student_proposals(folder, name, notes):
    try:
        raw = json.loads(read_inside(folder, PROPOSALS_JSON, RECORD_CAP).decode('utf-8'))
    except Refused:
        return {}
    except ValueError as err:
        notes.append('%s/%s is no JSON (%s): its proposals.csv rows are shown' % (name, PROPOSALS_JSON, err))
        return {}
    found = {}
    for entry in raw if isinstance(raw, list) else []:
        checked = proposal(entry, notes, '%s/%s' % (name, PROPOSALS_JSON))
        if checked is not None:
            found[checked['item']] = checked
    return found


def report_record(folder, name, notes):
    """The student's report.json as the page shows it (None when there is none): its
    :class:`~exam_lab.grader.score.records.ReportRecord`'s value, read as make rescore reads it; a
    record that is none is a report "not read" saying why, with a note. Only a page image below
    ``report/`` that is a PNG is shown."""
    try:
        read_inside(folder, REPORT_JSON, RECORD_CAP)  # no link, no folder, under the cap
    except Refused:
        return None
    record = proposals_csv.kept_report(folder).value
    if record['state'] == 'not read' and record['why'].startswith('the kept report.json is not'):
        notes.append('%s/%s: %s' % (name, REPORT_JSON, record['why']))
    for page in record['pages']:
        if not (page['image'] or '').lower().endswith('.png'):
            page['image'] = None
    return record


def page_image(student, index):
    """The PNG bytes of the student's report page ``index`` (its place in report.json's pages); Refused
    when it has none, or the file is not a PNG inside the student's folder."""
    pages = (student.report or {}).get('pages') or []
    if not 0 <= index < len(pages) or not pages[index]['image']:
        raise Refused('no such page image')
    data = read_inside(student.folder, pages[index]['image'], IMAGE_CAP)
    if not data.startswith(PNG):
        raise Refused('%s is not a PNG' % pages[index]['image'])
    return data


def code_files(folder):
    """The student's code as the page shows it: ``[(path, text or None, why not shown)]`` of
    OUT/<student>/code/, in name order, walked without following a link (a link is listed, not read),
    text files under the caps read and cleaned."""
    root = os.path.join(folder, CODE)
    if os.path.islink(root) or not os.path.isdir(root):
        return []
    found, total = [], 0
    for top, dirs, files in os.walk(root):
        dirs.sort()
        relative_top = os.path.relpath(top, folder)
        for name in sorted(files) + sorted(d for d in dirs if os.path.islink(os.path.join(top, d))):
            path = os.path.join(relative_top, name).replace(os.sep, '/')
            shown = path[len(CODE) + 1:]
            if len(found) >= CODE_FILES:
                return found + [('...', None, 'more files: see %s' % os.path.join(folder, CODE))]
            if os.path.islink(os.path.join(top, name)):
                found.append((shown, None, 'a link, not followed'))
                continue
            if not (name.endswith(CODE_ENDINGS) or name == 'CMakeLists.txt'):
                found.append((shown, None, 'not text code'))
                continue
            try:
                data = read_inside(folder, path, CODE_FILE_CAP)
            except Refused as err:
                found.append((shown, None, str(err)))
                continue
            if total + len(data) > CODE_CAP:
                found.append((shown, None, 'over the page\'s %d bytes of code' % CODE_CAP))
                continue
            total += len(data)
            found.append((shown, safe_text.clean(data.decode('utf-8', 'replace')), ''))
    return found


def load(out):
    """The students of OUT, as the page shows them (the grade records' order), and notes for the
    teacher (a file not read, a field dropped).

    :raises RecordError: a grade.json that is no grade record (as make worksheet)."""
    notes = []
    listed = grades.records_in(out, with_folders=True)
    by_key = _class_proposals(out, notes)
    students = []
    for index, (folder, record) in enumerate(listed):
        key = hand.key(record)
        name = safe_text.one_line(record['student'])
        proposals = dict(by_key.get(key) or by_key.get(record['student']) or {})
        proposals.update(_student_proposals(folder, name, notes))
        students.append(Student(index, record, key, name, record.get('participant'), record.get('sheet') or '',
                                record.get('status') or '', folder, proposals,
                                report_record(folder, name, notes)))
    return students, notes

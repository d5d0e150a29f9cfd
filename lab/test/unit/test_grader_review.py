"""make review's pure parts and its server in-process (issue 47 point 6): answers grouped by their
normalised text, points written into hand.csv only where decided (nothing typed lost, a re-run keeps
them), review.json's agreement, nothing read through a link, the data escaped, the token and the Host
checked.

The class is what the grader writes: graded by its own code from real kept measurements (make
rescore's path); each student's report the one its reader kept of a fixture of data/reports
(data/kept/report-<fixture>/report.json, copied from the OUT of test_review_browser's class, graded
by make grade's grade.py), its copies kept by root's own code (host/reports.keep_copies: the PDF as
handed in, each page as the reader renders it with pdftoppm), its code by host/reports.keep_code, its
proposals written by the desk's publish/proposals.py against the drones' reference records
(data/answers, captured from the drones). Only the answer groups' own tests build proposals from a
literal passage, with score/answers.py's proposal (the shape proposals.json holds).
"""
import csv
import html
import http.client
import json
import os
import shutil
import subprocess
import threading
import urllib.parse

import pytest

from exam_lab.grader.host import reports
from exam_lab.grader.publish import grades, hand, proposals
from exam_lab.grader.publish.review import decisions, folder, groups, page, server
from exam_lab.grader.score import answers
from exam_lab.grader.score.records import MEASUREMENTS, ReportRecord
from exam_lab.grader.score.sheets import HAND_ITEMS

from test_answers import DATA as ANSWERS
from test_grader_kept import KEPT, kept_copy

HERE = os.path.dirname(os.path.abspath(__file__))
GOOD = os.path.join(os.path.dirname(HERE), 'grader', 'submissions', 'good_student', 'exam')
REPORTS = os.path.join(HERE, 'data', 'reports')
Q4 = '$ rosnode list\n/mydrone\n/rosout\nLes deux nœuds qui tournent: le drone et rosout.'
#: Each student's report (a fixture of data/reports, as its reader kept it): ann and bob handed in
#: the same one, cyd another (sheet 001's, in a table), dan a hostile one (no question 4, markup for
#: question 5's comment); zoe's report was not read (none kept).
HANDED_IN = {'ann': 'fr_odt', 'bob': 'fr_odt', 'cyd': 'en_docx_table', 'dan': 'hostile'}
#: The students whose package's code the grader kept.
WITH_CODE = ('ann', 'dan')
#: pdftoppm's options of the reader's page images (boxed/report_reader.py, Pages.render).
PREVIEW = ['-png', '-scale-to', '1400']


@pytest.fixture(scope='module')
def boxes(tmp_path_factory):
    """What the reader's box leaves of each report of :data:`HANDED_IN`, made again once:
    ``{fixture: (the record it kept, the box's out folder)}``, the folder's report/ holding the PDF as
    handed in (the record's copy) and each page's PNG as the reader renders it."""
    root = tmp_path_factory.mktemp('boxes')
    made = {}
    for fixture in sorted(set(HANDED_IN.values())):
        record = ReportRecord.read(os.path.join(KEPT, 'report-' + fixture, ReportRecord.FILE))
        where = str(root / fixture)
        os.makedirs(os.path.join(where, 'report'))
        (copy,) = [f.copy for f in record.files]
        shutil.copyfile(os.path.join(REPORTS, fixture + '.pdf'), os.path.join(where, copy))
        for number, image in [(p.number, p.image) for p in record.pages]:
            prefix = os.path.join(where, 'page')
            subprocess.run(['pdftoppm'] + PREVIEW + ['-singlefile', '-f', str(number), '-l', str(number),
                                                    os.path.join(where, copy), prefix], check=True)
            os.rename(prefix + '.png', os.path.join(where, image))
        made[fixture] = record, where
    return made


def graded_out(root, boxes, names=('ann', 'bob', 'cyd', 'dan'), report_only=('zoe',)):
    """An OUT made by the grader's code: ``names`` graded from real kept measurements (good_student's
    grading, renamed), ``report_only`` not graded (a real no-node grading): grade.json by make rescore's
    rescore, hand.csv by make grade's writer; the reports of :data:`HANDED_IN` (from ``boxes``) and the
    code of :data:`WITH_CODE` kept, and the proposals written, as the grader keeps and writes them."""
    out = root / 'out'
    shapes = [(n, 'version-1') for n in names] + [(n, 'no-node-version-1') for n in report_only]
    for index, (name, shape) in enumerate(shapes):
        measured = kept_copy(shape)
        number = 201 + index
        measured.update(student=name, extra=dict(measured['extra'], participant=number,
                                                 folder='%s_%d_assignsubmission_file_' % (name, number)))
        (out / name).mkdir(parents=True)
        (out / name / MEASUREMENTS).write_text(json.dumps(measured))
        if name in HANDED_IN:
            record, where = boxes[HANDED_IN[name]]
            kept = reports.keep_copies(record, where, str(out / name))
            assert kept == record, kept.notes  # every file and page kept
            reports.write(str(out / name), kept)
        if name in WITH_CODE:
            assert reports.keep_code(GOOD, str(out / name)) == []
    records, _ = grades.rescore(str(out))
    hand.write(str(out / hand.FILE), records)
    for sheet in {r.get('sheet') or 'altitude' for r in records}:
        shutil.copy(os.path.join(ANSWERS, 'reference-%s.json' % sheet), str(out))
    proposals.write(str(out), records)
    return out, records


def proposed(out, name):
    """``{item: proposal}`` of the student's proposals.json, as the desk wrote it."""
    return {p['item']: p for p in json.loads((out / name / proposals.STUDENT_FILE).read_text())}


@pytest.fixture
def out(tmp_path, boxes):
    out, records = graded_out(tmp_path, boxes)
    return out


def test_normalise_sets_aside_case_spacing_and_what_each_run_changes():
    assert groups.normalise('  Rosnode  LIST\n/mydrone ') == groups.normalise('rosnode list /mydrone')
    assert groups.normalise('Pid: 12345') == groups.normalise('pid 99') == 'pid #'
    assert groups.normalise('URI: http://ann-laptop:41235/') == groups.normalise('uri: http://bob:38001/')
    assert groups.normalise('ﬁle') == 'file'  # NFKC
    assert groups.normalise('10 Hz') != groups.normalise('1 Hz')
    assert groups.normalise('data: 0.778') != groups.normalise('data: 0.779')


def p(item, points, state, passage=''):
    """A proposal of a literal passage, as score/answers.py makes one (proposals.json's entry)."""
    return answers.proposal(item, state, points, 'p.1: %s' % passage.split('\n')[0] if passage else 'no passage',
                            page=1 if passage else None, passage=passage)


def test_groups_put_identical_answers_together_every_member_listed():
    found = groups.groups('Q4', [
        ('altitude', p('Q4', 1.0, 'proposed', Q4)), ('altitude', p('Q4', 1.0, 'proposed', Q4.upper())),
        ('altitude', p('Q4', 0.5, 'proposed', 'rosnode list')), ('altitude', p('Q4', None, 'no answer found')),
        ('altitude', p('Q4', None, 'not read')), ('depth', p('Q4', 1.0, 'proposed', Q4)),
        ('altitude', p('Q4', None, 'no answer found')), ('altitude', None)])
    assert [g.members for g in found] == [[0, 1], [3, 6], [2], [4], [5], [7]]
    assert found[0].proposals == [(1.0, 'proposed')] and groups.proposed_points(found[0]) == 1.0
    assert found[1].state == 'no answer found' and groups.proposed_points(found[1]) is None
    assert found[-1].state == groups.NO_PROPOSAL
    assert sorted(i for g in found for i in g.members) == list(range(8))
    again = groups.groups('Q4', [('altitude', p('Q4', 1.0, 'proposed', Q4))])
    assert again[0].id == found[0].id  # stable: its URL, its decisions


def test_a_group_whose_proposals_differ_has_no_points_to_confirm():
    found = groups.groups('Q5', [('altitude', p('Q5', 1.0, 'to check', 'x')), ('altitude', p('Q5', 2.0, 'proposed', 'X'))])
    assert len(found) == 1 and groups.proposed_points(found[0]) is None


def test_parse_points():
    assert decisions.parse_points('1,5', 'Q5') == 1.5 and decisions.parse_points(' ', 'Q5') is None
    for bad in ('3', '-1', 'abc', '0.3', 'nan'):
        with pytest.raises(ValueError):
            decisions.parse_points(bad, 'Q5')


def hand_rows(out):
    with open(str(out / hand.FILE), newline='') as f:
        return {row['student']: row for row in csv.DictReader(f)}


def test_give_writes_only_the_cells_decided_and_keeps_what_was_typed(out):
    path = str(out / hand.FILE)
    records = grades.records_in(str(out))
    by = {r['student']: hand.key(r) for r in records}
    written, kept = hand.give(path, records, [(by['ann'], 'Q4', 1.0, ''), (by['bob'], 'Q4', 0.5, '')])
    assert written == [(by['ann'], 'Q4'), (by['bob'], 'Q4')] and kept == []
    # the teacher types bob's Q4 and cyd's remark in the spreadsheet meanwhile, with a decimal comma
    rows = hand_rows(out)
    rows['bob']['Q4'], rows['cyd']['remark'] = '0,75', 'seen'
    with open(path, 'w', newline='') as f:
        writer = csv.DictWriter(f, list(rows['ann']))
        writer.writeheader()
        writer.writerows(rows.values())
    written, kept = hand.give(path, records, [(by['bob'], 'Q4', 1.0, '0.5'), (by['ann'], 'Q4', 0.0, '1')])
    assert written == [(by['ann'], 'Q4')] and kept == [(by['bob'], 'Q4', '0,75')]
    rows = hand_rows(out)
    assert (rows['ann']['Q4'], rows['bob']['Q4'], rows['cyd']['remark']) == ('0', '0,75', 'seen')
    assert all(rows[n][item] == '' for n in ('cyd', 'dan', 'zoe') for item in HAND_ITEMS)
    # a re-run of make grade (or make rescore) writes hand.csv again: every point kept
    hand.write(path, grades.rescore(str(out))[0])
    assert hand.read(path)[by['bob']].points['Q4'] == 0.75 and hand.read(path)[by['ann']].points['Q4'] == 0.0
    with pytest.raises(hand.HandError):
        hand.give(path, records, [(by['ann'], 'Q4', 2.0, '')])
    with pytest.raises(hand.HandError):
        hand.give(path, records, [(9999, 'Q4', 1.0, '')])


def test_a_group_confirmed_then_a_member_changed_then_the_group_changed(out):
    students, notes = folder.load(str(out))
    assert notes == []
    by = {s.name: s for s in students}
    state = decisions.empty()
    found = groups.groups('Q4', [(s.sheet, s.proposals.get('Q4')) for s in students])
    pair = [g for g in found if len(g.members) == 2 and not g.state][0]
    members = [students[i] for i in pair.members]
    assert sorted(s.name for s in members) == ['ann', 'bob']
    cells = decisions.cells_now(str(out / hand.FILE))
    write, kept = decisions.group_targets(pair.id, 'Q4', members, cells, state)
    assert [s.name for s, _ in write] == ['ann', 'bob'] and kept == []
    decisions.give(str(out), [s.record for s in students], state, [(s, 'Q4', 1.0, was) for s, was in write], 'group', pair.id)
    decisions.give(str(out), [s.record for s in students], state, [(by['bob'], 'Q4', 0.5, '1')], 'student')
    cells = decisions.cells_now(str(out / hand.FILE))
    write, kept = decisions.group_targets(pair.id, 'Q4', members, cells, state)
    assert [s.name for s, _ in write] == ['ann'] and [(s.name, c) for s, c in kept] == [('bob', '0.5')]
    decisions.give(str(out), [s.record for s in students], state, [(s, 'Q4', 0.0, was) for s, was in write], 'group', pair.id)
    assert hand_rows(out)['ann']['Q4'] == '0' and hand_rows(out)['bob']['Q4'] == '0.5'
    kept_state = decisions.load(str(out / decisions.FILE))
    assert kept_state == json.loads(json.dumps(state)) and len(kept_state['history']) == 4
    # the agreement against what the desk proposed them (one answer: one proposal)
    ours = proposed(out, 'ann')['Q4']
    assert proposed(out, 'bob')['Q4']['points'] == ours['points'] and ours['points'] is not None, ours
    changed = [(n, ours['points'], given, ours['state']) for n, given in (('ann', 0.0), ('bob', 0.5))
               if given != ours['points']]
    q4 = decisions.agreement(kept_state)[0]
    assert (q4.item, q4.decided, q4.agreed) == ('Q4', 2, 2 - len(changed))
    assert sorted(q4.changed) == changed
    lines = decisions.agreement_lines(kept_state)
    assert lines[0].startswith('Q4       2 decided: %d as proposed (%d%%), %d changed' % (
        2 - len(changed), 50 * (2 - len(changed)), len(changed)))
    for name, was, given, why in changed:
        assert '  %s: proposed %s (%s), given %s' % (name, hand.points_cell(was), why, hand.points_cell(given)) in lines


def test_review_json_that_is_not_the_pages_is_never_written_over(tmp_path):
    path = tmp_path / decisions.FILE
    path.write_text('{"cells": []}')
    with pytest.raises(decisions.ReviewError):
        decisions.load(str(path))


def test_review_json_is_read_and_written_by_the_contract_never_through_a_link(tmp_path):
    """A review.json that is a link (to a review of the page's own shape) or a FIFO is refused, never
    followed nor waited on; saving replaces a link planted in its place, never writes through it."""
    elsewhere = tmp_path / 'elsewhere.json'
    elsewhere.write_text(json.dumps(decisions.empty()))
    path = tmp_path / decisions.FILE
    path.symlink_to(elsewhere)
    with pytest.raises(decisions.ReviewError, match='not read'):
        decisions.load(str(path))
    decisions.save(str(path), dict(decisions.empty(), history=[{'planted': False}]))
    assert not path.is_symlink() and json.loads(elsewhere.read_text()) == decisions.empty()
    assert decisions.load(str(path))['history'] == [{'planted': False}]
    path.unlink()
    os.mkfifo(str(path))
    with pytest.raises(decisions.ReviewError, match='not a regular file'):
        decisions.load(str(path))


def test_nothing_is_read_through_a_link_or_outside_the_students_folder(out, tmp_path):
    ann = str(out / 'ann')
    secret = tmp_path / 'secret.py'
    secret.write_text('SECRET = 1\n')
    os.chmod(str(out / 'ann' / 'code'), 0o755)
    os.symlink(str(secret), str(out / 'ann' / 'code' / 'planted.py'))
    os.symlink(str(tmp_path), str(out / 'ann' / 'code' / 'outside'))
    os.symlink(str(out / 'ann' / 'code'), str(out / 'ann' / 'linked'))
    for bad in ('../bob/report.json', '/etc/passwd', 'code/planted.py', 'linked/package.xml', 'code/outside/secret.py',
                'report/', ''):
        with pytest.raises(folder.Refused):
            folder.read_inside(ann, bad, folder.CODE_FILE_CAP)
    assert folder.read_inside(ann, 'code/package.xml', folder.CODE_FILE_CAP).startswith(b'<?xml')
    code = {path: (text, why) for path, text, why in folder.code_files(ann)}
    assert code['planted.py'] == (None, 'a link, not followed') and code['outside'] == (None, 'a link, not followed')
    assert 'SECRET' not in json.dumps(code) and code['package.xml'][0].startswith('<?xml')


def test_a_page_image_must_be_a_png_report_json_names(out):
    students, _ = folder.load(str(out))
    ann = [s for s in students if s.name == 'ann'][0]
    assert [folder.page_image(ann, i)[:8] for i in range(len(ann.report['pages']))] == [folder.PNG] * 2
    with pytest.raises(folder.Refused):
        folder.page_image(ann, len(ann.report['pages']))
    record = json.loads((out / 'ann' / 'report.json').read_text())
    record['pages'][0]['image'] = '../bob/' + record['pages'][0]['image']
    assert (out / 'ann' / record['pages'][0]['image']).is_file()  # bob's page is there: refused for its path
    (out / 'ann' / 'report.json').write_text(json.dumps(record))
    students, _ = folder.load(str(out))
    with pytest.raises(folder.Refused):
        folder.page_image([s for s in students if s.name == 'ann'][0], 0)


def test_the_report_is_read_through_its_checked_record_as_make_rescore_reads_it(out):
    """A report.json that is no record of the grader (a state 'read' without a page, a page of a file it
    does not list) is shown "not read" with why and a note, never its text; a report.json that is a link
    is not read at all."""
    record = json.loads((out / 'ann' / 'report.json').read_text())
    assert folder.report_record(str(out / 'ann'), 'ann', []) == proposals.kept_report(str(out / 'ann')).value
    record['pages'][0]['file'] = 3
    record['pages'][0]['text'] = 'PLANTED TEXT'
    (out / 'ann' / 'report.json').write_text(json.dumps(record))
    (out / 'cyd' / 'report.json').unlink()
    (out / 'cyd' / 'report.json').symlink_to(out / 'bob' / 'report.json')
    students, notes = folder.load(str(out))
    ann, cyd = [s for s in students if s.name == 'ann'][0], [s for s in students if s.name == 'cyd'][0]
    assert ann.report['state'] == 'not read' and ann.report['pages'] == [] and 'pages[0].file' in ann.report['why']
    assert 'PLANTED' not in json.dumps(ann.report)
    assert any(n.startswith('ann/report.json: the kept report.json is not a record') for n in notes)
    assert cyd.report is None


def test_the_readers_notes_are_on_the_students_page(out):
    """What the reader left out or could not read (its record's notes: a page not read by OCR, the cap
    of unsure words) is said on the student's page, escaped, never a silent cut."""
    record = json.loads((out / 'ann' / 'report.json').read_text())
    record['notes'] = ['page 2 of report.pdf: 340 words read by OCR with low confidence, the first 200 listed',
                       'page 3 of report.pdf: not read by OCR: <tesseract> stopped']
    (out / 'ann' / 'report.json').write_text(json.dumps(record))
    students, notes = folder.load(str(out))
    ann = [s for s in students if s.name == 'ann'][0]
    shown = page.student_page('t', '/T', ann, decisions.cells_now(str(out / hand.FILE)), folder.code_files(ann.folder))
    assert '340 words read by OCR with low confidence, the first 200 listed' in shown
    assert 'not read by OCR: &lt;tesseract&gt; stopped' in shown and '<tesseract>' not in shown


def test_fields_of_another_type_are_dropped_with_a_note(out):
    (out / 'cyd' / 'proposals.json').write_text(json.dumps([
        {'item': 'Q4', 'points': 7, 'state': 'proposed', 'evidence': ['x'], 'passage': 3},
        {'item': 'Q99', 'points': 1, 'state': 'proposed'}, 'nonsense', {'item': 'Q6', 'state': 'maybe'}]))
    students, notes = folder.load(str(out))
    cyd = [s for s in students if s.name == 'cyd'][0]
    assert cyd.proposals['Q4']['points'] is None and cyd.proposals['Q4']['evidence'] == ''
    assert any('outside 0-1' in n for n in notes) and any("'Q99'" in n for n in notes) and any("'maybe'" in n for n in notes)


def test_the_pages_escape_the_students_text_and_run_no_script(out):
    """dan's report (hostile.pdf) answers question 5 with markup: the passage the desk proposed from it
    holds it as the student typed it, the pages show it escaped."""
    hostile = [line for line in proposed(out, 'dan')['Q5']['passage'].split('\n') if '<' in line]
    assert '<script>document.title="pwned"</script>' in hostile and len(hostile) == 3, hostile
    students, notes = folder.load(str(out))
    dan = [s for s in students if s.name == 'dan'][0]
    cells = decisions.cells_now(str(out / hand.FILE))
    os.chmod(str(out / 'dan' / 'code'), 0o755)
    (out / 'dan' / 'code' / '<img src=x onerror=alert(1)>.py').write_text('# ' + hostile[0] + '\n')
    shown = page.student_page('t', '/T', dan, cells, folder.code_files(dan.folder))
    found = groups.groups('Q5', [(s.sheet, s.proposals.get('Q5')) for s in students])
    listed = page.item_page('t', '/T', 'Q5', found, students, cells, {g.id: ([], []) for g in found})
    for text in (shown, listed):
        assert '<script' not in text and '<img src=x' not in text and 'onerror="' not in text and '<a href="file' not in text
        assert all(html.escape(line, quote=True) in text for line in hostile), hostile
        assert '&lt;script&gt;document.title=&quot;pwned&quot;&lt;/script&gt;' in text
    assert '&lt;img src=x onerror=alert(1)&gt;.py' in shown
    assert "script-src" not in page.POLICY and "default-src 'none'" in page.POLICY


class Running(object):
    """The review server on a thread, for requests over loopback."""

    def __init__(self, out):
        self.httpd = server.Server(server.Review(str(out)))
        self.port = self.httpd.server_address[1]
        self.base = '/%s' % self.httpd.token
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def request(self, method, path, body=None, headers=None):
        connection = http.client.HTTPConnection('127.0.0.1', self.port, timeout=30)
        try:
            connection.request(method, path, body=body, headers=dict(
                {'Host': '127.0.0.1:%d' % self.port}, **(headers or {})))
            answer = connection.getresponse()
            return answer.status, dict(answer.getheaders()), answer.read().decode('utf-8', 'replace')
        finally:
            connection.close()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()
        self.thread.join(30)


@pytest.fixture
def running(out):
    run = Running(out)
    yield run
    run.close()


def test_only_the_token_opens_the_page_and_only_its_pages(running):
    assert running.httpd.server_address[0] == '127.0.0.1'
    status, headers, body = running.request('GET', running.base + '/')
    assert status == 200 and 'ann' in body and 'zoe' in body
    assert "default-src 'none'" in headers['Content-Security-Policy'] and headers['X-Content-Type-Options'] == 'nosniff'
    wrong = running.base[:-1] + ('A' if running.base[-1] != 'A' else 'B')
    for path in ('/', '/index.html', wrong + '/', running.base + '/../hand.csv', 'http://127.0.0.1' + running.base + '/',
                 running.base + '/hand.csv', running.base + '/review.json', running.base + '/student/99',
                 running.base + '/image/0/7', running.base + '/image/0/../../../etc/passwd', running.base + '/item/Q99',
                 running.base + '/student/0/../../hand.csv', '/../' + running.base[1:] + '/', running.base + '%2f..%2fhand.csv'):
        status, _, body = running.request('GET', path)
        assert status == 404 and 'ann' not in body, path
    status, _, _ = running.request('GET', running.base + '/', headers={'Host': 'evil.example:%d' % running.port})
    assert status == 403  # DNS rebinding: a name of another site pointing at 127.0.0.1
    status, headers, body = running.request('GET', running.base + '/image/0/0')
    assert status == 200 and headers['Content-Type'] == 'image/png'


def test_a_post_from_another_site_is_refused(running, out):
    form = urllib.parse.urlencode({'points': '1', 'was': ''})
    kinds = {'Content-Type': 'application/x-www-form-urlencoded'}
    for more in ({'Origin': 'http://evil.example'}, {'Sec-Fetch-Site': 'cross-site'}):
        status, _, _ = running.request('POST', running.base + '/student/0/Q4', form, dict(kinds, **more))
        assert status == 403
    status, _, _ = running.request('POST', '/nottoken/student/0/Q4', form, kinds)
    assert status == 404
    assert all(row['Q4'] == '' for row in hand_rows(out).values() if row['student'] != hand.MAX_ROW)
    status, headers, _ = running.request('POST', running.base + '/student/0/Q4', form, dict(
        kinds, Origin='http://127.0.0.1:%d' % running.port))
    assert status == 303 and headers['Location'].startswith(running.base + '/student/0?said=')
    assert hand_rows(out)['ann']['Q4'] == '1'
    status, _, body = running.request('GET', headers['Location'].split('#')[0])
    assert 'ann Q4: 1 written to hand.csv' in body


def test_a_decision_leaves_the_machines_column_as_a_rescore_wrote_it(out):
    """The page's records are read when it starts: a make rescore meanwhile moved the machine's points,
    and a decision after it must not write the old ones back."""
    path = str(out / hand.FILE)
    records = grades.records_in(str(out))
    rows = hand_rows(out)
    rows['ann']['machine'] = '15.5'
    with open(path, 'w', newline='') as f:
        writer = csv.DictWriter(f, list(rows['ann']))
        writer.writeheader()
        writer.writerows(rows.values())
    hand.give(path, records, [(hand.key(records[0]), 'Q6', 1.0, '')])
    assert hand_rows(out)['ann']['machine'] == '15.5' and hand_rows(out)['ann']['Q6'] == '1'


def test_a_group_decided_shows_its_points_to_change_them_once_more(out):
    students, _ = folder.load(str(out))
    found = groups.groups('Q4', [(s.sheet, s.proposals.get('Q4')) for s in students])
    pair = found[0]
    members = [students[i] for i in pair.members]
    state = decisions.empty()
    cells = decisions.cells_now(str(out / hand.FILE))
    targets = {g.id: decisions.group_targets(g.id, 'Q4', [students[i] for i in g.members], cells, state) for g in found}
    assert 'id="give-%s">Confirm<' % pair.id in page.item_page('t', '/T', 'Q4', found, students, cells, targets)
    decisions.give(str(out), [s.record for s in students], state,
                   [(s, 'Q4', 0.5, was) for s, was in targets[pair.id][0]], 'group', pair.id)
    cells = decisions.cells_now(str(out / hand.FILE))
    targets = {g.id: decisions.group_targets(g.id, 'Q4', [students[i] for i in g.members], cells, state) for g in found}
    shown = page.item_page('t', '/T', 'Q4', found, students, cells, targets)
    assert 'id="give-%s">Change<' % pair.id in shown and 'id="points-%s" value="0.5"' % pair.id in shown
    assert shown.count('<strong>0.5 in hand.csv</strong>') == len(members) == 2


def review_script():
    import importlib.util
    spec = importlib.util.spec_from_file_location('review_script', os.path.join(
        os.path.dirname(os.path.dirname(HERE)), 'scripts', 'review.py'))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_command_says_why_it_cannot_serve_and_prints_the_agreement(out, tmp_path, capsys):
    script = review_script()
    assert script.main(['--out', str(tmp_path / 'nothing')]) == 1
    assert 'no grade.json' in capsys.readouterr().err
    (out / 'review.json').write_text('[]')
    assert script.main(['--out', str(out), '--agreement']) == 1
    assert 'not a review of version 1' in capsys.readouterr().err
    (out / 'review.json').unlink()
    assert script.main(['--out', str(out), '--agreement']) == 0
    assert capsys.readouterr().out.splitlines()[1].startswith('Q4       0 decided')

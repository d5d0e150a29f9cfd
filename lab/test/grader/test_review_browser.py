"""make review in headless Chromium, as the teacher clicks it (issue 47 point 6), on what the grader
itself wrote: a class of four graded by the class run (``lab/scripts/grade.py``, what make grade runs),
their reports the fixtures of lab/test/unit/data/reports (made by lab/test/reports/make_reports.py with
LibreOffice and real screenshots): two students handed in the same report (one answer group), one a
report whose answer to question 5 is markup (hostile.pdf) and a package holding a file named as markup,
one only a report, in a table, without question 6. The proposals, passages, page images and code copies
are the grader's; what this test expects of them is read from its proposals.json, never typed here.

Then ``lab/scripts/review.py`` (what make review runs) is started on it. The browser opens the URL it
printed, confirms the largest answer group of Q4, changes one student's Q5 against its proposal with
a decimal comma, gives the report-only student a point for the question it did not answer, reloads:
hand.csv holds exactly those points (no proposal written unconfirmed), review.json each decision with
its proposal, the agreement says what changed. A request without the token is a 404, a Host of another
name a 403; the hostile passage and file name are shown as text, no script runs, nothing is logged.
Ctrl-C stops the server (killed if it does not, and the test fails); make rescore (a re-run's desk)
keeps every point, and a second review shows them.
"""
import csv
import http.client
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import threading

import pytest

from test_page_browser import CHROMIUM

HERE = os.path.dirname(os.path.realpath(__file__))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), 'reports'))
from cdp import Browser  # noqa: E402
from exam_lab.grader.publish import grades, hand  # noqa: E402
from exam_lab.grader.score.sheets import HAND_ITEMS  # noqa: E402
from exam_lab.harness.supervisor import DIES_WITH_PARENT  # noqa: E402
from make_reports import HOSTILE_LINES  # noqa: E402 (lab/test/reports: what hostile.pdf's answer holds)

LAB = os.path.dirname(os.path.dirname(HERE))
DATA = os.path.join(os.path.dirname(HERE), 'unit', 'data', 'reports')
GOOD = os.path.join(HERE, 'submissions', 'good_student', 'exam')
#: Generous: the machine is shared (test_report_class's window).
WINDOW = 1800
#: How long Ctrl-C may take to stop the server before it is killed (and the test fails).
STOP_WAIT = 60
SAME, ALSO_SAME, HOSTILE, REPORT_ONLY = 'Ann Good', 'Bea Same', 'Mallory Script', 'Zoe Report'
#: ``student: (the fixture report handed in, a package beside it)``.
CLASS = {SAME: ('fr_odt.pdf', True), ALSO_SAME: ('fr_odt.pdf', True), HOSTILE: ('hostile.pdf', True),
         REPORT_ONLY: ('en_docx_table.pdf', False)}
#: A file of the hostile student's package, named so that it would run a script if shown unescaped.
HOSTILE_FILE = '<img src=x onerror=alert(1)>.py'

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason='NO BROWSER: chromium is not installed '
                                '(tools/install_deps.sh installs it); the review page was not tested in a browser')


def graded_class(root):
    """CLASS, a Moodle folder each (participants 401...), graded by grade.py into ``root/out``."""
    klass = os.path.join(root, 'class')
    for number, (name, (report, package)) in enumerate(sorted(CLASS.items()), start=401):
        folder = os.path.join(klass, '%s_%d_assignsubmission_file_' % (name, number))
        os.makedirs(folder)
        shutil.copyfile(os.path.join(DATA, report), os.path.join(folder, report))
        if package:
            shutil.copytree(GOOD, os.path.join(folder, 'exam'), ignore=shutil.ignore_patterns('__pycache__'))
        if name == HOSTILE:
            with open(os.path.join(folder, 'exam', HOSTILE_FILE), 'w') as f:
                f.write(''.join('# %s\n' % line for line in HOSTILE_LINES))
    out = os.path.join(root, 'out')
    done = subprocess.run([sys.executable, os.path.join(LAB, 'scripts', 'grade.py'), '--class', klass, '--out', out,
                           '--jobs', '2'], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                          timeout=WINDOW)
    assert done.returncode == 0, done.stdout[-6000:]
    return out


def proposed(out, name):
    """``{item: proposal}`` of the student's proposals.json, as the grader wrote it."""
    with open(os.path.join(out, name, 'proposals.json')) as f:
        return {p['item']: p for p in json.load(f)}


class Review(object):
    """lab/scripts/review.py on OUT, as make review runs it; its URL from the line it prints. The server
    never outlives the test: stopped when its URL does not come, killed when a stop does not end it
    (:meth:`stop`, called in a ``finally``), and by the kernel if this process dies first (the
    supervisor's DIES_WITH_PARENT: a CI runner that kills the test)."""

    def __init__(self, out):
        self.process = subprocess.Popen(DIES_WITH_PARENT + [sys.executable, os.path.join(LAB, 'scripts', 'review.py'),
                                                            '--out', out],
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines = []
        found = threading.Event()

        def read():
            for line in self.process.stdout:
                self.lines.append(line)
                if 'http://127.0.0.1:' in line:
                    found.set()
            found.set()
        self.reader = threading.Thread(target=read, daemon=True)
        self.reader.start()
        try:
            assert found.wait(120), self.lines
            urls = [re.search(r'http://127\.0\.0\.1:(\d+)(/[^/\s]+)/', line) for line in self.lines]
            url = [u for u in urls if u]
            assert url, self.lines
        except BaseException:
            self.stop()
            raise
        self.url, self.port, self.base = url[0].group(0), int(url[0].group(1)), url[0].group(2)

    def get(self, path, host=None):
        connection = http.client.HTTPConnection('127.0.0.1', self.port, timeout=30)
        try:
            connection.request('GET', path, headers={'Host': host or '127.0.0.1:%d' % self.port})
            answer = connection.getresponse()
            return answer.status, answer.read().decode('utf-8', 'replace')
        finally:
            connection.close()

    def stop(self):
        """Ctrl-C: the exit status and what it printed; a server Ctrl-C did not stop within STOP_WAIT is
        killed, its status None."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            status = self.process.wait(STOP_WAIT)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
            status = None
        self.reader.join(30)
        return status, ''.join(self.lines)


@pytest.fixture(scope='module')
def review_out(tmp_path_factory):
    """The graded class's OUT and its grade records (the page's order)."""
    out = graded_class(str(tmp_path_factory.mktemp('review-class')))
    records = grades.records_in(out)
    assert sorted(r['student'] for r in records) == sorted(CLASS), [r['student'] for r in records]
    return out, records


@pytest.fixture
def browser(tmp_path):
    profile = str(tmp_path / 'chromium')
    os.makedirs(profile)
    opened = Browser(profile)
    try:
        opened.open()
        yield opened
    finally:
        opened.close()


def hand_cells(out):
    """``{student: {item: cell}}`` of hand.csv, the filled cells only."""
    with open(os.path.join(out, hand.FILE), newline='') as f:
        return {row['student']: {item: row[item] for item in HAND_ITEMS if row[item]}
                for row in csv.DictReader(f) if row['student'] != hand.MAX_ROW}


def page_text(browser, selector):
    return browser.evaluate('Array.prototype.map.call(document.querySelectorAll(%s), function (e) '
                            '{ return e.textContent; })' % json.dumps(selector))


def other_points(points):
    """A value to type over a proposal of ``points``, with a decimal comma: ``(typed, as hand.csv holds it)``."""
    return ('1,5', '1.5') if points != 1.5 else ('0,5', '0.5')


def test_the_review_page_as_a_teacher_clicks_it(review_out, browser):
    out, records = review_out
    names = [r['student'] for r in records]
    mine = {name: proposed(out, name) for name in names}
    # what the grader proposed, that the clicks below rest on
    q4 = mine[SAME]['Q4']
    assert q4['passage'] and q4['passage'] == mine[ALSO_SAME]['Q4']['passage'] and q4['points'] is not None, \
        (q4, mine[ALSO_SAME]['Q4'])
    assert mine[HOSTILE]['Q4']['state'] == 'no answer found', mine[HOSTILE]['Q4']
    assert mine[REPORT_ONLY]['Q4']['passage'] != q4['passage'], mine[REPORT_ONLY]['Q4']
    assert mine[REPORT_ONLY]['Q6']['state'] == 'no answer found', mine[REPORT_ONLY]['Q6']
    hostile_passage = mine[HOSTILE]['Q5']['passage']
    assert all(line in hostile_passage for line in HOSTILE_LINES), hostile_passage
    group_points = hand.points_cell(q4['points'])
    expected = [SAME, ALSO_SAME]
    changed, q5 = SAME, mine[SAME]['Q5']
    typed, written = other_points(q5['points'])

    review = Review(out)
    try:
        # nothing without the token; nothing for another name of this address
        for path in ('/', '/hand.csv', '/index.html', review.base + 'x/', '/..' + review.base + '/'):
            status, body = review.get(path)
            assert status == 404 and SAME not in body, path
        assert review.get(review.base + '/', host='attacker.example:%d' % review.port)[0] == 403
        refused = 'http://127.0.0.1:%d/' % review.port
        assert browser.go(refused) == 404

        since = len(browser.events)  # what the pages log from here: nothing (but the browser's own favicon.ico)
        assert browser.go(review.url) == 200
        listed = page_text(browser, '#students tbody tr td:first-child')
        assert listed == names  # every student, the report-only one too
        assert all(not cells for cells in hand_cells(out).values())  # proposals shown, none written

        # Q4: the largest group (the two who handed in the same report), confirmed once
        assert browser.click('a[href$="/item/Q4"]') == 200
        members = page_text(browser, '.group:first-of-type .members li a')
        assert sorted(members) == sorted(expected)
        assert browser.evaluate('document.querySelector(".group:first-of-type input[name=points]").value') == \
            group_points
        assert browser.click('.group:first-of-type button') == 200
        said = page_text(browser, '.said')
        assert said and ('Q4: %s given to %d student(s)' % (group_points, len(expected))) in said[0]

        # one student's Q5 changed against its proposal, with a decimal comma
        browser.go(review.url)
        assert browser.click('#students a[href$="/student/%d"]' % names.index(changed)) == 200
        assert browser.evaluate('document.querySelector("#points-Q5").value') == hand.points_cell(q5['points'])
        browser.type_into('#points-Q5', typed)
        assert browser.click('#save-Q5') == 200
        assert '%s Q5: %s written to hand.csv' % (changed, written) in page_text(browser, '.said')[0]
        assert browser.reload() == 200
        assert browser.evaluate('document.querySelector("#points-Q5").value') == written
        images = browser.evaluate('Array.prototype.map.call(document.images, function (i) '
                                  '{ return [i.complete, i.naturalWidth]; })')
        assert images and all(complete and width > 100 for complete, width in images), images

        # the report-only student, graded by hand like any other: the question its report does not answer
        browser.go(review.url)
        assert browser.click('#students a[href$="/student/%d"]' % names.index(REPORT_ONLY)) == 200
        assert browser.evaluate('document.querySelector("#points-Q6").value') == ''
        browser.type_into('#points-Q6', '0.5')
        assert browser.click('#save-Q6') == 200

        # the hostile student: shown as text, nothing run
        browser.go(review.url)
        assert browser.click('#students a[href$="/student/%d"]' % names.index(HOSTILE)) == 200
        assert browser.evaluate('document.title').startswith(HOSTILE)
        assert browser.evaluate('[document.scripts.length, document.querySelectorAll("a[href^=file]").length, '
                                'document.querySelectorAll("img[src=x]").length]') == [0, 0, 0]
        shown = page_text(browser, '#item-Q5 .passage')[0]
        assert all(line in shown for line in HOSTILE_LINES), shown
        assert any(t.endswith(HOSTILE_FILE) for t in page_text(browser, 'h3 code')), page_text(browser, 'h3 code')
        # the refused page's own 404 may be logged late (events come as they come): that one is no page's
        logged = [line for line in browser.logged(since) if not line.endswith(('/favicon.ico', ' ' + refused))]
        assert logged == [], logged

        # what the teacher decided, and only that
        cells = hand_cells(out)
        decided = {n: {'Q4': group_points} for n in expected}
        decided[changed]['Q5'] = written
        decided[REPORT_ONLY] = {'Q6': '0.5'}
        assert {n: c for n, c in cells.items() if c} == decided
        with open(os.path.join(out, 'review.json')) as f:
            state = json.load(f)
        given_q5 = [e for e in state['cells'].values() if e['item'] == 'Q5']
        assert [(e['student'], e['proposed'], e['given'], e['state'], e['by']) for e in given_q5] == [
            (changed, q5['points'], float(written), q5['state'], 'student')]
        assert sorted(e['student'] for e in state['cells'].values() if e['item'] == 'Q4' and e['by'] == 'group') == \
            sorted(expected)
        browser.go(review.url)
        agreement = page_text(browser, '#agreement tbody tr')
        assert any(row.startswith('Q4%d%d0' % (len(expected), len(expected))) for row in agreement), agreement
        assert any(row.startswith('Q5101') for row in agreement), agreement
        assert 'Q61001' in agreement, agreement  # decided without a proposal (no answer found)
    finally:
        status, printed = review.stop()
    assert status == 0 and 'review stopped' in printed, printed

    lines = subprocess.run([sys.executable, os.path.join(LAB, 'scripts', 'review.py'), '--out', out, '--agreement'],
                           stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    assert '%s: proposed %s (%s), given %s' % (changed, hand.points_cell(q5['points']), q5['state'], written) in lines, \
        lines

    # a re-run's desk (make rescore) writes hand.csv again: every point kept; a second review shows them
    subprocess.run([sys.executable, os.path.join(LAB, 'scripts', 'rescore.py'), '--out', out],
                   stdout=subprocess.DEVNULL, check=True)
    assert hand_cells(out) == cells
    again = Review(out)
    try:
        assert browser.go(again.url) == 200
        column = 5 + list(HAND_ITEMS).index('Q6')  # student, participant, sheet, machine, report, then the items
        row = browser.evaluate('Array.prototype.map.call(document.querySelectorAll("#students tbody tr"), '
                               'function (r) { return r.cells[0].textContent + "|" + r.cells[%d].textContent + "|" + '
                               'r.cells[%d].className; })' % (column, column))
        assert '%s|0.5|given' % REPORT_ONLY in row, row
        assert browser.click('a[href$="/item/Q4"]') == 200
        assert browser.evaluate('document.querySelector(".group:first-of-type button").textContent') == 'Change'
        assert all(' %s in hand.csv' % group_points in line for line in page_text(browser, '.group:first-of-type .members li'))
    finally:
        status, printed = again.stop()
    assert status == 0, printed

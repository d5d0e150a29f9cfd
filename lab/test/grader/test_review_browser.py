"""make review in headless Chromium, as the teacher clicks it (issue 47 point 6): test_grade's main
class (conftest.py ``main_class``, graded by the grader) copied, one more student who handed in only a
report graded into it by the class run's own code, then ``lab/scripts/review.py`` (what make review runs)
started on it. The browser opens the URL it printed, confirms the largest answer group of Q4, changes
one student's Q5 against its proposal, gives the report-only student a point, reloads: hand.csv holds
exactly those points (no proposal written unconfirmed), review.json each decision with its proposal,
the agreement says what changed. A request without the token is a 404, a Host of another name a 403;
a student's hostile passage and file name are shown as text, no script runs, nothing is logged. Ctrl-C
stops the server; make rescore (a re-run's desk) keeps every point, and a second review shows them.

The report records, code copies and proposals are review_stand_ins.py's (standing for reader47's
and answers47's output until it is merged): the grades, hand.csv and the report-only student are
the grader's own.
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
sys.path.insert(0, os.path.join(os.path.dirname(HERE), 'unit'))
import review_stand_ins as stand_ins  # noqa: E402  (lab/test/unit: the unit tests' stand-ins too)
from cdp import Browser  # noqa: E402
from exam_lab.grader import class_run  # noqa: E402
from exam_lab.grader.publish import grades, hand  # noqa: E402
from exam_lab.grader.score.sheets import HAND_ITEMS  # noqa: E402
from exam_lab.harness.supervisor import DIES_WITH_PARENT  # noqa: E402

LAB = os.path.dirname(os.path.dirname(HERE))
SUBMISSIONS = os.path.join(HERE, 'submissions')
REPORT_ONLY = 'Zoe Report'
#: A passage that would run a script if the page did not escape it; a file name alike.
HOSTILE = ('<script>document.title="pwned"</script><img src=x onerror="document.title=\'pwned\'">'
           '<a href="file:///etc/passwd">x</a>')
HOSTILE_FILE = '<img src=x onerror=alert(1)>.py'
Q4 = '$ rosnode list\n/mydrone\n/rosout\n2 nœuds tournent : le drone et /rosout (journal de ROS).'

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason='NO BROWSER: chromium is not installed '
                                '(tools/install_deps.sh installs it); the review page was not tested in a browser')


def report_only_student(out, root):
    """A student whose folder holds only report.pdf (a real PDF), graded by the class run into ``out``."""
    import test_grade
    folder = os.path.join(root, '%s_190_assignsubmission_file_' % REPORT_ONLY)
    os.makedirs(folder)
    test_grade.two_page_pdf(os.path.join(folder, 'report.pdf'))
    return class_run.grade_student(REPORT_ONLY, folder, out)


def proposals(names):
    """The stand-in proposals: every other student wrote ``Q4`` (its case and pid aside), the report-only
    student too, so the largest group holds it; the others a shorter Q4; each a Q5 to check; the last
    student a hostile Q5."""
    p = stand_ins.proposal
    made = {}
    for index, name in enumerate(names):
        q4 = (Q4.upper() if index % 4 else Q4) + '\nPid: %d' % (4000 + index)
        mine = [p('Q4', 1.0, 'proposed', q4) if index % 2 == 0 or name == REPORT_ONLY else
                p('Q4', 0.5, 'proposed', '$ rosnode list\n/mydrone\n/rosout'),
                p('Q5', 1.0, 'to check', HOSTILE if index == len(names) - 1 else 'rosnode info /mydrone\n%s' % name,
                  checks=[('Pid explained', False, 'no sentence on Pid')]),
                p('Q6', None, 'no answer found')]
        if name != REPORT_ONLY:
            mine += [p('comments', 2.0, 'to check', evidence='scripts/exam_node.py: 8 of 12 functions commented'),
                     p('quality', 2.0, 'to check', evidence='pyflakes: nothing')]
        made[name] = mine
    return made


def codes(records):
    """Each student's package as the reader keeps it: the fixture package it was made from."""
    found = {}
    for record in records:
        source = os.path.join(SUBMISSIONS, record['student'], 'exam')
        if os.path.isdir(source):
            found[record['student']] = source
    return found


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
        """Ctrl-C: the exit status and what it printed; a server that Ctrl-C did not end within 60 s is
        killed (its status then says so: -9)."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            status = self.process.wait(60)
        except subprocess.TimeoutExpired:
            self.process.kill()
            status = self.process.wait()
        self.reader.join(30)
        return status, ''.join(self.lines)


@pytest.fixture
def review_out(main_class, tmp_path):
    out = str(tmp_path / 'out')
    shutil.copytree(main_class['out'], out, symlinks=True)
    report_only_student(out, str(tmp_path / 'class'))
    records = grades.records_in(out)
    hand.write(os.path.join(out, hand.FILE), records)  # as make grade's desk: its row too
    names = [r['student'] for r in records]
    assert REPORT_ONLY in names
    stand_ins.write(out, proposals(names), code=codes(records))
    hostile = names[-1] if names[-1] != REPORT_ONLY else names[-2]
    code = os.path.join(out, hostile, 'code')
    if os.path.isdir(code):
        os.chmod(code, 0o755)
        with open(os.path.join(code, HOSTILE_FILE), 'w') as f:
            f.write('# %s\n' % HOSTILE)
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


def test_the_review_page_as_a_teacher_clicks_it(review_out, browser):
    out, records = review_out
    names = [r['student'] for r in records]
    sheets = {r['student']: r.get('sheet') for r in records}
    changed = [n for n in names if n != REPORT_ONLY][0]
    review = Review(out)
    try:
        # nothing without the token; nothing for another name of this address
        for path in ('/', '/hand.csv', '/index.html', review.base + 'x/', '/..' + review.base + '/'):
            status, body = review.get(path)
            assert status == 404 and 'good_student' not in body, path
        assert review.get(review.base + '/', host='attacker.example:%d' % review.port)[0] == 403
        assert browser.go('http://127.0.0.1:%d/' % review.port) == 404

        since = len(browser.events)  # what the pages log from here: nothing (but the browser's own favicon.ico)
        assert browser.go(review.url) == 200
        listed = page_text(browser, '#students tbody tr td:first-child')
        assert listed == names  # every student, the report-only one too
        assert all(not cells for cells in hand_cells(out).values())  # proposals shown, none written

        # Q4: the largest group, confirmed once
        assert browser.click('a[href$="/item/Q4"]') == 200
        members = page_text(browser, '.group:first-of-type .members li a')
        # one answer on one sheet (the depth sheet's students, wrong_topic, are a group of their own)
        expected = [n for i, n in enumerate(names) if (i % 2 == 0 or n == REPORT_ONLY) and sheets[n] == 'altitude']
        assert sorted(members) == sorted(expected)
        assert browser.evaluate('document.querySelector(".group:first-of-type input[name=points]").value') == '1'
        assert browser.click('.group:first-of-type button') == 200
        said = page_text(browser, '.said')
        assert said and ('Q4: 1 given to %d student(s)' % len(expected)) in said[0]

        # one student's Q5 changed against its proposal (1, to check), with a decimal comma
        browser.go(review.url)
        assert browser.click('#students a[href$="/student/%d"]' % names.index(changed)) == 200
        assert browser.evaluate('document.querySelector("#points-Q5").value') == '1'
        browser.type_into('#points-Q5', '1,5')
        assert browser.click('#save-Q5') == 200
        assert '%s Q5: 1.5 written to hand.csv' % changed in page_text(browser, '.said')[0]
        assert browser.reload() == 200
        assert browser.evaluate('document.querySelector("#points-Q5").value') == '1.5'
        images = browser.evaluate('Array.prototype.map.call(document.images, function (i) '
                                  '{ return [i.complete, i.naturalWidth]; })')
        assert images and all(complete and width > 100 for complete, width in images), images

        # the report-only student, graded by hand like any other
        browser.go(review.url)
        assert browser.click('#students a[href$="/student/%d"]' % names.index(REPORT_ONLY)) == 200
        browser.type_into('#points-Q6', '0.5')
        assert browser.click('#save-Q6') == 200

        # the hostile student: shown as text, nothing run
        hostile = names[-1] if names[-1] != REPORT_ONLY else names[-2]
        browser.go(review.url)
        browser.click('#students a[href$="/student/%d"]' % names.index(hostile))
        assert browser.evaluate('document.title').startswith(hostile)
        assert browser.evaluate('[document.scripts.length, document.querySelectorAll("a[href^=file]").length, '
                                'document.querySelectorAll("img[src=x]").length]') == [0, 0, 0]
        assert HOSTILE in page_text(browser, '#item-Q5 .passage')[0]
        if os.path.isdir(os.path.join(out, hostile, 'code')):
            assert any(HOSTILE_FILE in t for t in page_text(browser, 'h3 code'))
        logged = [line for line in browser.logged(since) if not line.endswith('/favicon.ico')]
        assert logged == [], logged

        # what the teacher decided, and only that
        cells = hand_cells(out)
        decided = {n: {'Q4': '1'} for n in expected}
        decided.setdefault(changed, {})['Q5'] = '1.5'
        decided[REPORT_ONLY]['Q6'] = '0.5'
        assert {n: c for n, c in cells.items() if c} == decided
        with open(os.path.join(out, 'review.json')) as f:
            state = json.load(f)
        q5 = [e for e in state['cells'].values() if e['item'] == 'Q5']
        assert [(e['student'], e['proposed'], e['given'], e['state'], e['by']) for e in q5] == [
            (changed, 1.0, 1.5, 'to check', 'student')]
        assert sorted(e['student'] for e in state['cells'].values() if e['item'] == 'Q4' and e['by'] == 'group') == \
            sorted(expected)
        browser.go(review.url)
        agreement = page_text(browser, '#agreement tbody tr')
        assert any(row.startswith('Q4%d%d0' % (len(expected), len(expected))) for row in agreement), agreement
        assert any(row.startswith('Q5101') for row in agreement), agreement
    finally:
        status, printed = review.stop()
    assert status == 0 and 'review stopped' in printed, printed

    lines = subprocess.run([sys.executable, os.path.join(LAB, 'scripts', 'review.py'), '--out', out, '--agreement'],
                           stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout
    assert '%s: proposed 1 (to check), given 1.5' % changed in lines, lines

    # a re-run's desk (make rescore) writes hand.csv again: every point kept; a second review shows them
    subprocess.run([sys.executable, os.path.join(LAB, 'scripts', 'rescore.py'), '--out', out],
                   stdout=subprocess.DEVNULL, check=True)
    assert hand_cells(out) == cells
    again = Review(out)
    try:
        assert browser.go(again.url) == 200
        row = browser.evaluate('Array.prototype.map.call(document.querySelectorAll("#students tbody tr"), '
                               'function (r) { return r.cells[0].textContent + "|" + r.cells[5].textContent + "|" + '
                               'r.cells[5].className; })')
        assert '%s|1|given' % REPORT_ONLY in row, row
        assert browser.click('a[href$="/item/Q4"]') == 200
        assert browser.evaluate('document.querySelector(".group:first-of-type button").textContent') == 'Change'
        assert all(' 1 in hand.csv' in line for line in page_text(browser, '.group:first-of-type .members li'))
    finally:
        status, printed = again.stop()
    assert status == 0, printed

"""The teacher's page in a real browser: test_grade's main class, graded once a session with its desk
written (plots, similarity, page, feedback zip: conftest.py ``main_class``), then OUT/index.html opened
by headless Chromium from the file system: no console message, one table row per student, every
flight plot an image that loaded, the table sorts, the screenshot is a picture of the page. Then the
students' pages of OUT/moodle-feedback.zip, and docs/feedback_example.html, the same way: nothing
loaded or logged, the plot drawn, the threshold run's value in none.

Chromium is installed by tools/install_deps.sh (Debian's ``chromium``); without it the test is
skipped, saying so. GRADER_PAGE_SCREENSHOT=docs/figures/grader_page.png retakes the class page's figure,
tagged by lab/report/screenshots.py (the example feedback page's figure is lab/report/grading_examples.py's).
"""
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile

import pytest

from exam_lab.grader.publish import feedback

HERE = os.path.dirname(os.path.realpath(__file__))
DOCS = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(HERE))), 'docs')
sys.path.insert(0, os.path.join(os.path.dirname(DOCS), 'lab', 'report'))

import screenshots  # noqa: E402  (lab/report is a script folder, not a package)

CHROMIUM = screenshots.chromium()
#: The two students whose feedback pages are opened: the good student (its report.pdf of two pages)
#: and one who lost points.
STUDENTS = ('good_student', 'no_kelvin')
#: Appended to a copy of the page: after load, what the browser made of it, into the DOM it dumps.
CHECK = """<script>
window.addEventListener('load', function () {
  var images = Array.prototype.map.call(document.images, function (img) {
    return [img.getAttribute('src'), img.complete, img.naturalWidth, img.naturalHeight];
  });
  var table = document.querySelector('table.scores');
  var names = function () {
    return Array.prototype.map.call(table.tBodies[0].rows, function (row) { return row.cells[0].textContent; });
  };
  var headers = Array.prototype.slice.call(table.tHead.rows[0].cells);
  var total = headers[headers.length - 1];
  total.click();
  var down = names();
  total.click();
  var up = names();
  document.body.setAttribute('data-check', JSON.stringify(
    {images: images, rows: table.tBodies[0].rows.length, down: down, up: up}));
});
</script>"""

pytestmark = pytest.mark.skipif(CHROMIUM is None, reason='NO BROWSER: chromium is not installed '
                                '(tools/install_deps.sh installs it); the page was not tested in a browser')


@pytest.fixture
def graded(main_class):
    """``(OUT, [records], the desk's lines)`` of the main class."""
    return main_class['out'], main_class['records'], main_class['lines']


def feedback_folder(record):
    """The student's folder in the feedback zip, by Moodle's rule (its full name and participant number)."""
    number = record['participant']
    return feedback.folder_name(feedback.moodle_name(record, number), number)


def chromium(args, page, timeout=120):
    """Run headless Chromium on ``page``; return (stdout, the console messages it logged)."""
    done = subprocess.run([CHROMIUM, '--headless', '--no-sandbox', '--disable-gpu', '--no-first-run',
                           '--enable-logging=stderr', '--v=0', '--virtual-time-budget=10000',
                           '--user-data-dir=%s' % os.path.join(os.path.dirname(page), '.chromium')] + args +
                          ['file://' + page], stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout)
    console = [l for l in done.stderr.decode('utf-8', 'replace').splitlines() if ':CONSOLE' in l]
    return done.stdout.decode('utf-8', 'replace'), console


def test_console_messages_are_captured(tmp_path):
    """The capture the next test relies on: a page that logs an error is seen to."""
    page = tmp_path / 'bad.html'
    page.write_text('<!DOCTYPE html><html><body><script>console.error("broken page")</script></body></html>')
    _, console = chromium(['--dump-dom'], str(page))
    assert any('broken page' in line for line in console), console


def test_the_page_in_a_browser(graded):
    out, records, lines = graded
    with open(os.path.join(out, 'index.html')) as f:
        text = f.read()
    check = os.path.join(out, 'check.html')
    with open(check, 'w') as f:
        f.write(text.replace('</body>', CHECK + '</body>'))
    dom, console = chromium(['--dump-dom'], check)
    assert console == []
    _, console = chromium(['--dump-dom'], os.path.join(out, 'index.html'))
    assert console == [], 'the page itself logs: %s' % console
    found = re.search(r'data-check="([^"]*)"', dom)
    assert found, dom[-2000:]
    got = json.loads(found.group(1).replace('&quot;', '"').replace('&amp;', '&'))
    assert got['rows'] == len(records)
    plotted = [r['student'] for r in records if os.path.isfile(os.path.join(out, r['student'], 'flight.png'))]
    assert set(STUDENTS) <= set(plotted)
    assert len(got['images']) == len(plotted)
    for src, complete, width, height in got['images']:
        assert complete and width > 0 and height > 0, (src, width, height)
        if src.split('/')[0] in STUDENTS:  # a flight drawn (a student that never flew has a notice)
            assert width > 600 and height > 400, (src, width, height)
    totals = {r['student']: r['total'] for r in records}
    assert [totals[n] for n in got['down']] == sorted(totals.values(), reverse=True)
    assert [totals[n] for n in got['up']] == sorted(totals.values())
    assert 'report.pdf (2 pages)' in text
    assert any(l.startswith('similarity:') for l in lines)


def test_a_screenshot_of_the_page(graded, tmp_path):
    out, _, _ = graded
    shot = str(tmp_path / 'page.png')
    chromium(['--hide-scrollbars', '--window-size=1280,2300', '--screenshot=%s' % shot],
             os.path.join(out, 'index.html'))
    with open(shot, 'rb') as f:
        head = f.read(24)
    assert head[:8] == b'\x89PNG\r\n\x1a\n'
    assert (int.from_bytes(head[16:20], 'big'), int.from_bytes(head[20:24], 'big')) == (1280, 2300)
    assert os.path.getsize(shot) > 50000  # a page with plots, not a blank one
    if os.environ.get('GRADER_PAGE_SCREENSHOT'):
        screenshots.take(os.path.join(out, 'index.html'), os.environ['GRADER_PAGE_SCREENSHOT'], (1280, 2300),
                         screenshots.page_code_digest())


#: Appended to a copy of a feedback page without its Content-Security-Policy (which lets no script run):
#: what the browser drew, into the DOM it dumps.
FEEDBACK_CHECK = """<script>
window.addEventListener('load', function () {
  var svg = document.querySelector('svg.plot'), box = svg ? svg.getBoundingClientRect() : null;
  document.body.setAttribute('data-check', JSON.stringify({
    plot: box ? [box.width, box.height] : null, texts: svg ? svg.querySelectorAll('text').length : 0,
    rows: document.querySelectorAll('table.items tbody tr').length}));
});
</script>"""


def open_feedback(path):
    """A feedback page in Chromium: ``(what it drew, the console messages)``. The page itself is opened
    as it is (a load its policy blocked would be logged), then a copy with the check."""
    with open(path) as f:
        text = f.read()
    _, console = chromium(['--dump-dom'], path)
    check = path + '.check.html'
    with open(check, 'w') as f:
        f.write(re.sub(r'<meta http-equiv="Content-Security-Policy"[^>]*>', '', text).replace(
            '</body>', FEEDBACK_CHECK + '</body>'))
    dom, more = chromium(['--dump-dom'], check)
    found = re.search(r'data-check="([^"]*)"', dom)
    assert found, dom[-2000:]
    return json.loads(found.group(1).replace('&quot;', '"').replace('&amp;', '&')), console + more


def test_the_students_feedback_pages_in_a_browser(graded, tmp_path):
    out, records, lines = graded
    by_name = {r['student']: r for r in records}
    folders = [feedback_folder(by_name[name]) for name in STUDENTS]
    with zipfile.ZipFile(os.path.join(out, feedback.FILE)) as archive:  # the desk's, with the setting shipped
        names = archive.namelist()
        shipped = {name.split('/')[0]: archive.read(name).decode('utf-8') for name in names}
    assert all(f + '/' + feedback.PAGE in names for f in folders), names
    assert all(name.endswith('_assignfeedback_file_/' + feedback.PAGE) for name in names), names
    assert any(l.startswith('moodle feedback: %s: a page for %d student(s)' % (os.path.join(out, feedback.FILE),
                                                                              len(names))) for l in lines)
    # Every student has a page or is named among those left out (a grade the teacher must look at).
    left = [l for l in lines if l.startswith('moodle feedback: ') and ' left out ' in l]
    assert len(names) + (int(left[0].split(': ')[1].split()[0]) if left else 0) == len(records), lines
    with open(os.path.join(out, STUDENTS[0], 'logs', 'plan-threshold.json')) as f:
        hidden = '%g' % json.load(f)['threshold']
    number = re.compile(r'(?<![\w.])%s(?:\.0+)?(?![\d])' % re.escape(hidden))
    assert number.search(json.dumps(by_name[STUDENTS[0]]))  # the teacher's record names it
    feedback.write(out, records, show='points')
    with zipfile.ZipFile(os.path.join(out, feedback.FILE)) as archive:
        points = {name.split('/')[0]: archive.read(name).decode('utf-8') for name in archive.namelist()}
    if feedback.read_show() == 'points':
        assert points == shipped
    feedback.write(out, records, show='evidence')
    with zipfile.ZipFile(os.path.join(out, feedback.FILE)) as archive:
        evidence = {name.split('/')[0]: archive.read(name).decode('utf-8') for name in archive.namelist()}
    for folder in folders:
        assert not number.search(points[folder]), folder
        assert '<svg' not in points[folder] and '<svg' in evidence[folder]
        # Q11's evidence names the main run's readings, one of which the threshold run took as its value
        # (the rest leg's): make check shows the same line; nowhere else is the value.
        shown = re.sub(r'<tr[^>]*><td>Q11</td>.*?</tr>', '', evidence[folder])
        assert not number.search(shown), folder
        assert 'threshold run (lowered' not in evidence[folder] and 'threshold run' not in shown.replace(
            'a problem in the threshold run', '')
        for show, text in (('points', points[folder]), ('evidence', evidence[folder])):
            page = str(tmp_path / ('%s-%s.html' % (folder.split('_')[0], show)))
            with open(page, 'w') as f:
                f.write(text)
            drawn, console = open_feedback(page)
            assert console == [], console
            assert drawn['rows'] == 7
            if show == 'evidence':
                assert drawn['plot'][0] > 500 and drawn['plot'][1] > 150 and drawn['texts'] > 10, drawn
            else:
                assert drawn['plot'] is None


def test_the_docs_example_feedback_page_in_a_browser(tmp_path):
    """docs/feedback_example.html (lab/report/grading_examples.py) opens offline, draws its plot, and its
    folder is the one docs/grading.md names."""
    page = str(tmp_path / 'feedback.html')
    shutil.copyfile(os.path.join(DOCS, 'feedback_example.html'), page)
    drawn, console = open_feedback(page)
    assert console == [], console
    assert drawn['rows'] == 7 and drawn['plot'][0] > 500 and drawn['plot'][1] > 150, drawn
    with open(os.path.join(DOCS, 'grading.md')) as f:
        assert 'Paul Martin_102_assignfeedback_file_/feedback.html' in f.read()
    shot = str(tmp_path / 'feedback.png')
    chromium(['--hide-scrollbars', '--window-size=1000,1750', '--screenshot=%s' % shot], page)
    with open(shot, 'rb') as f:
        head = f.read(24)
    assert head[:8] == b'\x89PNG\r\n\x1a\n' and os.path.getsize(shot) > 30000

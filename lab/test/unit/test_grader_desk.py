"""The teacher's desk on synthetic records: Gradescope's results.json, the page (one row per student,
the ones needing the teacher first, every plot it names written), the flight plot, PDF page counts,
progress lines and time estimates, the probe's trace. No master, no browser (the browser test is
lab/test/grader/test_page_browser.py)."""
import csv
import io
import json
import os
import re
from html.parser import HTMLParser

import pytest

from exam_lab.grader.boxed import documents

from exam_lab.grader.publish import desk, flightplot, gradescope, hand, moodle, page, progress, report
from exam_lab.grader.score.records import SimilarityRecord
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS
from test_grader_probe_record import keep_runs

T0 = 1000.0


def record(student, lost=None, status='graded', reason='', participant=None):
    lost = lost or {}
    items = [{'id': i, 'points': top - lost.get(i, 0.0), 'max': top,
              'evidence': 'why %s <lost> "x"' % i if lost.get(i) else 'ok'} for i, (top, _) in ITEMS.items()]
    return dict(report.grade_record(student, 'altitude', items, ['hint'], {'seconds': 40.0, 'participant': participant}),
                status=status, status_reason=reason)


def probe_result(kind='main'):
    """A probe result as the probe writes one: schedule, calls, trace."""
    if kind == 'main':
        schedule = {'rest': T0 + 5, 'short_up': T0 + 8, 'short_down': T0 + 11, 'long_up': T0 + 13.5,
                    'long_down': T0 + 21, 'end': T0 + 23.5}
        calls = [[T0 + 18.5, 'WARNING'], [T0 + 21.0, 'NORMAL']]
    else:
        schedule = {'start': T0 + 1, 'step': T0 + 4, 'end': T0 + 11.5}
        calls = [[T0 + 9.0, 'WARNING']]
    oracle = [[t, 1430.0 if k.endswith('up') or k == 'step' else 1170.0] for k, t in sorted(schedule.items())
              if k != 'end']
    published = [[T0 + 1 + 0.1 * i, 1300.0 + 100 * ((i // 30) % 2)] for i in range(220)]
    return {'kind': kind, 'sheet': 'altitude', 'threshold': 1300.0, 't0': T0, 'schedule': schedule,
            'calls': calls, 'trace': {'published': published, 'oracle': oracle}}


class Collector(HTMLParser):
    """The page's elements; every tag must close in order (a browser would forgive it, we do not)."""
    VOID = ('meta', 'img', 'br', 'input')

    def __init__(self):
        HTMLParser.__init__(self)
        self.stack, self.rows, self.images, self.ids, self.links = [], 0, [], [], []
        self.table = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag not in self.VOID:
            self.stack.append(tag)
        if tag == 'table':
            self.table = attrs.get('class')
        if tag == 'tr' and 'tbody' in self.stack and self.table == 'scores':
            self.rows += 1
        if tag == 'img':
            self.images.append(attrs['src'])
        if 'id' in attrs:
            self.ids.append(attrs['id'])
        if tag == 'a' and attrs.get('href', '').startswith('#'):
            self.links.append(attrs['href'][1:])

    def handle_startendtag(self, tag, attrs):
        self.handle_starttag(tag, attrs)
        if tag not in self.VOID:
            self.stack.pop()

    def handle_endtag(self, tag):
        assert self.stack and self.stack[-1] == tag, (tag, self.stack[-5:])
        self.stack.pop()


def parsed(text):
    collector = Collector()
    collector.feed(text)
    collector.close()
    assert collector.stack == [], collector.stack
    return collector


def test_gradescope_results_follow_the_schema():
    got = gradescope.results(record('Jane', {'Q11': 1.5}))
    assert got['score'] == 15.5
    assert [t['name'].split(':')[0] for t in got['tests']] == list(ITEMS)
    q11 = got['tests'][2]
    assert (q11['score'], q11['max_score'], q11['status']) == (2.5, 4.0, 'failed')
    assert q11['output'].startswith('why Q11')
    assert set(got['tests'][0]) >= {'name', 'score', 'max_score', 'output'}
    assert 'visibility' not in got
    held = gradescope.results(record('Bob', {'runs': 2}, status='not graded', reason='crash'))
    assert held['visibility'] == 'hidden' and 'crash' in held['output']


def test_page_has_one_row_per_student_and_the_teacher_first(tmp_path):
    records = [record('Jane Doe', participant=101), record('Paul <Martin>', {'Q11': 1.5}, participant=102),
               record('Ada', {'runs': 2, 'Q10': 2}, status='not graded', reason='the build failed'),
               record('Bob', {'Q13': 2}, status='needs a hand grade', reason='odd design')]
    entries = {'Jane Doe': {'plot': 'Jane Doe/flight.png', 'grade_md': report.markdown(records[0]),
                            'folder': 'Jane Doe', 'documents': [{'name': 'report.pdf', 'pages': 3}]}}
    pairs = [{'a': 'Jane Doe', 'b': 'Bob', 'score_a': 0.9, 'score_b': 0.8,
              'files': [{'file_a': 'scripts/n.py', 'file_b': 'scripts/m.py', 'sim_a': 0.9, 'sim_b': 0.8,
                         'html_a': "<span class='highlight-red'>x = 1</span>", 'html_b': 'y'}]}]
    text = page.render(records, 'Class', entries, SimilarityRecord.make({'pairs': pairs, 'notes': []}),
                       ['worksheet: 2 grades'])
    got = parsed(text)
    assert got.rows == 4
    assert got.images == ['Jane Doe/flight.png']
    for target in got.links:
        assert target in got.ids, target
    first = text[text.index('id="first"'):text.index('id="histogram"')]
    assert 'Ada' in first and 'Bob' in first and 'Jane Doe' not in first
    assert 'Paul &lt;Martin&gt;' in text and 'Paul <Martin>' not in text
    assert 'report.pdf (3 pages)' in text
    assert 'Jane Doe and Bob: 90 % / 80 % alike' in text
    assert 'http' not in text.replace('http://www.w3.org/2000/svg', '')  # no network
    assert text.count('<rect ') == 18  # the histogram: one bar per point, 0 to 17


def test_the_page_lists_the_students_a_note_names_under_it():
    """"moodle feedback: 2 student(s) left out ...:" and its indented lines, as on the terminal."""
    notes = ['worksheet: 2 grades', 'moodle feedback: 2 student(s) left out (the teacher must still look at them):',
             '  Ada: status "not graded"', '  Bob <x>: status "needs a hand grade"', 'similarity: 3 pairs', '  odd']
    text = page.render([record('Ada')], 'Class', {}, None, notes)
    section = text[text.index('id="notes"'):text.index('id="histogram"')]
    assert ('<li>moodle feedback: 2 student(s) left out (the teacher must still look at them):<ul>'
            '<li>Ada: status &quot;not graded&quot;</li><li>Bob &lt;x&gt;: status &quot;needs a hand grade&quot;</li>'
            '</ul></li>') in section.replace('&#x27;', "'")
    assert '<li>similarity: 3 pairs</li><li>odd</li>' in section  # under a line that names no list: its own item


def test_markdown_of_a_grade_renders_its_table():
    html = page.markdown_html(report.markdown(record('Jane', {'Q11': 1.5})))
    assert html.count('<tr>') == 1 + len(ITEMS) + 1  # header, items, total
    assert '<strong>15.5 / 17</strong>' in html
    assert 'why Q11 &lt;lost&gt; &quot;x&quot;' in html
    parsed('<div>%s</div>' % html)


def test_flight_plot_is_a_png_of_both_runs(tmp_path):
    path = str(tmp_path / 'flight.png')
    assert flightplot.draw([('main', probe_result()), ('threshold', probe_result('threshold'))], path, 'Jane')
    with open(path, 'rb') as f:
        head = f.read(24)
    assert head[:8] == b'\x89PNG\r\n\x1a\n'
    width, height = int.from_bytes(head[16:20], 'big'), int.from_bytes(head[20:24], 'big')
    assert width > 600 and height > 2 * 200
    assert not flightplot.draw([('main', {'calls': [], 'trace': {}})], str(tmp_path / 'none.png'))
    assert not os.path.exists(str(tmp_path / 'none.png'))


def test_legs_of_a_schedule():
    got = flightplot.legs(probe_result()['schedule'])
    assert [(n, s - T0, e - T0, side) for n, s, e, side in got] == [
        ('rest', 5, 8, 'below'), ('short_up', 8, 11, 'above'), ('short_down', 11, 13.5, 'below'),
        ('long_up', 13.5, 21, 'above'), ('long_down', 21, 23.5, 'below')]


def test_finish_writes_the_desk_for_a_class(tmp_path):
    out = str(tmp_path)
    records = [record('Jane Doe', participant=101), record('Paul', {'Q11': 1.5}, participant=102)]
    for r in records:
        keep_runs(os.path.join(out, r['student']), [('main', probe_result())])
        report.write_grade(os.path.join(out, r['student']), r)
    worksheet = tmp_path / 'ws.csv'
    worksheet.write_text('\ufeffIdentifier,Full name,Grade,Maximum grade,Last modified (grade),Feedback comments\n'
                         '"Participant 101","Jane Doe",,17.00,-,\n', encoding='utf-8')
    lines = desk.finish(out, records, similar=SimilarityRecord.make({'pairs': [], 'students': 2, 'notes': []}), worksheet=str(worksheet))
    # No hand point given yet: no file to upload (the machine's points alone are no grade).
    assert any("no whole grade yet, so no moodle-worksheet.csv to upload" in l for l in lines), lines
    assert not os.path.exists(os.path.join(out, moodle.UPLOAD))
    assert any('NOT MATCHED: Paul' in l for l in lines)
    for r in records:
        assert os.path.isfile(os.path.join(out, r['student'], 'flight.png'))
        with open(os.path.join(out, r['student'], 'results.json')) as f:
            assert json.load(f)['score'] == r['total']
    with open(os.path.join(out, 'index.html')) as f:
        got = parsed(f.read())
    assert got.images == ['Jane Doe/flight.png', 'Paul/flight.png']
    # hand.csv beside grades.csv, one empty row per student for the teacher's 13 points.
    assert any(l.startswith('hand points: %s' % os.path.join(out, 'hand.csv')) for l in lines)
    assert sorted((h.student, h.participant) for h in hand.read(os.path.join(out, 'hand.csv')).values()) == \
        [('Jane Doe', 101), ('Paul', 102)]
    assert '  none given yet: Jane Doe, Paul' in lines
    # The teacher gives Jane's points: a rescore (the desk again, no WORKSHEET=) fills the kept worksheet,
    # asks for no point already given, and ends with the commands to paste, OUT quoted.
    from test_grader_hand import fill
    fill(os.path.join(out, hand.FILE), {('Jane Doe', item): str(top) for item, (top, _) in HAND_ITEMS.items()})
    lines = desk.finish(out, records)
    assert any('1 whole grade(s)' in l and moodle.UPLOAD in l for l in lines), lines
    assert '  none given yet: Paul' in lines and not any('Jane Doe' in l and 'not given' in l for l in lines)
    with open(os.path.join(out, moodle.UPLOAD), encoding='utf-8-sig') as f:
        assert '"Participant 101","Jane Doe",17,17.00' in f.read()  # 30 of 30 on a worksheet out of 17
    with open(os.path.join(out, 'index.html')) as f:
        assert 'none given yet: Paul' in f.read()  # the page says whose hand points are missing
    commands = desk.next_commands(out, records)
    assert '  make worksheet OUT="%s"' % out in commands and any('make rescore OUT="%s"' % out in c for c in commands)


def test_the_plot_draws_the_kept_measurements_never_a_file_in_the_logs(tmp_path):
    """The flight plot reads the session's record in measurements.json: a probe-main.json in logs/ (a
    forged one, a stale one) is not what it draws; a run whose result was refused for its times is."""
    folder = str(tmp_path / 'Jane')
    os.makedirs(os.path.join(folder, 'logs'))
    with open(os.path.join(folder, 'logs', 'probe-main.json'), 'w') as f:
        json.dump(dict(probe_result(), threshold=999.0), f)
    assert flightplot.load_runs(folder) == []
    keep_runs(folder, [('main', probe_result())])
    runs = flightplot.load_runs(folder)
    assert [(tag, probe['threshold'], probe['calls']) for tag, probe in runs] == [
        ('main', 1300.0, probe_result()['calls'])]
    with open(os.path.join(folder, 'measurements.json')) as f:
        kept = json.load(f)
    kept['session']['runs'][0]['refused_probe'] = kept['session']['runs'][0].pop('probe')
    kept['session']['runs'][0]['probe'] = None
    with open(os.path.join(folder, 'measurements.json'), 'w') as f:
        json.dump(kept, f)
    assert [(tag, probe['threshold']) for tag, probe in flightplot.load_runs(folder)] == [('main', 1300.0)]


def test_the_page_shows_the_grade_record_it_was_given_not_grade_md_read_back(tmp_path):
    out = str(tmp_path)
    jane = record('Jane Doe', participant=101)
    report.write_grade(os.path.join(out, 'Jane Doe'), jane)
    with open(os.path.join(out, 'Jane Doe', 'grade.md'), 'w') as f:
        f.write('# Jane Doe\n\nSTALE words of an older grading\n')
    desk.finish(out, [jane])
    with open(os.path.join(out, 'index.html')) as f:
        text = f.read()
    assert 'STALE' not in text and 'what is checked' in text


def test_pdf_pages(tmp_path):
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt
    from matplotlib.backends.backend_pdf import PdfPages
    path = str(tmp_path / 'report.pdf')
    with PdfPages(path) as pdf:
        for _ in range(3):
            figure = plt.figure()
            pdf.savefig(figure)
            plt.close(figure)
    assert documents.pdf_pages(path) == 3
    (tmp_path / 'fake.pdf').write_bytes(b'not a pdf')
    assert documents.pdf_pages(str(tmp_path / 'fake.pdf')) is None
    found = documents.documents(str(tmp_path))
    assert found == [{'name': 'fake.pdf', 'pages': None}, {'name': 'report.pdf', 'pages': 3}]
    facts = documents.submission_facts(str(tmp_path))
    assert facts['participant'] is None and len(facts['documents']) == 2


class Clock(object):
    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_time_left_estimate():
    assert progress.estimate_left([], [], 4, 2) == pytest.approx(2 * 45.0)
    assert progress.estimate_left([40.0, 60.0], [10.0], 2, 2) == pytest.approx((2 * 50 + 40) / 2)
    # overdue: each student takes as long as the longest seen, a running one a tenth of that at least
    assert progress.estimate_left([50.0], [70.0], 0, 2) == pytest.approx(7.0)
    assert progress.estimate_left([50.0], [], 0, 2) == 0.0


def test_time_left_is_never_stuck_then_rising():
    """Issue 49: 5 students, 4 at a time, each 100 s: the estimate stayed at "about 16 s" while the
    first four outlasted the 45 s prior, then jumped up. Now, past the prior and before any is done,
    it is not given; once one is done it only falls as the class goes on."""
    shown = []
    for t in range(0, 300, 5):
        first = [min(t, 100.0)] * 4 if t < 100 else []
        done = [100.0] * 4 if t >= 100 else []
        running = first if t < 100 else [t - 100.0]
        if t >= 200:
            done, running = done + [100.0], []
        waiting = 1 if t < 100 else 0
        shown.append((t, progress.estimate_left(done, running, waiting, 4)))
    before = [left for t, left in shown if t <= 45]
    assert before == sorted(before, reverse=True) and before[0] == pytest.approx(45 + 45 / 4.0)
    assert all(left is None for t, left in shown if 45 < t < 100)
    after = [left for t, left in shown if t >= 100]
    assert after == sorted(after, reverse=True) and after[0] == pytest.approx(100.0) and after[-1] == 0.0
    line = progress.ClassProgress(4, io.StringIO(), live=False, clock=lambda: 60.0)
    line.total, line.running = 5, {'Jane': [0.0, 'main flight']}
    assert line.line().endswith('time left known when the first student is done')


def test_class_progress_on_a_terminal_and_off():
    clock, stream = Clock(), io.StringIO()
    shown = progress.ClassProgress(2, stream, live=True, clock=clock)
    shown.total = 3  # begin() without its redraw thread
    shown.started('Jane')
    clock.now = 12.0
    shown.step('Jane', 'main flight')
    assert shown.line() == '[0 of 3 graded] now: Jane (main flight, 12 s); about 1 min 02 s left'
    shown.finished(dict(record('Jane'), seconds=40.0))
    shown.close()
    text = stream.getvalue()
    assert 'graded Jane: 17.0/17.0, graded (40 s)\n' in text and '\r\x1b[K' in text
    quiet = io.StringIO()
    off = progress.ClassProgress(2, quiet, live=False, clock=clock)
    off.begin(['Jane'])
    off.started('Jane')
    off.step('Jane', 'build')
    off.finished(dict(record('Jane'), seconds=40.0))
    off.close()
    assert quiet.getvalue() == 'graded Jane: 17.0/17.0, graded (40 s)\n'


def test_steps_seen_in_the_log_folder(tmp_path):
    seen = []
    with progress.watching(str(tmp_path), seen.append):
        (tmp_path / 'build.log').write_text('')
        (tmp_path / 'plan-main.json').write_text('{}')
        from exam_lab.harness.wait import wait_until
        assert wait_until(lambda: len(seen) == 2, 10.0, period=0.05)
    assert seen == ['build', 'main flight']
    stream = io.StringIO()
    steps = progress.StepProgress(stream, live=True, clock=Clock())
    steps('unpack')
    assert stream.getvalue() == '   0.0 s  unpack\n'
    off = io.StringIO()
    progress.StepProgress(off, live=False)('unpack')
    assert off.getvalue() == ''


def test_the_probe_trace_is_compact():
    from exam_lab.grader.judge import legs
    samples = [(T0 + 0.01 * i, float(i)) for i in range(1000)] + [(T0 + 11.0, float('nan'))]
    got = legs.trace(samples, [[T0, 1170.0], [T0 + 3.0, 1430.123456]])
    assert 100 <= len(got['published']) <= 112
    assert got['published'][-1] == [T0 + 11.0, None]
    assert got['oracle'][1] == [T0 + 3.0, 1430.123]
    json.dumps(got, allow_nan=False)


def crafted_pdf(path, size=4 << 20):
    """A PDF made to stop a backtracking reader: a page tree node that never closes, repeated, then
    ``stream`` lines with nothing to inflate; its real page tree (7 pages) is in an object stream."""
    import zlib
    half = size // 2
    unclosed = b'<< /Type /Pages ' + b'/Type /Pages /Count 1 ' * (half // 22)
    streams = b'stream\n' * (half // 7)
    real = b'1 0 obj\n<< /Type /ObjStm /Filter /FlateDecode >>\nstream\n' \
        + zlib.compress(b'<< /Type /Pages /Kids [3 0 R] /Count 7 >>') + b'\nendstream\n'
    with open(path, 'wb') as f:
        f.write(b'%PDF-1.5\n' + real + unclosed + b'\n' + streams)


def test_pdf_pages_in_linear_time(tmp_path):
    """A crafted report of a few MB is read in linear time (a backtracking regular expression took 76 s on
    325 KB, hours on 5 MB; the linear reader takes about 0.1 s). The bound is on the child's CPU time, 20
    times the linear reader's, which a busy machine does not stretch; in a child process, so that a
    regression fails, never hangs."""
    import subprocess
    import sys
    path = str(tmp_path / 'crafted.pdf')
    crafted_pdf(path)
    assert os.path.getsize(path) > 3 << 20
    code = ('import sys, time\nfrom exam_lab.grader.boxed import documents\nstarted = time.process_time()\n'
            'pages = documents.pdf_pages(sys.argv[1])\nprint(pages, time.process_time() - started)\n')
    try:
        out = subprocess.run([sys.executable, '-c', code, path], stdout=subprocess.PIPE, timeout=120, check=True)
    except subprocess.TimeoutExpired:
        pytest.fail('pdf_pages took over 120 s on a 4 MB PDF')
    pages, seconds = out.stdout.decode().split()
    assert pages == '7' and float(seconds) < 2.0, out.stdout


def test_the_default_out_is_pasted_as_it_is():
    """Issue 49: Moodle's zip name gave a folder ending in .zip with spaces and parentheses, which every
    later OUT= needed quoted. The default has neither; any OUT is printed quoted as bash reads it back."""
    import subprocess
    name = moodle.out_name('/home/t/ROS-2026-Exam submarinedrone (groupe D)-915302.zip')
    assert name == 'ROS-2026-Exam_submarinedrone_groupe_D-915302'
    assert moodle.out_name('/x/Cours d\'été "ROS".tar.gz') == 'Cours_d_été_ROS'
    assert moodle.out_name('/x/class/') == 'class'
    for out in ('/tmp/a b (c)', '/tmp/x"y$z`w\\v', '/tmp/plain'):
        said = subprocess.run(['bash', '-c', 'printf %s ' + moodle.shell_quoted(out)], stdout=subprocess.PIPE)
        assert said.stdout.decode() == out


def test_a_report_only_student_has_the_class_sheet_and_counts_in_no_statistic(tmp_path):
    """Issue 49 point 3: a student who handed in only a report (not graded: no package; the runner's
    default sheet, altitude) is listed with the class's sheet, counted in neither the mean nor the
    histogram, and her hand points make her grade in the worksheet."""
    out = str(tmp_path)
    depth = [dict(record(name, participant=number), sheet='depth') for name, number in (('Ann', 1), ('Bob', 2))]
    report_only = record('Cleo', status='not graded', participant=3,
                         reason='submission refused: no catkin package (package.xml) in Cleo_3 (seen: report.pdf)')
    report_only['items'] = [dict(e, points=0.0) for e in report_only['items']]
    report_only['total'] = 0.0
    records = depth + [report_only]
    for r in records:
        report.write_grade(os.path.join(out, r['student']), r)
    report.write_csv(os.path.join(out, 'grades.csv'), records)
    worksheet = tmp_path / 'ws.csv'
    worksheet.write_text('\ufeffIdentifier,Full name,Grade,Maximum grade,Last modified (grade),Feedback comments\n'
                         + ''.join('"Participant %d",%s,,20.00,-,\n' % (n, s) for s, n in (('Ann', 1), ('Bob', 2), ('Cleo', 3))),
                         encoding='utf-8')
    desk.finish(out, records, worksheet=str(worksheet))
    assert {h.student: h for h in hand.read(os.path.join(out, hand.FILE)).values()}
    with open(os.path.join(out, hand.FILE), encoding='utf-8') as f:
        assert [row['sheet'] for row in csv.DictReader(f) if row['student'] == 'Cleo'] == ['depth']
    with open(os.path.join(out, 'grades.csv'), encoding='utf-8') as f:
        assert [row['sheet'] for row in csv.DictReader(f) if row['student'] == 'Cleo'] == ['depth']
    with open(os.path.join(out, 'index.html')) as f:
        text = f.read()
    assert 'mean 17.0 / 17 over the 2 whose package ran; 1 not graded' in text
    histogram = text[text.index('<svg'):text.index('</svg>')]
    assert '<title>0 point(s): 0 student(s)</title>' in histogram and '<title>17 point(s): 2 student(s)</title>' in histogram
    from test_grader_hand import fill
    fill(os.path.join(out, hand.FILE), {('Cleo', item): str(top) for item, (top, _) in HAND_ITEMS.items()})
    lines = desk.finish(out, records)
    assert any('1 whole grade(s)' in l for l in lines), lines
    with open(os.path.join(out, moodle.UPLOAD), encoding='utf-8-sig') as f:
        cleo = [row for row in csv.DictReader(f) if row['Full name'] == 'Cleo'][0]
    assert cleo['Grade'] == '8.67'  # 0 + 13 of 30, out of 20
    assert 'nothing of the package ran: submission refused' in cleo['Feedback comments']



def test_a_report_only_student_has_the_sheet_her_report_is_about(tmp_path):
    """Issue 47: a report-only student in a class whose packages ran on the depth sheet, her report
    (LibreOffice's, of the aerial drone) naming /temperature, /pressure, mydrone: her sheet is the one
    her report answers, in hand.csv, grades.csv and her proposals (checked against the aerial drone's
    outputs), and her notes say how; one whose report names no sheet gets the class's."""
    import shutil
    out = str(tmp_path)
    data = os.path.join(os.path.dirname(__file__), 'data')
    depth = [dict(record(name, participant=number), sheet='depth') for name, number in (('Ann', 1), ('Bob', 2))]
    report_only = []
    for name, number in (('Cleo', 3), ('Dora', 4)):
        r = record(name, status='not graded', participant=number,
                   reason='submission refused: no catkin package (package.xml) in %s_%d (seen: report.pdf)' % (name, number))
        r['items'] = [dict(e, points=0.0) for e in r['items']]
        r['total'] = 0.0
        report_only.append(r)
    records = depth + report_only
    for r in records:
        report.write_grade(os.path.join(out, r['student']), r)
    shutil.copy(os.path.join(data, 'kept', 'report-fr_odt', 'report.json'), os.path.join(out, 'Cleo', 'report.json'))
    for sheet in ('altitude', 'depth'):
        shutil.copy(os.path.join(data, 'answers', 'reference-%s.json' % sheet), out)
    report.write_csv(os.path.join(out, 'grades.csv'), records)
    desk.finish(out, records)
    with open(os.path.join(out, 'grades.csv'), encoding='utf-8') as f:
        assert {row['student']: row['sheet'] for row in csv.DictReader(f)} == \
            {'Ann': 'depth', 'Bob': 'depth', 'Cleo': 'altitude', 'Dora': 'depth'}
    with open(os.path.join(out, hand.FILE), encoding='utf-8') as f:
        assert [row['sheet'] for row in csv.DictReader(f) if row['student'] == 'Cleo'] == ['altitude']
    sheeted = {r['student']: r for r in desk.with_sheets(out, records)}
    assert any(n.startswith('sheet altitude: its report is about it (it names ') for n in sheeted['Cleo']['for_the_teacher'])
    assert any(n.startswith("sheet depth: the class's") for n in sheeted['Dora']['for_the_teacher'])
    assert sheeted['Ann'] is records[0]
    with open(os.path.join(out, 'Cleo', 'proposals.json'), encoding='utf-8') as f:
        q6 = [p for p in json.load(f) if p['item'] == 'Q6'][0]
    assert 'topics: ok (/pressure, /rosout, /temperature)' in q6['evidence'] and q6['points'] == 1.0, q6

def test_a_status_reason_is_said_once():
    """A doubt that is the status reason itself (several uploads) is not printed twice on its line."""
    twice = dict(record('Jane', status='needs a hand grade', reason='several uploads: a.zip and b.zip'),
                 doubts=['several uploads: a.zip and b.zip', 'a launch file warning'])
    line, = report.needing_the_teacher([twice])
    assert line.count('several uploads') == 1 and 'a launch file warning' in line
    text = page.render([twice], 'Class', {})
    first = re.sub(r' title="[^"]*"', '', text[text.index('id="first"'):text.index('id="histogram"')])
    assert first.count('several uploads') == 1  # (the status's tooltip aside)


@pytest.mark.parametrize('text, sheet', [
    ('$ rostopic list\n/pressure_robot\n/pressure_remote\n/depth\n/rosout', 'depth'),
    ('catkin_create_pkg exam rospy std_msgs submarinedrone ; rosservice call /depth_warning', 'depth'),
    ('rostopic list /pressure /temperature; rosnode info /mydrone', 'altitude'),
    ('la pression et la température, pressure and temperature, depth and altitude', None),  # prose names nothing
    ('/pressure_robot and /temperature', None),                # one of each: neither
    ('/mydrone/pressure /exam/depth_x /altitudes', None),      # whole names only
    ('/pressure /temperature /altitude mydrone, unlike /depth', 'altitude'),  # 4 against 1
])
def test_the_sheet_a_text_is_about(text, sheet):
    from exam_lab.grader.score.sheets import sheet_named_in
    named, words = sheet_named_in(text)
    assert named == sheet, words
    assert words.startswith('it names ') and "of the depth sheet's ROS names" in words

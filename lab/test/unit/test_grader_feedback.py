"""Each student's feedback page back into Moodle (exam_lab.grader.publish.feedback) on synthetic records:
Moodle's naming rule on real download folder names and what Moodle's importer makes of the zip, who is
released and who is left out, what each setting shows, the hidden threshold value in no file of the
zip, a student's text escaped, the same bytes for the same grade. The real class in a browser is
lab/test/grader/test_page_browser.py."""
import html
import json
import os
import re
import warnings
import zipfile
from html.parser import HTMLParser

import pytest

from exam_lab.grader.publish import feedback, hand, report, student_view
from exam_lab.grader.score import identity
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS
from test_grader_desk import probe_result as desk_probe_result
from test_grader_moodle_names import download_path, moodle_import
from test_grader_probe_record import keep_runs

#: The value the threshold run flew at: in the teacher's files, never in a student's.
HIDDEN = '1040'

# Download folder names as Moodle writes them: (folder, the user's full name in Moodle, participant id).
# The first ones are the project's fixtures (grep lab/test for assignsubmission); the others are what
# Moodle's rule (feedback.py's comment) makes of accents, apostrophes, quotes, an underscore, a slash,
# and two students of one name. A name ending in '_' is Moodle 3.1-4.0's layout, one without, 4.1's.
DOWNLOADS = [
    ('Jane Doe_1234567_assignsubmission_file_', 'Jane Doe', 1234567),       # test_grader_moodle.py
    ('Jane Doe_101_assignsubmission_file_', 'Jane Doe', 101),               # test_page_browser.py
    ('Paul Martin_102_assignsubmission_file_', 'Paul Martin', 102),
    ('Bob_13_assignsubmission_file_', 'Bob', 13),                          # test_sandbox.py
    ('Participant_88_assignsubmission_file', 'Participant', 88),           # blind marking, Moodle 4.1
    ('Zoé ONeil_7_assignsubmission_file_', "Zoé O'Neil", 7),
    ('Anne-Sophie dArc_8_assignsubmission_file', "Anne-Sophie d'Arc", 8),
    ('Ève Evie Lefèvre_9_assignsubmission_file_', 'Ève "Evie" Lefèvre', 9),
    ('Jean Pierre Martin_10_assignsubmission_file_', 'Jean_Pierre Martin', 10),
    ('AB C_11_assignsubmission_file_', 'A/B: C', 11),
    ('Marie Dupont_21_assignsubmission_file_', 'Marie Dupont', 21),
    ('Marie Dupont_22_assignsubmission_file_', 'Marie Dupont', 22),
]


def download_folder(fullname, number, last):
    """A download folder by Moodle's rule (test_grader_moodle_names' port, not the product's)."""
    return download_path(fullname, number, '', '3.1' if last else '4.1').rstrip('/')


@pytest.mark.parametrize('folder, fullname, number', DOWNLOADS)
def test_moodle_naming_rule_gives_the_download_names(folder, fullname, number):
    assert download_folder(fullname, number, '_' if folder.endswith('_') else '') == folder
    got = feedback.folder_name(feedback.moodle_name({'folder': folder, 'student': 'x'}, number), number)
    assert got == folder.rstrip('_').replace('_assignsubmission_file', '_assignfeedback_file') + '_'
    assert moodle_import(got + '/feedback.html', {number}) == (number, 'assignfeedback', 'file', '/feedback.html')


def test_the_class_zips_names_reach_the_feedback_folders(tmp_path):
    """A class zip as Moodle's downloader streams it (ZipStream flags a non-ASCII name as UTF-8, as Python
    does): unpacked, each folder's name is Moodle's, and so is its feedback folder's."""
    from exam_lab.grader.boxed import classlist
    from test_grader_unpack import PACKAGE_XML, make_zip
    archive = make_zip(tmp_path / 'ROS-Exam-12.zip', [('%s/exam/package.xml' % folder, PACKAGE_XML)
                                                      for folder, _, _ in DOWNLOADS])
    scratch = tmp_path / 'scratch'
    scratch.mkdir()
    found = classlist.list_students(archive, str(scratch))
    assert sorted(os.path.basename(path) for _, path in found) == sorted(folder for folder, _, _ in DOWNLOADS)
    for _, path in found:
        folder = os.path.basename(path)
        r = {'folder': folder, 'student': 'x', 'participant': None}
        number = identity.identity(r).participant
        assert feedback.folder_name(feedback.moodle_name(r, number), number) == \
            folder.rstrip('_').replace('_assignsubmission_file', '_assignfeedback_file') + '_'


def test_clean_filename_is_moodles_param_file():
    assert feedback.clean_filename('a&b<c>d"e`f|g\'h:i\\j/k\x00l\x1fm\x7fn é ü') == 'abcdefghijklmn é ü'
    assert feedback.clean_filename('..') == '' and feedback.clean_filename('.') == ''
    assert feedback.clean_filename('a..b') == 'a..b'


def test_a_folder_moodle_did_not_write_still_imports():
    """An underscore in the name part (a folder made by hand) would make Moodle read the name as the id:
    the rule replaces it, as Moodle does."""
    naive = 'a_noisy_101_assignfeedback_file_'  # the fixture a_noisy_101_assignsubmission_file_, renamed
    assert moodle_import(naive + '/feedback.html', {101}) is None
    got = feedback.folder_name(feedback.moodle_name({'folder': 'a_noisy_101_assignsubmission_file_'}, 101), 101)
    assert got == 'a noisy_101_assignfeedback_file_'
    assert moodle_import(got + '/feedback.html', {101})[0] == 101
    # a hidden file is skipped by Moodle: the page is not one
    assert moodle_import(got + '/.feedback.html', {101}) is None and not feedback.PAGE.startswith(('.', '~'))


def record(student, lost=None, status='graded', reason='', folder=None, evidence=None, notes=('hint',)):
    lost, evidence = lost or {}, evidence or {}
    items = [{'id': i, 'points': top - lost.get(i, 0.0), 'max': top,
              'evidence': evidence.get(i, 'measured %s' % i)} for i, (top, _) in ITEMS.items()]
    number = re.search(r'_(\d+)_assign', folder or '')
    extra = {'participant': int(number.group(1)) if number else None, 'folder': folder, 'documents': []}
    return dict(report.grade_record(student, 'altitude', items, list(notes), extra), status=status,
                status_reason=reason)


def probe_result(kind='main', threshold=1300.0, requests=('WARNING', 'NORMAL')):
    """test_grader_desk's probe result, with the run's threshold and the main run's two requests."""
    result = dict(desk_probe_result(kind), threshold=threshold)
    if kind == 'main':
        result['calls'] = [[t, request] for (t, _), request in zip(result['calls'], requests)]
    return result


def graded_class(out, records, threshold_run=True, requests=('WARNING', 'NORMAL')):
    """OUT as a class run leaves it: each student's grade and logs (the threshold run's too)."""
    for r in records:
        logs = os.path.join(out, r['student'], 'logs')
        os.makedirs(logs)
        runs = [('main', probe_result(requests=requests))]
        if threshold_run:
            with open(os.path.join(logs, 'plan-threshold.json'), 'w') as f:
                json.dump({'threshold': float(HIDDEN)}, f)
            runs.append(('threshold', probe_result('threshold', threshold=float(HIDDEN))))
        keep_runs(os.path.join(out, r['student']), runs)
        report.write_grade(os.path.join(out, r['student']), r)


def pages(out):
    with zipfile.ZipFile(os.path.join(out, feedback.FILE)) as archive:
        return {name: archive.read(name).decode('utf-8') for name in archive.namelist()}


class Strict(HTMLParser):
    """Every element closes in order; the tags and attributes seen (a browser would forgive, we do not)."""
    VOID = ('meta', 'img', 'br', 'input', 'path', 'use', 'rect', 'circle', 'stop')

    def __init__(self):
        HTMLParser.__init__(self, convert_charrefs=True)
        self.stack, self.tags, self.attrs, self.text = [], [], [], []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.attrs += attrs
        if tag not in self.VOID:
            self.stack.append(tag)

    def handle_startendtag(self, tag, attrs):
        self.tags.append(tag)
        self.attrs += attrs

    def handle_endtag(self, tag):
        if tag in self.VOID:
            return
        assert self.stack and self.stack[-1] == tag, (tag, self.stack[-5:])
        self.stack.pop()

    def handle_data(self, data):
        self.text.append(data)


def strict(text):
    parser = Strict()
    parser.feed(text)
    parser.close()
    assert parser.stack == [], parser.stack
    return parser


def test_the_zip_has_one_page_per_released_student_in_moodles_folders(tmp_path):
    out = str(tmp_path)
    records = [record('Jane Doe', folder=DOWNLOADS[1][0]), record('Zoé ONeil', {'Q11': 1.5}, folder=DOWNLOADS[5][0]),
               record('Marie Dupont', folder=DOWNLOADS[10][0]), record('Marie Dupont_2', {'Q13': 2}, folder=DOWNLOADS[11][0]),
               record('Paul Martin', status='needs a hand grade', reason='the node died', folder=DOWNLOADS[2][0]),
               record('Bob', status='not graded', reason='refused', folder=DOWNLOADS[3][0]),
               record('fixed', status='graded with fixes', reason='made executable', folder=DOWNLOADS[8][0]),
               record('loose', folder='loose')]
    graded_class(out, records)
    lines = feedback.write(out, records, show='points')
    got = pages(out)
    assert sorted(got) == ['Jane Doe_101_assignfeedback_file_/feedback.html',
                           'Jean Pierre Martin_10_assignfeedback_file_/feedback.html',
                           'Marie Dupont_21_assignfeedback_file_/feedback.html',
                           'Marie Dupont_22_assignfeedback_file_/feedback.html',
                           'Zoé ONeil_7_assignfeedback_file_/feedback.html']
    ids = {101, 7, 21, 22, 10, 102, 13}
    imported = {moodle_import(name, ids)[0]: text for name, text in got.items()}
    assert sorted(imported) == [7, 10, 21, 22, 101]
    # two students of one name: each its own points
    assert '<h1>Marie Dupont: 17 / 17</h1>' in imported[21] and '<h1>Marie Dupont: 15 / 17</h1>' in imported[22]
    assert '<h1>Zoé ONeil: 15.5 / 17</h1>' in imported[7]
    assert lines[0].startswith('moodle feedback: %s: a page for 5 student(s)' % os.path.join(out, feedback.FILE))
    left = lines[lines.index([l for l in lines if 'left out' in l][0]) + 1:]
    assert left == ['  Paul Martin: status "needs a hand grade": the node died', '  Bob: status "not graded": refused',
                    '  loose: no Moodle participant number in its folder\'s name (loose)']
    with zipfile.ZipFile(os.path.join(out, feedback.FILE)) as archive:
        assert all(info.flag_bits & 0x800 for info in archive.infolist() if not info.filename.isascii())


def test_one_participant_number_twice_is_left_out(tmp_path):
    out = str(tmp_path)
    records = [record('Ann', folder='Ann_5_assignsubmission_file_'), record('Ann_2', folder='Ann_5_assignsubmission_file_'),
               record('Ben', folder='Ben_6_assignsubmission_file_')]
    graded_class(out, records)
    lines = feedback.write(out, records, show='points')
    assert sorted(pages(out)) == ['Ben_6_assignfeedback_file_/feedback.html']
    assert '  Ann: participant 5 is also Ann_2' in lines and '  Ann_2: participant 5 is also Ann' in lines


def test_nothing_released_leaves_no_stale_zip(tmp_path):
    out = str(tmp_path)
    records = [record('Ann', folder='Ann_5_assignsubmission_file_')]
    graded_class(out, records)
    feedback.write(out, records, show='points')
    assert os.path.isfile(os.path.join(out, feedback.FILE))
    held = [dict(records[0], status='needs a hand grade', status_reason='a doubt')]
    lines = feedback.write(out, held, show='points')
    assert not os.path.exists(os.path.join(out, feedback.FILE))
    assert lines[0].endswith('NOT written: no student\'s grade is released yet')
    assert lines[-1] == '  Ann: status "needs a hand grade": a doubt'


def hostile_threshold_record(folder):
    """A record whose every teacher-only place names the hidden value: Q14a's evidence, the runs' words
    about the threshold run, the status reason, the teacher's notes."""
    return record('Ann', {'runs': 1.0}, status='graded with fixes',
                  reason='in the threshold run the node set to %s warned late' % HIDDEN, folder=folder,
                  evidence={'Q14a': 'launch file /threshold = 1300; set to %s, the node warned 5.00 s after '
                                    'reaching 1170.0' % HIDDEN,
                            'runs': 'builds (2 s); but: main run: node exam died (exit code 1); threshold run: '
                                    'the probe failed: plan %s\nthreshold %s' % (HIDDEN, HIDDEN)},
                  notes=['threshold parameter: set to %s' % HIDDEN])


@pytest.mark.parametrize('show', student_view.SHOW)
def test_the_hidden_threshold_value_is_in_no_file_of_the_zip(tmp_path, show):
    out = str(tmp_path)
    records = [hostile_threshold_record('Ann_5_assignsubmission_file_')]
    graded_class(out, records)
    with open(os.path.join(out, 'Ann', 'grade.json')) as f:  # the value is there to leak
        assert HIDDEN in f.read()
    feedback.write(out, records, show=show)
    got = pages(out)
    assert len(got) == 1
    for name, text in got.items():
        assert not re.search(r'(?<![\w.])%s(?![\d])' % HIDDEN, name + text), name
        assert 'threshold run' not in text.replace('a problem in the threshold run', '')
        assert 'set to' not in text and 'hint' not in text
        if show == 'evidence':  # the main run's plot is there, with its own threshold; the other run's is not
            assert '<svg' in text and 'threshold 1300' in text and 'main run' in text
            assert student_view.Q14A_WORDS[0] in html.unescape(text) and 'a problem in the threshold run' in text
        else:
            assert '<svg' not in text and 'measured Q11' not in text and 'warned late' not in text


def test_the_plot_of_both_runs_would_name_the_hidden_value(tmp_path):
    """The check above can fail: the teacher's plot (both runs) names it."""
    from exam_lab.grader.publish import flightplot
    import matplotlib
    runs = [('main', probe_result()), ('threshold', probe_result('threshold', threshold=float(HIDDEN)))]
    with matplotlib.rc_context({'svg.fonttype': 'none'}):
        flightplot.draw(runs, str(tmp_path / 'both.svg'))
    assert 'threshold %s' % HIDDEN in (tmp_path / 'both.svg').read_text()


def test_points_only_and_evidence_show_what_make_check_shows(tmp_path):
    out = str(tmp_path)
    r = record('Ann', {'Q11': 1.5}, status='graded with fixes', reason='made executable (chmod +x)',
               folder='Ann_5_assignsubmission_file_', evidence={'Q11': 'values: 3 of 3 disagree\nsecond line'})
    graded_class(out, [r], threshold_run=False)
    feedback.write(out, [r], show='points')
    points = strict(list(pages(out).values())[0])
    feedback.write(out, [r], show='evidence')
    evidence = strict(list(pages(out).values())[0])
    shown_points, shown_evidence = ' '.join(points.text), ' '.join(evidence.text)
    for item in ITEMS:
        assert item in shown_points and item in shown_evidence
    assert '2.5 / 4' in shown_points and 'Status: graded with fixes' in shown_points
    assert 'values: 3 of 3 disagree' not in shown_points and 'chmod' not in shown_points
    assert 'svg' not in points.tags
    assert 'values: 3 of 3 disagree' in shown_evidence and 'second line' not in shown_evidence
    assert 'graded with fixes - made executable (chmod +x)' in shown_evidence and 'svg' in evidence.tags
    # without a threshold run, Q14a's own words help the student, as in make check
    assert 'measured Q14a' in shown_evidence
    for word in student_view.lines(r, 'evidence', False)[1:-3]:
        assert word.split()[-1] in shown_evidence
    assert 'hint' not in shown_evidence  # the teacher's notes


def test_the_page_loads_nothing_and_runs_nothing(tmp_path):
    out = str(tmp_path)
    r = record('Ann', folder='Ann_5_assignsubmission_file_')
    graded_class(out, [r])
    feedback.write(out, [r], show='evidence')
    text = list(pages(out).values())[0]
    parsed = strict(text)
    assert 'script' not in parsed.tags and 'img' not in parsed.tags and 'link' not in parsed.tags
    for key, value in parsed.attrs:
        if key in ('src', 'href', 'xlink:href'):
            assert value.startswith(('#', 'data:')), (key, value)
        assert not key.startswith('on'), key
    assert "default-src 'none'" in text


def test_a_students_text_is_escaped(tmp_path):
    out = str(tmp_path)
    topic = '/alt<script>alert("x")</script>'
    log = 'node said: \x1b[2J\x07\'single\' "double" </td></tr><img src=x onerror=alert(1)>\x00 end'
    r = record('Eve', {'Q11': 1.5}, folder='Eve <b>_9_assignsubmission_file_',
               evidence={'Q11': 'publisher: %s std_msgs/Float32' % topic, 'runs': 'builds; but: main run: %s' % log},
               reason='the node printed %s' % log, status='graded with fixes')
    graded_class(out, [r], requests=('"WARNING"\x07<b>', 'NORMAL'))
    with warnings.catch_warnings(record=True) as caught:  # a control character the plot cannot draw
        warnings.simplefilter('always')
        feedback.write(out, [r], show='evidence')
    assert [str(w.message) for w in caught if 'Glyph' in str(w.message)] == []
    got = pages(out)
    assert list(got) == ['Eve b_9_assignfeedback_file_/feedback.html']  # Moodle's rule drops < >
    text = got['Eve b_9_assignfeedback_file_/feedback.html']
    parsed = strict(text)
    assert 'script' not in parsed.tags and 'img' not in parsed.tags and 'b' not in parsed.tags
    assert not re.search('[\x00-\x08\x0b-\x1f\x7f]', text)
    shown = ''.join(parsed.text)
    assert topic in shown and '\'single\' "double" </td></tr><img src=x onerror=alert(1)> end' in shown
    assert '&lt;script&gt;alert(&quot;x&quot;)' in text
    assert 'REFUSED ""WARNING"<b>" calls (1 in the flight)' in shown  # the plot's label, a student's request, as text: its first 12 characters once the bell was gone (the probe's record made it safe)


def test_hand_points_merged_or_left_out(tmp_path):
    out = str(tmp_path)
    records = [record('Ann', folder='Ann_5_assignsubmission_file_'), record('Ben', folder='Ben_6_assignsubmission_file_'),
               record('Cid', folder='Cid_7_assignsubmission_file_')]
    graded_class(out, records)
    hand.write(os.path.join(out, hand.FILE), records)
    with open(os.path.join(out, hand.FILE)) as f:
        rows = f.read().splitlines()
    full = ','.join('%g' % top for top, _ in HAND_ITEMS.values())
    part = '1' + ',' * (len(HAND_ITEMS) - 1)
    rows = [rows[0], rows[1]] + [row.replace(',' * (len(HAND_ITEMS) + 1), ',%s,%s' % (fill, remark))
                                 for row, fill, remark in zip(rows[2:], (full, part), ('well done', ''))] + rows[4:]
    with open(os.path.join(out, hand.FILE), 'w') as f:
        f.write('\n'.join(rows) + '\n')
    lines = feedback.write(out, records, show='points')
    got = {moodle_import(n, {5, 6, 7})[0]: t for n, t in pages(out).items()}
    assert sorted(got) == [5, 7]
    assert '<h1>Ann: 30 / 30</h1>' in got[5] and 'well done' in got[5] and 'Q5' in got[5]
    assert '<h1>Cid: 17 / 17</h1>' in got[7] and 'not scored by the machine' in got[7]
    assert any(l.startswith('  Ben: hand points not all given in hand.csv (') for l in lines)


def test_the_same_grade_gives_the_same_bytes(tmp_path):
    """A rescore that moves nothing changes no page (Moodle replaces every page of an upload all the same:
    the teacher can tell by the bytes whose page moved)."""
    out = str(tmp_path)
    r = record('Ann', folder='Ann_5_assignsubmission_file_')
    graded_class(out, [r])
    feedback.write(out, [r], show='evidence')
    first = pages(out)
    feedback.write(out, [r], show='evidence')
    assert pages(out) == first
    feedback.write(out, [dict(r, total=16.0)], show='evidence')
    assert pages(out) != first


def test_the_setting_is_make_checks_file(tmp_path, monkeypatch):
    # realpath both: CI runs the tests from the workspace's src/ link to lab/.
    assert os.path.realpath(feedback.SETTING) == os.path.realpath(os.path.join(os.path.dirname(os.path.dirname(
        os.path.dirname(os.path.realpath(__file__)))), 'check_visibility.ini'))
    assert feedback.read_show() in student_view.SHOW
    out = str(tmp_path)
    r = record('Ann', folder='Ann_5_assignsubmission_file_')
    graded_class(out, [r])
    feedback.write(out, [r], show='points')
    bad = tmp_path / 'bad.ini'
    bad.write_text('[check]\nshow = everything\n')
    monkeypatch.setattr(feedback, 'SETTING', str(bad))
    lines = feedback.write(out, [r])
    assert 'NOT written' in lines[0] and 'everything' in lines[0]
    assert not os.path.exists(os.path.join(out, feedback.FILE))


def test_make_grade_rescore_and_worksheet_write_the_zip(tmp_path, capsys):
    """make grade and make rescore write it through the desk; make worksheet with the hand points merged."""
    from exam_lab.grader.publish import desk
    from test_grader_hand import WORKSHEET, write_worksheet, worksheet_script
    out = tmp_path / 'out'
    records = [record('Jane Doe', folder='Jane Doe_101_assignsubmission_file_'),
               record('Paul Martin', {'Q11': 1.5}, folder='Paul Martin_102_assignsubmission_file_')]
    graded_class(str(out), records)
    lines = desk.finish(str(out), records, show='points')
    assert any(l.startswith('moodle feedback: %s: a page for 2 student(s)' % (out / feedback.FILE)) for l in lines)
    with open(str(out / 'index.html')) as f:
        assert 'moodle feedback:' in f.read()  # and on the class page's notes
    with open(str(out / hand.FILE)) as f:
        rows = f.read().splitlines()
    full = ','.join('%g' % top for top, _ in HAND_ITEMS.values())
    rows[2] = rows[2].replace(',' * (len(HAND_ITEMS) + 1), ',%s,' % full)
    rows[3] = rows[3].replace(',' * (len(HAND_ITEMS) + 1), ',1' + ',' * len(HAND_ITEMS))
    with open(str(out / hand.FILE), 'w') as f:
        f.write('\n'.join(rows) + '\n')
    write_worksheet(tmp_path / 'ws.csv', WORKSHEET)
    assert worksheet_script().main(['--out', str(out), '--worksheet', str(tmp_path / 'ws.csv')]) == 0
    printed = capsys.readouterr().out
    assert '  Paul Martin: hand points not all given in hand.csv (Q5, Q6, Q7, Q8, Q9, comments, quality)' in printed
    got = pages(str(out))
    assert list(got) == ['Jane Doe_101_assignfeedback_file_/feedback.html']
    assert '<h1>Jane Doe: 30 / 30</h1>' in got['Jane Doe_101_assignfeedback_file_/feedback.html']


def test_without_its_logs_a_grade_is_shown_as_if_the_threshold_run_took_place(tmp_path):
    """make check reads the run's plan from its logs; a kept page cannot ask again: no logs, no value."""
    out = str(tmp_path)
    r = hostile_threshold_record('Ann_5_assignsubmission_file_')
    report.write_grade(os.path.join(out, 'Ann'), r)
    feedback.write(out, [r], show='evidence')
    text = list(pages(out).values())[0]
    assert not re.search(r'(?<![\w.])%s(?![\d])' % HIDDEN, text)
    assert student_view.Q14A_WORDS[0] in html.unescape(text) and '<svg' not in text

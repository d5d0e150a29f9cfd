"""What reaches the teacher is clean, and the desk survives any one student (issue 26, points 4 and 5).

A record whose evidence, notes and log tail carry a student's escape sequences (cursor movement,
erase, OSC, C1, DEL, NUL, bidi overrides) reaches no output with a control character in it: the
terminal (table, progress, the lines grade.py prints), grade.md/json, grades.csv, Moodle's worksheet,
Gradescope's results.json, the page. One student whose plot, results.json or page section fails
costs only that student's part of the desk; values like +-1.7e308, inf and nan are drawn clamped.
No master, no grading run (lab/test/grader/test_boundary_publish.py grades such a student).
"""
import csv
import importlib.util
import io
import json
import math
import os
import re

import pytest

from exam_lab.grader import class_run
from exam_lab.grader.publish import grades, teacher
from exam_lab.grader.score.records import MEASUREMENTS, SimilarityRecord
from exam_lab.grader.host import run as host_run

from exam_lab.grader.publish import desk, flightplot, gradescope, hand, moodle, page, progress, report
from exam_lab.grader.score import kept, safe_text
from exam_lab.grader.score.kept import GradeRecord
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS
from test_grader_desk import probe_result
from test_grader_probe_record import keep_runs

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
#: What may not reach the teacher, written out here rather than taken from the module under test.
CONTROL = re.compile('[\x00-\x08\x0b-\x1f\x7f-\x9f\u202a-\u202e\u2066-\u2069]')
#: A traceback as a hostile node prints it: the screen erased, the cursor moved home and up, a line
#: overwritten by a carriage return, a title (OSC), an 8-bit CSI, C1, DEL, NUL, a bidi override.
HOSTILE = ('Traceback (most recent call last):\x1b[2J\x1b[H17/17 graded\x1b[1A\x1b[K\r'
           'NameError: boom\x1b]0;owned\x07 \x9b2J\x85\x7f\x00 \u202edetarg\u202c end')
#: A student's name as a hostile upload could make it (NUL aside: the name is a folder too).
NAME = 'Eve\x1b[2J\x1b[H\r\x85\u202e'
WORKSHEET = ('\ufeffIdentifier,Full name,Grade,Maximum grade,Last modified (grade),Feedback comments\n'
             '"Participant 101","Eve",,17.00,-,\n')


def hostile_record(student=NAME):
    """A record as it could reach an output without passing :func:`report.grade_record` (read back
    from grade.json, made by a later runner): every text field carries :data:`HOSTILE`."""
    items = [{'id': item, 'points': top / 2 if item == 'Q11' else top, 'max': top,
              'evidence': 'values wrong: %s\nmore %s' % (HOSTILE, HOSTILE) if item == 'Q11' else 'ok'}
             for item, (top, _) in ITEMS.items()]
    total = sum(i['points'] for i in items)
    return {'version': kept.VERSION, 'student': student, 'sheet': 'altitude', 'total': total, 'max': 17.0, 'items': items,
            'for_the_teacher': ['main run, odd lines in the log: %s' % HOSTILE], 'participant': 101,
            'status': 'needs a hand grade', 'status_reason': 'the node crashed: %s' % HOSTILE,
            'documents': [{'name': 'report%s.pdf' % HOSTILE, 'pages': 2}], 'seconds': 40.0}


def strings(value):
    """Every string in a JSON value, keys too."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for k, v in value.items():
            yield k
            yield from strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from strings(v)


def _read(path):
    with open(path, encoding='utf-8', newline='') as f:
        return f.read()


def _grade_script():
    spec = importlib.util.spec_from_file_location('grade_script', os.path.join(REPO, 'lab', 'scripts', 'grade.py'))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def out_terminal_table(tmp_path, record, monkeypatch, capsys):
    return [report.table([record])] + report.needing_the_teacher([record]) + report.evidence_lines(record)


def out_progress(tmp_path, record, monkeypatch, capsys):
    stream = io.StringIO()
    shown = progress.ClassProgress(2, stream, live=False)
    shown.begin([record['student']])
    shown.started(record['student'])
    shown.finished(record)
    shown.close()
    return [stream.getvalue(), shown.line()]


def out_grade_files(tmp_path, record, monkeypatch, capsys):
    report.write_grade(str(tmp_path), record)
    return [_read(str(tmp_path / 'grade.md')), _read(str(tmp_path / 'grade.json'))] + \
        list(strings(json.loads(_read(str(tmp_path / 'grade.json')))))


def out_grades_csv(tmp_path, record, monkeypatch, capsys):
    report.write_csv(str(tmp_path / 'grades.csv'), [record])
    text = _read(str(tmp_path / 'grades.csv'))
    return [text.replace('\r\n', '\n')] + [cell for row in csv.reader(io.StringIO(text)) for cell in row]


def as_read(tmp_path, record):
    """``record`` as every reader of a grade gets it (make worksheet, make rescore, the desk): its
    grade.json (written raw here, as a later grader or a hand could) read as a
    :class:`~exam_lab.grader.score.kept.GradeRecord`, the one place its text is made safe. The
    publishers clean nothing again (issue 37 point 1)."""
    with open(str(tmp_path / 'grade.json'), 'w') as f:
        json.dump(record, f)
    return GradeRecord.read(str(tmp_path / 'grade.json')).value


def all_hand_points(record):
    """``record`` made whole with every hand point given (what the worksheet is filled with)."""
    return hand.combine(record, hand.Hand(record['student'], {i: top for i, (top, _) in HAND_ITEMS.items()},
                                          'seen', record.get('participant')))


def give_hand_points(out, records):
    """hand.csv in ``out`` with every hand point given for ``records``, as a teacher fills it."""
    from test_grader_hand import fill
    os.makedirs(str(out), exist_ok=True)
    hand.write(os.path.join(str(out), hand.FILE), records)
    fill(os.path.join(str(out), hand.FILE), {(r['student'], i): str(top) for r in records
                                             for i, (top, _) in HAND_ITEMS.items()})


def out_worksheet(tmp_path, record, monkeypatch, capsys):
    filled, summary = moodle.fill(WORKSHEET, [all_hand_points(dict(as_read(tmp_path, record), status='graded'))])
    assert len(summary['graded']) == 1  # the feedback was written: the test sees it
    return [filled] + moodle.summary_lines(summary, moodle.UPLOAD)


def out_gradescope(tmp_path, record, monkeypatch, capsys):
    gradescope.write(str(tmp_path), as_read(tmp_path, record))
    return [_read(str(tmp_path / 'results.json'))] + list(strings(json.loads(_read(str(tmp_path / 'results.json')))))


def out_page(tmp_path, record, monkeypatch, capsys):
    out = tmp_path / 'out'
    os.makedirs(str(out / record['student'] / 'logs'))
    lines = desk.finish(str(out), [record], similar=SimilarityRecord.make({'error': 'similarity failed on %s' % HOSTILE, 'notes': []}))
    return lines + [_read(str(out / 'index.html'))]


def out_grade_script(tmp_path, record, monkeypatch, capsys):
    """What ``grade.py --class`` prints, the grading itself replaced by the record."""
    (tmp_path / 'class').mkdir()
    os.makedirs(str(tmp_path / 'out' / record['student']))
    monkeypatch.setattr(class_run, 'grade_class', lambda *args, **kwargs: [record])
    monkeypatch.setattr(class_run, 'class_similarity', lambda *args: SimilarityRecord.make({'pairs': [], 'students': 1, 'notes': []}))
    assert _grade_script().main(['--class', str(tmp_path / 'class'), '--out', str(tmp_path / 'out')]) == 0
    printed = capsys.readouterr()
    assert 'need the teacher' in printed.out and 'Eve' in printed.out
    return [printed.out, printed.err]


OUTPUTS = [out_terminal_table, out_progress, out_grade_files, out_grades_csv, out_worksheet, out_gradescope,
           out_page, out_grade_script]
#: Outputs that show no evidence nor reason (names, points, status only).
NO_EVIDENCE = (out_progress, out_grades_csv)


@pytest.mark.parametrize('output', OUTPUTS, ids=lambda f: f.__name__[len('out_'):])
def test_no_control_character_reaches_an_output(output, tmp_path, monkeypatch, capsys):
    texts = output(tmp_path, hostile_record(), monkeypatch, capsys)
    found = sorted({'%r' % c for t in texts for c in CONTROL.findall(t)})
    assert found == []
    assert output in NO_EVIDENCE or any('most recent call last' in t for t in texts)  # the text itself stays


def test_the_record_is_clean_where_it_is_made():
    """The boundary: the log tail as the session keeps it, the notes the runner makes of it, the
    record :func:`report.grade_record` makes of them."""
    outcome = host_run.launch_outcome('[exam-1] started\n%s\n[exam-1] process has died [pid 3, exit code 1]\n'
                                     % HOSTILE)
    assert CONTROL.findall(outcome['tail']) == [] and '17/17 graded' in outcome['tail']
    run = {'tag': 'main', 'launch': {'tail': HOSTILE}}
    notes = teacher.hints({}, {'build': None, 'runs': [run]}, [], None, True)
    record = report.grade_record('Eve', 'altitude', hostile_record()['items'], notes,
                                 {'documents': hostile_record()['documents']}, ('needs a hand grade', HOSTILE))
    assert [s for s in strings(record) if CONTROL.search(s)] == []
    assert 'NameError: boom' in record['status_reason']


@pytest.mark.parametrize('raw, shown', [
    ('a\x1b[2J\x1b[Hb\x1b[1A\x1b[10;20Hc', 'abc'),        # erase, home, up, position
    ('\x1b[1;31mred\x1b[0m', 'red'),                     # colour
    ('\x1b]0;title\x07x\x1b]8;;http://e\x1b\\link\x1b]8;;\x1b\\', 'xlink'),  # OSC, ended by BEL or ST
    ('\x9b2Jx\x9d0;t\x9cy', 'xy'),                        # 8-bit CSI and OSC
    ('\x1b(Bx\x1bMy\x1b7z', 'xyz'),                       # two-character sequences
    ('x\x85y\x7f\x00\x08z', 'xyz'),                       # C1, DEL, NUL, backspace
    ('\x1bPdcs\x1b\\x\x90dcs\x9cy', 'xy'),                # DCS strings, 7- and 8-bit
    ('\u202eevil\u202c \u2066x\u2069', 'evil x'),        # bidi overrides and isolates
    ('one\rtwo\r\nthree\tfour', 'one\ntwo\nthree\tfour'),  # CR: a line of its own; tab kept
    ('\x1b]unended\nnext', '\nnext'),                    # an OSC without its end stops at the line's
    ('Größe 1300 m', 'Größe 1300 m'),
])
def test_clean_text(raw, shown):
    assert safe_text.clean(raw) == shown
    assert safe_text.one_line(raw) == shown.replace('\n', ' ').replace('\t', ' ')


def test_cleaned_record_keeps_its_shape():
    value = {'a\x1b[1A': ['x\x00', ('y\x7f', 1.5)], 'n': None, 'k': True}
    assert safe_text.cleaned(value) == {'a': ['x', ('y', 1.5)], 'n': None, 'k': True}
    assert value['a\x1b[1A'][0] == 'x\x00'  # a copy: the record given is not changed


def extreme_probe():
    """A main run whose node published +-1.7e308 once each, inf and nan, the threshold inf, an oracle
    value of -1.7e308 and a call at a time that is not a number: as the probe's JSON carries them."""
    probe = probe_result()
    published = probe['trace']['published']
    published[40][1], published[41][1] = 1.7e308, -1.7e308
    published[42][1], published[43][1] = float('inf'), float('nan')
    probe['trace']['oracle'].append([published[44][0], -1.7e308])
    probe['calls'].append([float('nan'), 'WARNING'])
    probe['threshold'] = float('inf')
    return probe


def test_extreme_values_are_drawn_clamped_and_said(tmp_path):
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt
    path = str(tmp_path / 'flight.png')
    assert flightplot.draw([('main', extreme_probe()), ('threshold', probe_result('threshold'))], path, 'Eve')
    with open(path, 'rb') as f:
        assert f.read(8) == b'\x89PNG\r\n\x1a\n'
    fig, ax = plt.subplots()
    try:
        flightplot._panel(ax, 'main', extreme_probe())
        low, high = ax.get_ylim()
        assert math.isfinite(low) and math.isfinite(high) and -2 * flightplot.LIMIT < low < high < 2 * flightplot.LIMIT
        said = ' '.join(t.get_text() for t in ax.texts)
        assert '5 value(s) beyond ±1e+06' in said  # 2 published, inf, the oracle's, the threshold
        labels = ax.get_legend_handles_labels()[1]
        assert 'published beyond +1e+06 (2)' in labels and 'published beyond -1e+06 (1)' in labels
        assert '2 time(s) or value(s) not a number' in said            # nan published, the call's time
    finally:
        plt.close(fig)


def test_a_student_with_extreme_values_gets_its_plot_on_the_page(tmp_path):
    out = tmp_path / 'out'
    # The extremes a probe's record takes (published +-1.7e308, inf, nan; an oracle value of -1.7e308),
    # kept as the grading keeps them: the measurements are read as a record (a threshold or a call's
    # time that is not a finite number is no probe's result: it never reaches the plot).
    extremes = dict(extreme_probe(), threshold=probe_result()['threshold'], calls=probe_result()['calls'])
    keep_runs(str(out / 'Eve'), [('main', extremes)])
    record = report.grade_record('Eve', 'altitude', hostile_record()['items'], [], {})
    lines = desk.finish(str(out), [record])
    assert os.path.isfile(str(out / 'Eve' / 'flight.png'))
    assert 'src="Eve/flight.png"' in _read(str(out / 'index.html'))
    assert [l for l in lines if l.startswith('Eve:')] == []


def class_desk(tmp_path):
    """Three graded students with their logs and grade.md, and a worksheet for them."""
    out = tmp_path / 'out'
    records = []
    for number, name in enumerate(('Ada', 'Bob', 'Eve'), 101):
        items = [{'id': item, 'points': top, 'max': top, 'evidence': 'ok'} for item, (top, _) in ITEMS.items()]
        record = report.grade_record(name, 'altitude', items, ['hint'], {'participant': number})
        keep_runs(str(out / name), [('main', probe_result())])
        report.write_grade(str(out / name), record)
        records.append(record)
    worksheet = tmp_path / 'ws.csv'
    worksheet.write_text('\ufeffIdentifier,Full name,Grade,Maximum grade,Last modified (grade),Feedback comments\n'
                         + ''.join('"Participant %d","%s",,17.00,-,\n' % (r['participant'], r['student'])
                                   for r in records), encoding='utf-8')
    give_hand_points(out, records)
    return out, records, str(worksheet)


#: Each part of the desk made per student: (module, function, the student its call is for).
PARTS = {'plot': (flightplot, 'draw', lambda runs, path, title: title),
         'results.json': (gradescope, 'write', lambda folder, record: record['student']),
         'section': (page, '_section', lambda record, entry: record['student'])}


@pytest.mark.parametrize('part', sorted(PARTS))
def test_the_desk_survives_one_student_whose_part_fails(part, tmp_path, monkeypatch):
    out, records, worksheet = class_desk(tmp_path)
    module, name, student_of = PARTS[part]
    real = getattr(module, name)

    def failing(*args):
        if student_of(*args) == 'Bob':
            raise RuntimeError('a bug on Bob\x1b[2J')
        return real(*args)

    monkeypatch.setattr(module, name, failing)
    lines = desk.finish(str(out), records, similar=SimilarityRecord.make({'pairs': [], 'students': 3, 'notes': []}), worksheet=worksheet)
    for student in ('Ada', 'Eve'):
        assert os.path.isfile(str(out / student / 'flight.png'))
        assert os.path.isfile(str(out / student / 'results.json'))
    assert os.path.isfile(str(out / moodle.UPLOAD)) and any('3 whole grade(s)' in l for l in lines)
    html = _read(str(out / 'index.html'))
    assert html.count('class="student"') == 3
    assert 'src="Ada/flight.png"' in html and 'src="Eve/flight.png"' in html
    bob = html[html.index('id="student-Bob"'):html.index('id="student-Eve"')]
    assert 'a bug on Bob' in bob  # the note is in Bob's own section
    assert 'never ran against the probe' not in bob  # its flight was flown: drawn, or its plot failed
    if part != 'section':  # made before the page: the terminal says so too
        assert [l for l in lines if l.startswith('Bob: ') and 'a bug on Bob' in l]
    assert [l for l in lines if CONTROL.search(l)] == [] and CONTROL.search(html) is None


def test_a_page_that_cannot_be_made_is_replaced_by_a_plain_one(tmp_path, monkeypatch):
    out, records, worksheet = class_desk(tmp_path)

    def broken(*args):
        raise ValueError('no page\x1b[2J')

    monkeypatch.setattr(page, 'render', broken)
    lines = desk.finish(str(out), records, worksheet=worksheet)
    html = _read(str(out / 'index.html'))
    assert 'the page could not be made' in html and 'ValueError: no page' in html and CONTROL.search(html) is None
    assert all('<a href="%s/grade.md">' % r['student'] in html for r in records)
    assert any('the page could not be made' in l for l in lines) and os.path.isfile(str(out / moodle.UPLOAD))


#: A name in bytes that are not UTF-8, as Python reads it from a student's tar (surrogate escapes).
NOT_UTF8 = 'notes\udcff\udce9.py'


def not_utf8_record():
    """:func:`hostile_record` whose name, evidence, notes and documents carry a name in any bytes."""
    record = hostile_record(NAME + '\udcff')
    record['status_reason'] += ' in %s' % NOT_UTF8
    record['for_the_teacher'].append('comments (not scored): in scripts/%s' % NOT_UTF8)
    record['documents'] = [{'name': 'rapport\udce9.pdf', 'pages': 1}]
    for item in record['items']:
        if item['id'] == 'Q11':  # the item the terminal shows (not full points)
            item['evidence'] = 'most recent call last: %s' % NOT_UTF8
    return record


@pytest.mark.parametrize('output', OUTPUTS, ids=lambda f: f.__name__[len('out_'):])
def test_a_name_in_any_bytes_survives_every_output(output, tmp_path, monkeypatch, capsys):
    """Issue 36 point 3: a file name that is not UTF-8 is shown escaped (each byte ``\\xNN``) in every
    output; none refuses it (the page emptied, grade.md never written)."""
    texts = output(tmp_path, not_utf8_record(), monkeypatch, capsys)
    assert [t for t in texts if re.search('[\ud800-\udfff]', t)] == []
    texts = [t.replace('&#92;', '\\') for t in texts]  # the worksheet's HTML writes a backslash so
    assert any('\\xff' in t for t in texts)
    assert output in NO_EVIDENCE or any('notes\\xff\\xe9.py' in t for t in texts)


def test_a_name_in_any_bytes_is_kept_exactly_by_a_rescore(tmp_path):
    """The measurements keep the name as it was (surrogate escapes in JSON); a rescore shows it
    escaped, run after run."""
    out = tmp_path / 'out'
    measured = {'version': kept.VERSION, 'student': 'Cy', 'sheet': 'altitude', 'static': {},
                'notes': ['link %s dropped' % NOT_UTF8],
                'fixes': [], 'comments': {'comments': 1, 'code': 2, 'files': ['scripts/' + NOT_UTF8]},
                'isolate': True, 'how_run': None,
                'session': {'outcome': 'session_failed', 'build': None, 'runs': [], 'error': 'x'},
                'extra': {'participant': 3, 'folder': 'Cy_3_assignsubmission_file_', 'documents': [], 'seconds': 1.0}}
    os.makedirs(str(out / 'Cy'))
    with open(str(out / 'Cy' / MEASUREMENTS), 'w') as f:
        json.dump(measured, f)
    for _ in range(2):
        records, _ = grades.rescore(str(out))
        assert desk.finish(str(out), records)[-1].startswith('page: ')
    with open(str(out / 'Cy' / MEASUREMENTS)) as f:
        assert json.load(f)['comments']['files'] == ['scripts/' + NOT_UTF8]
    assert 'scripts/notes\\xff\\xe9.py' in _read(str(out / 'Cy' / 'grade.md'))
    assert 'scripts/notes\\xff\\xe9.py' in _read(str(out / 'index.html'))
    assert 'Cy' in _read(str(out / 'grades.csv'))


def test_the_class_outputs_never_name_a_student(tmp_path):
    """Every file a class's desk writes in OUT ends like an output (identity.OUTPUT_ENDINGS), which no
    student's folder does (:func:`identity.student_name`): a student named ``grades.csv`` cannot take
    the table's place."""
    from exam_lab.grader.score import identity
    out, records, worksheet = class_desk(tmp_path)
    report.write_csv(str(out / 'grades.csv'), records)
    desk.finish(str(out), records, similar=SimilarityRecord.make({'pairs': [], 'students': 3, 'notes': []}), worksheet=worksheet, title='Class')
    written = [n for n in os.listdir(str(out)) if not os.path.isdir(str(out / n))]
    assert written and [n for n in written if not n.lower().endswith(identity.OUTPUT_ENDINGS)] == []
    for name in written + ['hand.csv.zip', 'Index.HTML', 'grades.csv_12_assignsubmission_file_']:
        shown = identity.student_name(name)
        assert shown not in written and not shown.lower().endswith(identity.OUTPUT_ENDINGS), (name, shown)


def test_the_publishers_take_records_only_the_desk_makes_them(tmp_path):
    """Issue 37 point 1: text is made safe once, where its record is made; the publishers clean
    nothing again. A raw grade (never passed through a GradeRecord: every text field carries
    HOSTILE) reaches results.json, the worksheet, the feedback zip and the page through the desk,
    which makes each grade its record: none of them shows a control character. A similarity check
    given as a plain dict is refused by the desk and the page alike (its text would reach the page
    uncleaned, its HTML unchecked)."""
    import zipfile
    out = tmp_path / 'out'
    raw = dict(hostile_record('Eve'), status='graded')  # a name of the class's listing: its folder
    os.makedirs(str(out / 'Eve'))
    worksheet = tmp_path / 'ws.csv'
    worksheet.write_text(WORKSHEET, encoding='utf-8')
    give_hand_points(out, [GradeRecord.make(raw).value])
    lines = desk.finish(str(out), [raw], worksheet=str(worksheet), show='evidence')
    written = [_read(str(out / 'index.html')), _read(str(out / 'Eve' / 'results.json')), _read(str(out / moodle.UPLOAD))]
    with zipfile.ZipFile(str(out / 'moodle-feedback.zip')) as zf:
        written += [zf.read(name).decode('utf-8') for name in zf.namelist()]
    assert len(written) == 4 and all('most recent call last' in text for text in written), lines
    assert [text[:80] for text in written if CONTROL.search(text)] == []
    hostile = {'pairs': [], 'students': 1, 'notes': ['Eve: not compared (%s)' % HOSTILE]}
    with pytest.raises(TypeError):
        desk.finish(str(out), [raw], similar=hostile)
    with pytest.raises(TypeError):
        page.render([], 'Class', {}, hostile)


def test_make_rescore_reads_the_runs_similarity_json_as_its_record(tmp_path, capsys):
    """rescore.py shows the run's similarity check from its record (capped, checked, its text made
    safe); one edited into markup other than the detector's highlight, or of another shape, is no
    record: the page says so where its pairs would be, and every grade is rescored all the same."""
    import runpy
    from html import unescape
    from test_grader_kept import kept_folder
    out = tmp_path / 'out'
    for name in ('Ann', 'Bob'):
        kept_folder(out, 'version-1', name)
    match = {'file_a': 'scripts/a.py', 'file_b': 'scripts/b.py', 'sim_a': 0.9, 'sim_b': 0.9,
             'html_a': "<span class='highlight-red'>x = 1</span>", 'html_b': 'x = 1'}
    check = {'pairs': [{'a': 'Ann', 'b': 'Bob', 'score_a': 0.9, 'score_b': 0.9, 'files': [match]}],
             'students': 2, 'threshold': 0.5, 'notes': ['Cy: not compared (%s)' % HOSTILE]}
    script = runpy.run_path(os.path.join(REPO, 'lab', 'scripts', 'rescore.py'))
    for kept, said in ((check, 'Ann and Bob: 90 % / 90 % alike'),
                       (dict(check, pairs=[dict(check['pairs'][0], files=[dict(match, html_b='<img src=x onerror=alert(1)>')])]),
                        "similarity check not run: the run's similarity.json cannot be read (make grade checks the class "
                        "again): similarity.json.pairs[0].files[0].html_b: markup other than the detector's highlight"),
                       ({'error': 'the box failed'}, 'similarity.json: notes is missing')):
        (out / 'similarity.json').write_text(json.dumps(kept))
        assert script['main'](['--out', str(out)]) == 0
        html = _read(str(out / 'index.html'))
        assert said in unescape(html) and CONTROL.search(html) is None and 'onerror' not in html
    capsys.readouterr()
    (out / 'similarity.json').write_text(json.dumps(check))
    script['main'](['--out', str(out)])
    html = _read(str(out / 'index.html'))
    assert 'Cy: not compared (Traceback (most recent call last):17/17 graded' in html, 'its notes are on the page'

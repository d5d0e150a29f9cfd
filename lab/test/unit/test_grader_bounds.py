"""A cap on a box's record is a sentence, and the student is still graded on what fits (issue 36
point 6): every list and long text a box puts into its record (inspect.json, intake.json,
similarity.json) is bounded where it is made (:mod:`exam_lab.grader.boxed.bounds`), with a sentence
naming the cap and the value; the record then passes root's check of its schema and bytes. Every
other cap a box meets (files, bytes, depths, archives, pages, pictures, its memory) is said as that cap.
No ROS: the inspection runs here as a function, the similarity record is made from a detector's result.
"""
import json
import os
import re
import shutil
import zipfile

import pytest

from exam_lab.grader.boxed import bounds, inspect, intake, similarity
from exam_lab.grader.score import records
from exam_lab.grader.score.inspection import InspectRecord
from exam_lab.grader.score.records import MAX_ITEMS, MAX_TEXT, SimilarityRecord

HERE = os.path.dirname(os.path.realpath(__file__))
GOOD = os.path.join(HERE, '..', 'grader', 'submissions', 'good_student', 'exam')


def read_back(record_type, value):
    """``value`` as root reads it from the box: its JSON, checked against the record's schema and bytes."""
    return record_type.from_json(json.dumps(value).encode('utf-8', 'surrogateescape'), record_type.MAX_BYTES)


def package_with(tmp_path, files):
    """The good student's package with more ``{relative path: text}``, inspected as its box does."""
    pkg = tmp_path / 'upload' / 'exam'
    shutil.copytree(GOOD, str(pkg))
    for relative, text in files.items():
        os.makedirs(os.path.dirname(str(pkg / relative)), exist_ok=True)
        (pkg / relative).write_text(text)
    ws = tmp_path / 'ws'
    (ws / 'src').mkdir(parents=True)
    found = inspect.inspect(str(pkg), str(ws), str(tmp_path / 'out'), None, 0.5)
    return bounds.fit(found, InspectRecord)


def test_a_list_over_its_cap_keeps_its_first_and_says_so():
    notes = []
    assert bounds.kept(range(501), 'Python files', notes, verb='read') == list(range(500))
    assert notes == ['501 Python files (at most 500): the first 500 are read']
    assert bounds.kept(['a', 'threshold', 'b'], 'names', notes, 2, first=lambda n: n == 'threshold') == \
        ['threshold', 'a']  # what the rubric reads goes first when some are left out
    assert bounds.kept(['a', 'threshold'], 'names', [], 2, first=lambda n: n == 'threshold') == ['a', 'threshold']
    text = bounds.cut('scripts/' + 'x' * 3000 + '.py:12', MAX_TEXT)
    assert len(text) == MAX_TEXT and text.startswith('scripts/') and text.endswith('.py:12')
    many = bounds.closed(['n%d' % i for i in range(600)])
    assert len(many) == MAX_ITEMS and many[-1] == '600 notes (at most 500): the first 499 kept'
    many = bounds.closed(['n%d' % i for i in range(600)] + ['a cap'], keep=['a cap'])  # a cap's sentence stays
    assert len(many) == MAX_ITEMS and many[-3:] == ['n497', 'a cap', '601 notes (at most 500): the first 499 kept']


def test_501_python_files_are_graded_on_the_first_500(tmp_path):
    """The case of the issue: the good student's package (its one script) and 500 tiny modules, 501 Python files:
    its record was refused ("inspect.json.comments.files: 501 files (at most 500)"), the student not
    graded. Now the first 500 are read for the comments, and the record says so."""
    found = package_with(tmp_path, {'src/exam/parts/m%03d.py' % i: 'x = %d\n' % i for i in range(500)})
    record = read_back(InspectRecord, found)
    assert len(record.comments.files) == MAX_ITEMS
    assert '501 Python files (at most 500): the first 500 are read for comments' in record.notes
    assert record.main_launch is not None and record.static.threshold.name == '/threshold'


def test_every_list_the_code_makes_is_bounded_and_the_threshold_kept(tmp_path):
    """A node that reads 600 parameters, calls publish, a Timer and a Rate 600 times each, its
    threshold's name sorted last and one name of 3000 characters: each list within its cap, the
    threshold kept for Q14a, one sentence per list."""
    names = ['p%03d' % i for i in range(600)] + ['zz' * 1500]
    code = ''.join("a = rospy.get_param('~%s')\npub.publish(a)\nrospy.Timer(1, f)\nwarn(a)\n" % n for n in names)
    files = {'scripts/flood.py': "import rospy\nwarn = rospy.ServiceProxy('w', T)\n" + code +
                                 "rospy.get_param('~threshold')\nrospy.init_node('flood')\n",
             'scripts/argv.py': 'import argparse\np = argparse.ArgumentParser()\n' +
                                ''.join("p.add_argument('--a%03d')\n" % i for i in range(600))}
    found = package_with(tmp_path, files)
    record = read_back(InspectRecord, found)
    static = record.static
    assert len(static.params_in_code) == MAX_ITEMS and '~threshold' in static.params_in_code
    assert all(len(p) <= MAX_TEXT for p in static.params_in_code)
    assert len(static.args_in_code) == MAX_ITEMS
    for key in ('publishes', 'timers', 'service_calls', 'private_before_init'):
        assert len(getattr(static.code, key)) == MAX_ITEMS, key
    # read before init_node, so a read rospy resolves against <ns>/unnamed: the rubric must still see it
    assert [w for w in static.code.private_before_init if w.endswith(': ~threshold')]
    said = [n for n in record.notes if '(at most 500): the first 500 are kept' in n]
    assert said[0] == '603 parameter names the code reads (at most 500): the first 500 are kept', said
    assert '600 arguments the code reads (at most 500): the first 500 are kept' in said
    assert [n for n in said if re.match(r'^6\d\d service calls in the code ', n)], said
    assert '602 private parameters read before init_node (at most 500): the first 500 are kept' in said
    for what in ('publish calls', 'timers'):  # the good node's own and the flood's
        assert [n for n in said if re.match(r'^6\d\d %s in the code ' % what, n)], said


def test_python_2_findings_are_bounded(tmp_path):
    """501 files of Python 2 (a print statement each): the first 500 findings, the note of them
    naming five and counting the rest."""
    found = package_with(tmp_path, {'scripts/old%03d.py' % i: 'print "old"\n' for i in range(501)})
    record = read_back(InspectRecord, found)
    assert len(record.static.python2) == MAX_ITEMS and record.static.python2[0] == 'scripts/old000.py:1: print statement'
    assert '501 files of Python 2 (at most 500): the first 500 are kept' in record.notes
    assert '501 Python files that do not parse as Python 3 (at most 50): the first 50 are named' in record.notes
    assert [n for n in record.notes if n.startswith('Python 2 code, which ROS Noetic cannot run: ')
            and n.endswith(' and 496 more')]


def test_a_record_over_its_bytes_cuts_its_lists_of_text(tmp_path):
    """500 parameter names of 1999 characters each make an inspect.json of 1 MB: within every list's
    cap, over the record's bytes. Its lists of text are cut further, and the notes say so."""
    names = ['%03d' % i + 'q' * 1995 for i in range(500)]
    found = package_with(tmp_path, {'scripts/long.py': 'import rospy\n' + ''.join(
        "rospy.get_param('%s')\n" % n for n in names)})
    assert len(json.dumps(found)) <= InspectRecord.MAX_BYTES
    record = read_back(InspectRecord, found)
    assert [n for n in record.notes if n.startswith('inspect.json: ') and 'its lists of text cut' in n]
    assert record.static.threshold.name == '/threshold'


def test_fixes_and_notes_of_many_files_are_bounded(tmp_path):
    """600 scripts that are not executable (a fix each) and 600 launch files (a note each when
    they are broken): fixes and notes within their caps, said."""
    files = {'scripts/s%03d.py' % i: '#!/usr/bin/env python3\nx = 1\n' for i in range(600)}
    files.update({'launch/l%03d.launch' % i: '<launch><oops></launch>\n' for i in range(600)})  # not XML
    found = package_with(tmp_path, files)
    record = read_back(InspectRecord, found)
    assert len(record.fixes) == MAX_ITEMS and record.fixes[-1].startswith('6') and 'fixes (at most 500)' in record.fixes[-1]
    assert len(record.notes) <= MAX_ITEMS
    assert len(record.static.launch_files) == MAX_ITEMS
    assert record.static.launch.file == 'launch/exam.launch'  # exam.launch read first when some are left out
    assert any(n.startswith('601 launch files (at most 500): the first 500 are read') for n in record.notes)
    assert [n for n in record.notes if re.match(r'^\d+ problems of the launch files \(at most 50\): the first 50 '
                                                r'are named$', n)], record.notes[-5:]


def test_any_list_left_uncut_is_cut_by_the_record_s_schema():
    """What no maker cut (a list added later): fit cuts it by the schema and says so in the notes."""
    value = {'uid': 1000, 'refused': 'x' * 5000, 'sheet': 'altitude', 'notes': [], 'fixes': ['f'] * 700,
             'static': None, 'threshold_value': 1300.0, 'calls_service': False, 'namespace': '/',
             'main_launch': None, 'threshold_launch': None, 'comments': None,
             'facts': {'participant': None, 'folder': 'f', 'documents': [{'name': 'r.pdf', 'pages': 1}] * 501}}
    record = read_back(InspectRecord, bounds.fit(value, InspectRecord))
    assert len(record.refused) == MAX_TEXT and len(record.fixes) == MAX_ITEMS
    assert 'inspect.json.fixes: 700 items (at most 500): the first 500 kept' in record.notes
    assert 'inspect.json.facts.documents: 501 items (at most 500): the first 500 kept' in record.notes
    assert 'inspect.json.refused: a text of 5000 characters (at most 2000): cut in its middle' in record.notes


def test_the_similarity_record_keeps_the_most_alike_within_its_caps():
    """A class of 700 who all handed in the same 60 KB node: 244,650 pairs, each flagged with its
    highlighted code. The record keeps the most alike pairs, their code within its bytes, the scores
    within theirs, and says what it left out."""
    html = "<span class='highlight-red'>" + 'x' * 60000 + '</span>'
    names = ['s%03d' % i for i in range(700)]
    pairs = [{'a': a, 'b': b, 'score_a': 0.9, 'score_b': 0.9 + (i == 7) * 0.05,
              'files': [{'file_a': 'scripts/n.py', 'file_b': 'scripts/n.py', 'sim_a': 1.0, 'sim_b': 1.0,
                         'html_a': html, 'html_b': html.replace('red', 'green')}]}
             for i, (a, b) in enumerate((a, b) for j, a in enumerate(names[:80]) for b in names[j + 1:80])]
    scores = [[a, b, 0.9, 0.9] for j, a in enumerate(names) for b in names[j + 1:]]
    result = similarity.bounded({'pairs': pairs, 'students': 700, 'threshold': 0.5, 'detector': 'copydetect',
                                 'scores': scores, 'notes': ['s1: not compared (refused)'] * 600})
    result = bounds.fit(result, SimilarityRecord)
    record = read_back(SimilarityRecord, result)
    assert len(record.pairs) == 3160 and record.pairs[0].score_b > 0.94  # the most alike first
    assert len(record.scores) < len(scores) and len(record.notes) == MAX_ITEMS
    said = ' | '.join(record.notes)
    assert '244650 pairs\' scores' in said and 'highlighted fragments not kept' in said, said[-800:]
    assert "<span class='highlight-red'>" in record.pairs[0].files[0].html_a
    assert '<' not in record.pairs[-1].files[0].html_a


def test_the_intake_cuts_a_reason_and_refuses_more_students_than_a_class_holds(tmp_path, monkeypatch, capsys):
    """A reason longer than MAX_REFUSED is cut in its middle; a class of more students than
    intake.json holds is refused as a class, in a sentence naming the cap and the value."""
    out = tmp_path / 'out'
    klass = out / 'class'
    folders = [klass / ('S%d_%d_assignsubmission_file_' % (i, i)) for i in range(3)]
    for folder in folders:
        folder.mkdir(parents=True)

    def listed(path, scratch, refused):  # as classlist lists an archive: a student refused by its bounds
        refused[str(folders[1])] = 'why ' * 1000
        return [('S%d' % i, str(f)) for i, f in enumerate(folders)]
    monkeypatch.setattr(intake.classlist, 'list_students', listed)
    monkeypatch.setattr(intake.os, 'getuid', lambda: 1000)
    assert intake.main(['--class', str(klass), '--out', str(out)]) == 0
    record = records.IntakeRecord.from_json((out / 'intake.json').read_bytes(), records.IntakeRecord.MAX_BYTES)
    assert len(record.students[1].refused) == intake.MAX_REFUSED and bounds.CUT_MARK in record.students[1].refused
    monkeypatch.setattr(records.IntakeRecord, 'MAX_STUDENTS', 2)
    assert intake.main(['--class', str(klass), '--out', str(out)]) == 3
    assert 'the class archive holds 3 students (at most 2 for a class)' in capsys.readouterr().err


# --- Every other cap a box meets, when hit, is a sentence naming the cap and what was seen (issue 46
# point 6), never a traceback's tail or a wrong reason. Small caps are lowered here to be hit cheaply.

REPORTS = os.path.join(HERE, 'data', 'reports')


def test_the_code_s_functions_and_signals_over_their_caps_are_said(tmp_path, monkeypatch):
    """The functions and blocks judged for their comments, the signs of bad practice: the first of
    each kept, said (they were cut without a word)."""
    from exam_lab.grader.boxed import code_quality
    monkeypatch.setattr(code_quality, 'MAX_UNITS', 3)
    monkeypatch.setattr(code_quality, 'MAX_SIGNALS', 1)
    code = ''.join('def f%d():\n    global g%d\n    g%d = 1\n' % (i, i, i) for i in range(5))
    record = read_back(InspectRecord, package_with(tmp_path, {'scripts/many.py': code}))
    assert len(record.comments.units) == 3 and len(record.comments.quality) == 1
    assert [n for n in record.notes if re.match(r'^\d+ functions and blocks of the code \(at most 3\): the first 3 '
                                                r'are judged for their comments$', n)], record.notes
    assert [n for n in record.notes if re.match(r'^\d+ signs of bad practice in the code \(at most 1\): the first '
                                                r'1 is listed$', n)], record.notes


def test_pdfs_over_their_caps_are_said(tmp_path, monkeypatch):
    """PDFs handed in beyond those listed; a PDF over the bytes read to count its pages; one whose
    streams inflate past the work spent counting: each said, the pages counted on what was read."""
    from exam_lab.grader.boxed import documents
    for name in ('en_docx_table.pdf', 'fr_odt.pdf', 'long_45_pages.pdf'):
        shutil.copy(os.path.join(REPORTS, name), str(tmp_path / name))
    monkeypatch.setattr(documents, 'MAX_DOCUMENTS', 2)
    notes = []
    assert [d['name'] for d in documents.documents(str(tmp_path), notes)] == ['en_docx_table.pdf', 'fr_odt.pdf']
    assert notes == ['3 PDF files (at most 2): the first 2 are listed']
    long_pdf = str(tmp_path / 'long_45_pages.pdf')
    size = os.path.getsize(long_pdf)
    monkeypatch.setattr(documents, 'PDF_READ_BYTES', 1000)
    notes = []
    documents.pdf_pages(long_pdf, notes, 'report/long.pdf')
    assert notes == ["'report/long.pdf': %d bytes, its pages counted on the first 1000 (the most read of a PDF)" % size]
    monkeypatch.setattr(documents, 'PDF_READ_BYTES', size + 100)  # all of it read, its streams inflate further
    notes = []
    documents.pdf_pages(long_pdf, notes, 'long.pdf')
    assert notes == ["'long.pdf': its streams inflate past the %d bytes of work spent counting its pages: counted "
                     "on those read" % (size + 100)]
    monkeypatch.setattr(documents, 'PDF_READ_BYTES', 50 << 20)
    notes = []
    assert documents.pdf_pages(long_pdf, notes) == 46 and notes == []  # 46: its name says 45


def test_the_inspection_says_the_pdfs_it_did_not_list(tmp_path, monkeypatch):
    """The documents' caps reach the teacher's notes of the inspection's record."""
    from exam_lab.grader.boxed import documents
    monkeypatch.setattr(documents, 'MAX_DOCUMENTS', 1)
    found = package_with(tmp_path, {})
    assert not [n for n in found['notes'] if 'PDF files' in n]
    for name in ('fr_odt.pdf', 'long_45_pages.pdf'):
        shutil.copy(os.path.join(REPORTS, name), str(tmp_path / 'upload' / 'exam' / name))
    ws = tmp_path / 'ws2'
    (ws / 'src').mkdir(parents=True)
    record = read_back(InspectRecord, bounds.fit(inspect.inspect(str(tmp_path / 'upload' / 'exam'), str(ws),
                                                                 str(tmp_path / 'out2'), None, 0.5), InspectRecord))
    assert '2 PDF files (at most 1): the first 1 is listed' in record.notes
    assert [d.name for d in record.facts.documents] == ['fr_odt.pdf']


def test_a_code_file_over_the_bytes_compared_is_said(tmp_path, monkeypatch):
    """A file over MAX_FILE_BYTES is data, not compared: said with its name (it was left out silently)."""
    package = tmp_path / 'up' / 'exam'
    for relative, size in (('scripts/exam_node.py', 100), ('scripts/table.py', 400), ('package.xml', 100)):
        os.makedirs(os.path.dirname(str(package / relative)), exist_ok=True)
        (package / relative).write_text('x' * size)
    monkeypatch.setattr(similarity, 'MAX_FILE_BYTES', 300)
    staged, notes = similarity.stage([('dee', str(tmp_path / 'up'))], str(tmp_path / 'staged'))
    assert sorted(os.listdir(os.path.join(staged['dee'], 'scripts'))) == ['exam_node.py']
    assert notes == ["dee: 1 code file(s) not compared, each over the 300 bytes the check reads of one file: "
                     "'scripts/table.py'"]


def test_a_package_beyond_the_search_is_said_as_that_cap(tmp_path):
    """A package deeper than the folders searched, in an archive deeper than the archives opened: the
    cap that left it out, never "no catkin package"."""
    from exam_lab.grader.boxed import archives, package
    deep = tmp_path / 'deep' / 'a' / 'b' / 'c' / 'd' / 'e' / 'exam'
    deep.mkdir(parents=True)
    (deep / 'package.xml').write_text('<package><name>exam</name></package>')
    try:
        package.open_submission(str(tmp_path / 'deep'), str(tmp_path / 'scratch1'), [])
        raise AssertionError('a package 6 folders deep was found')
    except archives.UnpackError as err:
        assert str(err) == ("'a/b/c/d/e/exam/package.xml' is 6 folders deep (the grader looks for the package %d "
                            "folders deep at most)" % package.MAX_DEPTH)
    nested = tmp_path / 'nested'
    nested.mkdir()
    inner = str(tmp_path / 'l3.zip')
    with zipfile.ZipFile(inner, 'w') as zf:
        zf.writestr('exam/package.xml', '<package><name>exam</name></package>')
    for outer in ('l2.zip', 'l1.zip'):
        with zipfile.ZipFile(str(tmp_path / outer), 'w') as zf:
            zf.write(inner, os.path.basename(inner))
        inner = str(tmp_path / outer)
    shutil.move(inner, str(nested / 'l1.zip'))
    try:
        package.open_submission(str(nested), str(tmp_path / 'scratch2'), [])
        raise AssertionError('a package in an archive 3 deep was found')
    except archives.UnpackError as err:
        assert str(err) == "'l3.zip' is an archive inside archives (the grader opens archives %d deep at most)" \
            % package.MAX_NESTING


def test_every_cap_of_an_archive_s_entry_names_the_cap_and_what_was_seen(tmp_path):
    from exam_lab.grader.boxed import archives
    bomb = str(tmp_path / 'bomb.zip')
    with zipfile.ZipFile(bomb, 'w', zipfile.ZIP_DEFLATED) as zf:
        zf.writestr('exam/big', b'\0' * (archives.RATIO_FROM_BYTES + 1))
    with pytest.raises(archives.UnpackError) as refused:
        archives.safe_extract(bomb, str(tmp_path / 'out1'))
    assert re.match(r"^entry 'exam/big' unpacks %d bytes from \d+, more than 200 times its size \(the most an entry "
                    r"over 16 MB may\): a zip bomb\?$" % (archives.RATIO_FROM_BYTES + 1), str(refused.value))
    for name, said in (('/'.join(['d'] * 65) + '/f', "is 66 folders deep (at most 64)"),
                       ('/'.join(['d' * 200] * 25), 'has a path of more than 4096 bytes')):
        archive = str(tmp_path / 'a.zip')
        with zipfile.ZipFile(archive, 'w') as zf:
            zf.writestr(name, 'x')
        with pytest.raises(archives.UnpackError) as refused:
            archives.safe_extract(archive, str(tmp_path / 'out2'))
        assert said in str(refused.value) and str(refused.value).startswith('entry '), str(refused.value)


def test_launch_files_beyond_their_caps_are_said(tmp_path):
    """Includes followed deeper than MAX_INCLUDE_DEPTH ("not found", once), more files read than
    MAX_FILES: each said as its cap."""
    from exam_lab.grader.boxed import launch
    pkg = tmp_path / 'exam'
    (pkg / 'launch').mkdir(parents=True)
    (pkg / 'package.xml').write_text('<package><name>exam</name></package>')
    (pkg / 'launch' / 'self.launch').write_text('<launch><include file="$(dirname)/self.launch"/></launch>')
    analysis = launch.analyse(str(pkg / 'launch' / 'self.launch'), str(pkg), 'exam')
    assert analysis.problems == ['include $(dirname)/self.launch not read: it is included %d deep (at most %d)'
                                 % (launch.MAX_INCLUDE_DEPTH + 1, launch.MAX_INCLUDE_DEPTH)]
    (pkg / 'launch' / 'leaf.launch').write_text('<launch/>')
    (pkg / 'launch' / 'wide.launch').write_text(
        '<launch>%s</launch>' % ('<include file="$(dirname)/leaf.launch"/>' * launch.MAX_FILES))
    analysis = launch.analyse(str(pkg / 'launch' / 'wide.launch'), str(pkg), 'exam')
    assert analysis.problems == ['cannot evaluate launch/wide.launch: more than %d launch files read (includes of '
                                 'includes)' % launch.MAX_FILES]


def test_a_box_out_of_memory_is_said_as_its_bound_not_its_traceback(tmp_path):
    """Python's MemoryError at the box's address space: the bound, without the traceback; another
    failure keeps its log's tail."""
    import subprocess
    import sys
    from exam_lab.grader.host import boxed_run
    memory = 256 << 20
    done = subprocess.run(['prlimit', '--as=%d' % memory, '--', sys.executable, '-c', 'bytearray(1 << 30)'],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)
    assert done.returncode == 1 and done.stdout.rstrip().endswith('MemoryError'), done.stdout
    why, tail = boxed_run.bound_hit(done.returncode, boxed_run.session_tail(done.stdout), 60, memory)
    assert (why, tail) == ('it ran out of memory: its bound is 256 MB of address space', '')
    assert boxed_run.bound_hit(1, 'ValueError: x', 60, memory) == ('it failed (exit 1)', 'ValueError: x')
    assert boxed_run.bound_hit(-9, '', 60, memory) == \
        ('it was killed by signal 9 (its bounds: 60 s of CPU, 256 MB of address space)', '')


def test_the_report_reader_says_each_of_its_caps(tmp_path, monkeypatch):
    """Report files beyond those read, a file over the bytes read, a picture over the pixels decoded:
    each a sentence naming the cap and what was seen."""
    from exam_lab.grader.boxed import report_files, report_reader
    upload = tmp_path / 'upload'
    upload.mkdir()
    for name in ('en_docx_table.pdf', 'fr_odt.pdf', 'scan.pdf'):
        shutil.copy(os.path.join(REPORTS, name), str(upload / name))
    monkeypatch.setattr(report_files, 'REPORT_FILES', 2)
    notes = []
    assert [n for n, _ in report_files.find_reports(str(upload), str(tmp_path / 's1'), notes)] == \
        ['en_docx_table.pdf', 'fr_odt.pdf']
    assert notes == ['3 report files (at most 2): the first 2 are read']
    size = os.path.getsize(str(upload / 'scan.pdf'))
    monkeypatch.setattr(report_reader, 'FILE_BYTES', size - 1)
    monkeypatch.setattr(report_files, 'REPORT_FILES', 10)
    scan_only = tmp_path / 'scan'
    scan_only.mkdir()
    shutil.copy(str(upload / 'scan.pdf'), str(scan_only / 'scan.pdf'))
    value = report_reader.Reader(str(tmp_path / 'r1')).read(str(scan_only))
    assert value['files'][0]['note'] == "'scan.pdf': %d bytes, over the %d the reader reads of one file" % (size, size - 1)
    monkeypatch.setattr(report_reader, 'MAX_PICTURE_PIXELS', 1000)
    reader = report_reader.Reader(str(tmp_path / 'r2'))
    assert reader.pictures(str(scan_only / 'scan.pdf'), 1, {1}) == {}  # page 1's pictures asked for
    assert [n for n in reader.notes if re.match(r'^page 1: a picture of \d+ x \d+ pixels \(at most 0 million\): the '
                                                r'page\'s image read instead$', n)], reader.notes


def test_a_docx_is_known_by_its_document_whatever_its_entries_before(tmp_path):
    """A docx whose word/document.xml comes after 1000 other entries was "not a document" (its kind read
    from the first 1000 names only): a cap said as a wrong reason. Every name is looked up now."""
    from exam_lab.grader.boxed import report_files
    crowded = str(tmp_path / 'crowded.docx')
    with zipfile.ZipFile(os.path.join(REPORTS, 'en_docx_table.docx')) as source, \
            zipfile.ZipFile(crowded, 'w', zipfile.ZIP_DEFLATED) as target:
        for i in range(1001):
            target.writestr('word/media/extra%04d.xml' % i, '<x/>')
        for info in source.infolist():
            target.writestr(info, source.read(info))
    assert report_files.kind_of(crowded) == 'docx'


def test_a_document_beyond_the_folders_searched_is_said_as_that_cap(tmp_path):
    """A report deeper than the reader looks, or in an archive deeper than it opens, was "no report
    handed in"; a PDF deeper than the facts list went unsaid. Each is said as its cap."""
    from exam_lab.grader.boxed import documents, report_files, report_reader
    deep = tmp_path / 'up' / 'a' / 'b' / 'c' / 'd' / 'e'
    deep.mkdir(parents=True)
    shutil.copy(os.path.join(REPORTS, 'fr_odt.pdf'), str(deep / 'report.pdf'))
    notes = []
    assert documents.documents(str(tmp_path / 'up'), notes) == []
    assert notes == ["'a/b/c/d/e/report.pdf' is 5 folders deep: PDFs are listed %d folders deep at most"
                     % (documents.MAX_DEPTH + 1)]
    deeper = deep / 'f'
    deeper.mkdir()
    shutil.move(str(deep / 'report.pdf'), str(deeper / 'report.pdf'))
    value = report_reader.Reader(str(tmp_path / 'r1')).read(str(tmp_path / 'up'))
    assert value['why'] == ("'a/b/c/d/e/f/report.pdf' is 6 folders deep (the reader looks for a report %d folders "
                            "deep at most)" % (report_files.MAX_DEPTH + 1)), value['why']
    nested = tmp_path / 'nested'
    nested.mkdir()
    inner = str(tmp_path / 'l3.zip')
    with zipfile.ZipFile(inner, 'w') as zf:
        zf.write(os.path.join(REPORTS, 'fr_odt.pdf'), 'report.pdf')
    for outer in ('l2.zip', 'l1.zip'):
        with zipfile.ZipFile(str(tmp_path / outer), 'w') as zf:
            zf.write(inner, os.path.basename(inner))
        inner = str(tmp_path / outer)
    shutil.move(inner, str(nested / 'l1.zip'))
    value = report_reader.Reader(str(tmp_path / 'r2')).read(str(nested))
    assert value['why'] == ("'l1.zip/l2.zip/l3.zip' is an archive inside archives, not searched for a report (the "
                            "reader opens archives %d deep at most)" % report_files.MAX_NESTING), value['why']

"""A cap on a box's record is a sentence, and the student is still graded on what fits (issue 36
point 6): every list and long text a box puts into its record (inspect.json, intake.json,
similarity.json) is bounded where it is made (:mod:`exam_lab.grader.boxed.bounds`), with a sentence
naming the cap and the value; the record then passes root's check of its schema and bytes.
No ROS: the inspection runs here as a function, the similarity record is made from a detector's result.
"""
import json
import os
import re
import shutil

from exam_lab.grader.boxed import bounds, inspect, intake, similarity
from exam_lab.grader.score import records
from exam_lab.grader.score.records import MAX_ITEMS, MAX_TEXT, InspectRecord, SimilarityRecord

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
    assert len(record.comments['files']) == MAX_ITEMS
    assert '501 Python files (at most 500): the first 500 are read for comments' in record.notes
    assert record.main_launch is not None and record.static['threshold']['name'] == '/threshold'


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
    assert len(static['params_in_code']) == MAX_ITEMS and '~threshold' in static['params_in_code']
    assert all(len(p) <= MAX_TEXT for p in static['params_in_code'])
    assert len(static['args_in_code']) == MAX_ITEMS
    for key in ('publishes', 'timers', 'service_calls', 'private_before_init'):
        assert len(static['code'][key]) == MAX_ITEMS, key
    # read before init_node, so a read rospy resolves against <ns>/unnamed: the rubric must still see it
    assert [w for w in static['code']['private_before_init'] if w.endswith(': ~threshold')]
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
    assert len(record.static['python2']) == MAX_ITEMS and record.static['python2'][0] == 'scripts/old000.py:1: print statement'
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
    assert record.static['threshold']['name'] == '/threshold'


def test_fixes_and_notes_of_many_files_are_bounded(tmp_path):
    """600 scripts that are not executable (a fix each) and 600 launch files (a note each when
    they are broken): fixes and notes within their caps, said."""
    files = {'scripts/s%03d.py' % i: '#!/usr/bin/env python3\nx = 1\n' for i in range(600)}
    files.update({'launch/l%03d.launch' % i: '<launch><oops></launch>\n' for i in range(600)})  # not XML
    found = package_with(tmp_path, files)
    record = read_back(InspectRecord, found)
    assert len(record.fixes) == MAX_ITEMS and record.fixes[-1].startswith('6') and 'fixes (at most 500)' in record.fixes[-1]
    assert len(record.notes) <= MAX_ITEMS
    assert len(record.static['launch_files']) == MAX_ITEMS
    assert record.static['launch']['file'] == 'launch/exam.launch'  # exam.launch read first when some are left out
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

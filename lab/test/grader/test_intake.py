"""A class never stops for one student (issue 36 point 3): one Moodle "download all submissions" zip,
graded, its desk written, rescored.

The class, in Moodle's folders (``Full Name_<participant>_assignsubmission_file_/``, as the fixtures of
lab/test/unit/test_grader_moodle.py), each student a kind of upload that used to stop the class:

- ``Ann Screenshot``: a one-colour screenshot beside her zip (5 MB that Moodle's zip deflates 1000x),
  and a log of 2 MB in her own zip (the case of the same kind: an upload's compressible file);
- ``Bob Crowd``: more files than one submission may unpack: refused alone, on his row, with why;
- ``Cy Bytes``: a tar whose file names, and a link's name and target (the case of the same kind),
  are not UTF-8;
- ``grades.csv.zip`` and ``index.html.zip`` at the zip's top, and a Moodle folder ``hand.csv_...``
  (the case of the same kind): students named like the class's outputs;
- ``Dee Copy`` and ``Eve Original``: the same code; Dee's package also holds 3 MB of YAML and
  60 more Python files than the check reads of one student; ``Gus Deep`` a file in folders deeper than
  an upload may be (the case of the same kind: refused alone, by the grading and by the check);
- ``Fay Many``: 501 Python files, one over the inspection record's list cap: graded on the first
  500, a sentence naming the cap and the value for the teacher, no traceback.

The class zip itself is staged for its intake by a class's bounds, not one upload's.

No package here starts a ROS node: what is judged is what the intake, the inspections, the
similarity check, the desk and a rescore make of them (no flight; a few seconds of boxes).
"""
import io
import json
import os
import runpy
import tarfile
import zipfile

import pytest

from exam_lab.grader import class_run
from exam_lab.grader.score.records import MEASUREMENTS
from exam_lab.grader.boxed import archives, classlist, similarity
from exam_lab.grader.host import sandbox, staging
from exam_lab.grader.publish import desk
from exam_lab.grader.score import rubric

HERE = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
PACKAGE_XML = b'<package format="2"><name>exam</name><version>0.0.1</version></package>\n'
#: Code two students share: the answer's pure modules (no node: nothing is flown).
with open(os.path.join(REPO, 'exam', 'src', 'exam', 'formulas.py'), 'rb') as _f:
    SHARED = _f.read()
with open(os.path.join(REPO, 'exam', 'src', 'exam', 'debounce.py'), 'rb') as _f:
    SHARED += b'\n' + _f.read()
MOODLE = '%s_%d_assignsubmission_file_/'


def zipped(entries):
    data = io.BytesIO()
    with zipfile.ZipFile(data, 'w', zipfile.ZIP_DEFLATED) as zf:
        for name, content in entries:
            zf.writestr(name, content)
    return data.getvalue()


def package(*more):
    """A zip of an ``exam`` package without a node, with ``more`` entries ``(path in it, bytes)``."""
    return zipped([('exam/package.xml', PACKAGE_XML), ('exam/CMakeLists.txt', b'project(exam)\n')] +
                  [('exam/' + name, content) for name, content in more])


def not_utf8_tar():
    """A tar of a package whose names are bytes that are not UTF-8: a script, a link and its target."""
    data = io.BytesIO()
    with tarfile.open(fileobj=data, mode='w', format=tarfile.GNU_FORMAT) as tf:
        for name, content, link in ((b'exam/package.xml', PACKAGE_XML, None),
                                    (b'exam/scripts/notes\xff\xe9.py', b'# notes\nx = 1\n', None),
                                    (b'exam/lien\xfe', b'', b'/tmp/cible\xfd')):
            info = tarfile.TarInfo(name.decode('utf-8', 'surrogateescape'))
            if link is not None:
                info.type, info.linkname = tarfile.SYMTYPE, link.decode('utf-8', 'surrogateescape')
            info.size = len(content)
            tf.addfile(info, io.BytesIO(content))
    return data.getvalue()


def moodle_zip(path):
    entries = [
        (MOODLE % ('Ann Screenshot', 101) + 'exam.zip', package(('run.log', b'[INFO] altitude 1300.0 m\n' * 80000))),
        (MOODLE % ('Ann Screenshot', 101) + 'screenshot.bmp', b'\xff' * (5 << 20)),
        (MOODLE % ('Bob Crowd', 102) + 'exam.zip', package()),
        (MOODLE % ('Cy Bytes', 103) + 'exam.tar', not_utf8_tar()),
        ('grades.csv.zip', package()),
        ('index.html.zip', package()),
        (MOODLE % ('hand.csv', 104) + 'exam.zip', package()),
        (MOODLE % ('Dee Copy', 105) + 'exam.zip', package(
            ('src/exam/logic.py', SHARED), *[('config/map%d.yaml' % i, b'cell: [0, 0, 0]\n' * 6400) for i in range(30)],
            *[('tools/t%02d.py' % i, ('value_%d = %d\n' % (i, i)).encode() * 200) for i in range(60)])),
        (MOODLE % ('Eve Original', 106) + 'exam.zip', package(('src/exam/logic.py', SHARED))),
        (MOODLE % ('Fay Many', 107) + 'exam.zip', package(*[('src/exam/m%03d.py' % i, b'x = 1\n') for i in range(501)])),
        (MOODLE % ('Gus Deep', 108) + 'exam.zip', package()),
        (MOODLE % ('Gus Deep', 108) + 'deep/' * (staging.UPLOAD_DEPTH + 1) + 'notes.txt', b'deep'),
    ] + [(MOODLE % ('Bob Crowd', 102) + 'photos/p%04d.jpg' % i, b'j') for i in range(archives.MAX_FILES)]
    with zipfile.ZipFile(path, 'w', zipfile.ZIP_DEFLATED) as zf:
        for name, content in entries:
            zf.writestr(name, content)
    return path


@pytest.fixture(scope='module')
def graded(tmp_path_factory):
    """The class graded (JOBS=2), its similarity checked, its desk written, then ``make rescore``."""
    if os.geteuid() != 0 or sandbox.check() is not None:
        pytest.skip('boxes need root and bubblewrap: %s' % sandbox.check())
    root = tmp_path_factory.mktemp('intake')
    klass = moodle_zip(str(root / 'class.zip'))
    out = str(root / 'out')
    staged, stage_upload = [], staging.stage_upload

    def spy(source, target, *bounds):
        staged.append((source, bounds))
        return stage_upload(source, target, *bounds)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(staging, 'stage_upload', spy)
        records = class_run.grade_class(klass, out, jobs=2)
        similar = class_run.class_similarity(klass, out, records)
    lines = desk.finish(out, records, similar=similar, title='Intake class')
    before = {r['student']: r for r in records}
    rescore = runpy.run_path(os.path.join(REPO, 'lab', 'scripts', 'rescore.py'))
    status = rescore['main'](['--out', out])
    return {'out': out, 'records': before, 'similar': similar.value, 'lines': lines, 'rescore': status,
            'staged': staged, 'class': klass}


def read(path):
    with open(path, encoding='utf-8') as f:
        return f.read()


def test_every_student_has_a_row_and_every_output_is_written(graded):
    names = ['Ann Screenshot', 'Bob Crowd', 'Cy Bytes', 'Dee Copy', 'Eve Original', 'Fay Many', 'Gus Deep',
             'grades_csv', 'hand_csv', 'index_html']
    assert sorted(graded['records']) == names
    rows = read(os.path.join(graded['out'], 'grades.csv')).splitlines()[1:]
    assert sorted(row.split(',')[0] for row in rows) == names
    page = read(os.path.join(graded['out'], 'index.html'))
    for name in names:
        assert os.path.isfile(os.path.join(graded['out'], name, 'grade.json')), name
        assert os.path.isfile(os.path.join(graded['out'], name, 'grade.md')), name
        assert '>%s<' % name in page, name
    assert graded['rescore'] == 0
    for name in names:  # the rescore wrote each grade again, with the points it had
        assert 'previous' in json.loads(read(os.path.join(graded['out'], name, 'grade.json'))), name


def test_a_compressible_file_refuses_nobody(graded):
    ann = graded['records']['Ann Screenshot']
    assert ann['status'] != rubric.NOT_GRADED, ann['status_reason']
    assert 'no script of the package starts a ROS node' in ann['status_reason']


def test_a_student_over_its_own_bounds_is_refused_alone_with_why(graded):
    bob = graded['records']['Bob Crowd']
    assert bob['status'] == rubric.NOT_GRADED
    assert bob['status_reason'] == ("submission refused: the files of 'Bob Crowd_102_assignsubmission_file_': "
                                    '5001 more files, beyond the 5000 a submission may unpack')
    assert bob['participant'] == 102
    assert [line for line in graded['similar']['notes'] if line.startswith('Bob Crowd: not compared')]


def test_a_name_in_any_bytes_is_shown_escaped_everywhere(graded):
    cy = graded['records']['Cy Bytes']
    hints = ' | '.join(cy['for_the_teacher'])
    assert 'scripts/notes\\xff\\xe9.py' in hints, hints
    assert "'exam/lien\\xfe' -> '/tmp/cible\\xfd'" in hints, hints
    assert 'scripts/notes\\xff\\xe9.py' in read(os.path.join(graded['out'], 'Cy Bytes', 'grade.md'))
    assert 'notes\\xff\\xe9.py' in read(os.path.join(graded['out'], 'index.html'))
    with open(os.path.join(graded['out'], 'Cy Bytes', MEASUREMENTS)) as f:  # kept exactly
        assert 'scripts/notes\udcff\udce9.py' in json.load(f)['comments']['files']


def test_students_named_like_outputs_never_take_their_place(graded):
    for name in ('grades_csv', 'index_html', 'hand_csv'):
        assert graded['records'][name]['status'] != rubric.NOT_GRADED, graded['records'][name]['status_reason']
    for output in ('grades.csv', 'index.html', 'hand.csv'):
        assert os.path.isfile(os.path.join(graded['out'], output)), output


def test_a_copy_is_flagged_whatever_data_one_of_them_hands_in(graded):
    similar = graded['similar']
    assert 'error' not in similar, similar.get('error')
    pairs = {(p['a'], p['b']): p for p in similar['pairs']}
    assert ('Dee Copy', 'Eve Original') in pairs, sorted(pairs)
    assert pairs[('Dee Copy', 'Eve Original')]['score_b'] >= 0.9  # all of Eve's code is in Dee's
    cut = [line for line in similar['notes'] if line.startswith('Dee Copy: ')]
    assert cut and ('left out (at most %d files and %d bytes of a student)'
                    % (similarity.MAX_STUDENT_FILES, similarity.MAX_STUDENT_BYTES)) in cut[0], similar['notes']


def test_a_cap_hit_reads_as_a_sentence_and_the_student_is_graded_on_what_fits(graded):
    fay = graded['records']['Fay Many']
    assert fay['status'] != rubric.NOT_GRADED, fay['status_reason']
    assert 'no script of the package starts a ROS node' in fay['status_reason'], fay['status_reason']
    assert '501 Python files (at most 500): the first 500 are read for comments' in fay['for_the_teacher']
    assert 'Traceback' not in fay['status_reason'] and 'File "' not in fay['status_reason']


def test_a_student_over_an_upload_s_bounds_is_left_out_alone(graded):
    gus = graded['records']['Gus Deep']
    assert gus['status'] == rubric.NOT_GRADED, gus['status_reason']
    assert 'folders more than %d deep' % staging.UPLOAD_DEPTH in gus['status_reason'], gus['status_reason']
    assert [line for line in graded['similar']['notes'] if line.startswith('Gus Deep: not compared')]


def test_the_class_zip_is_staged_by_a_class_s_bounds(graded):
    """A class of 60 with its PDFs is larger than one upload may be (256 MB): its zip is staged for
    the intake by the class's bounds."""
    assert [bounds for source, bounds in graded['staged'] if source == graded['class']] == \
        [(classlist.CLASS_BYTES, 1)] * 2  # the grading's intake and the similarity check's

"""make rescore: today's rubric on the measurements a run kept (issue 29 point 2), no ROS, no box."""
import json

from exam_lab.grader import class_run, runner
from exam_lab.grader.publish import grades
from exam_lab.grader.score.records import MEASUREMENTS
from exam_lab.grader.score import flight

from test_grader_kept import kept_copy


def late_measurements():
    """A real grading's measurements (good_student, version 1), its main run's second WARNING (and the
    drone's answer to it) 0.5 s later: 5.40 s after the node's own value stayed above, inside the
    rubric's window, 0.10 s outside a window of the delay +-0.3 s."""
    late = kept_copy('version-1')
    probe = late['session']['runs'][0]['probe']
    warning = [call for call in probe['calls'] if call[1] == 'WARNING'][1]
    answer = [a for a in probe['answers'] if a[:2] == warning][0]
    warning[0] = answer[0] = warning[0] + 0.5
    return dict(late, student='late')


def test_rescore_applies_todays_rubric_to_the_kept_measurements(tmp_path, monkeypatch):
    """Two students' measurements (real ones, as a run keeps them): no change with the same rubric; a
    tighter WARNING window moves the late student's Q14b only, with its previous points kept."""
    for name, kept in (('on_time', dict(kept_copy('version-1'), student='on_time')), ('late', late_measurements())):
        folder = tmp_path / name
        folder.mkdir()
        (folder / MEASUREMENTS).write_text(json.dumps(kept))
        (folder / 'grade.json').write_text(json.dumps(grades.score(kept)))
    records, changes = grades.rescore(str(tmp_path))
    assert changes == [] and [r['total'] for r in records] == [17.0, 17.0]
    monkeypatch.setattr(flight, 'warning_window', lambda probe: (probe.delay - 0.3, probe.delay + 0.3))
    records, changes = grades.rescore(str(tmp_path))
    assert changes == ['late: 17 -> 15.5 (Q14b 3 -> 1.5)']  # the delay's 1.5 of 14b
    late_record = json.loads((tmp_path / 'late' / 'grade.json').read_text())
    assert late_record['previous']['items']['Q14b'] == 3.0 and late_record['provenance']['how'] == 'rescore'
    assert late_record['provenance']['rubric'] and late_record['provenance']['grader']
    assert (tmp_path / 'grades.csv').is_file()
    grade_md = (tmp_path / 'late' / 'grade.md').read_text()
    assert 'Rescored by the grader' in grade_md and 'Before: 17 / 17 (graded)' in grade_md


def test_a_student_the_grader_could_not_grade_keeps_its_participant(tmp_path, monkeypatch):
    """Its hand.csv row and worksheet row are keyed by the participant number like everyone's."""
    def fails(*args, **kwargs):
        raise RuntimeError('a grader bug')
    monkeypatch.setattr(runner, 'grade_submission', fails)
    record = class_run.grade_student('Jane Doe', str(tmp_path / 'Jane Doe._1001_assignsubmission_file_'), str(tmp_path))
    assert record['status'] == 'not graded' and 'a grader bug' in ' '.join(record['for_the_teacher'])
    assert (record['participant'], record['folder']) == (1001, 'Jane Doe._1001_assignsubmission_file_')
    assert json.loads((tmp_path / 'Jane Doe' / 'grade.json').read_text())['participant'] == 1001


def test_every_similarity_json_the_class_run_writes_is_read_back_as_its_record(tmp_path, monkeypatch):
    """Issue 37 point 1: a check that could not run left ``{"error"}`` without the record's ``notes``,
    which make rescore (reading it as a SimilarityRecord) refused. Each file written now is one, a
    failure's words cut to the record's length and made safe as the record makes them."""
    import os
    from exam_lab.grader.boxed import archives
    from exam_lab.grader.score.records import SimilarityRecord
    errors = []
    for why in ('the archive failed on \x1b]0;owned\x07 entry 3', 'a failure ' + 'x' * 30000 + ' at its end'):
        def fails(*args, **kwargs):
            raise archives.UnpackError(why)
        monkeypatch.setattr(class_run, 'class_students', fails)
        result = class_run.class_similarity(str(tmp_path / 'class.zip'), str(tmp_path), [])
        kept = SimilarityRecord.read(str(tmp_path / 'similarity.json'))
        assert isinstance(result, SimilarityRecord) and kept == result and kept.notes == ()
        assert not [n for n in os.listdir(str(tmp_path)) if n.endswith('.part')]
        errors.append(kept.error)
    assert errors[0] == 'the archive failed on  entry 3'
    assert len(kept.error) == SimilarityRecord.SCHEMA['error'].schema.limit and kept.error.endswith('x at its end')


def test_make_rescore_reads_each_kept_report_as_its_record_never_the_box(tmp_path, monkeypatch, capsys):
    """Each student's report.json is read back through ReportRecord (capped, checked); one not read, or
    a garbled one, is said by name; the reader's box is never started again (issue 47 point 1)."""
    import os
    import sys
    from exam_lab.grader.host import reports
    from exam_lab.grader.score.records import ReportRecord
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), '..', 'scripts'))
    import rescore
    for name in ('read', 'encrypted', 'garbled', 'none'):
        folder = tmp_path / name
        folder.mkdir()
        kept = dict(kept_copy('version-1'), student=name)
        (folder / MEASUREMENTS).write_text(json.dumps(kept))
        (folder / 'grade.json').write_text(json.dumps(grades.score(kept)))
    page = {'file': 0, 'number': 1, 'source': 'text', 'text': 'rosnode list', 'layout': '', 'confidence': None,
            'unsure': [], 'pictures': 0, 'image': None}
    reports.write(str(tmp_path / 'read'), ReportRecord.make({
        'version': 1, 'state': 'read', 'why': '', 'notes': [], 'seconds': 1.0, 'pages': [page],
        'files': [{'name': 'r.pdf', 'kind': 'pdf', 'converted': False, 'pages': 1, 'note': '', 'state': 'read',
                   'copy': None}]}))
    reports.write(str(tmp_path / 'encrypted'), ReportRecord.not_read("'r.pdf': an encrypted PDF"))
    (tmp_path / 'garbled' / 'report.json').write_text('{"state": "read"}')

    def never(*args, **kwargs):
        raise AssertionError('the reader was run again')
    monkeypatch.setattr(reports, 'read_report', never)
    rescore.main(['--out', str(tmp_path)])
    lines = [line.strip() for line in capsys.readouterr().out.splitlines() if line.strip().startswith('report of')]
    assert lines[0] == "report of encrypted not read: 'r.pdf': an encrypted PDF"
    assert lines[1].startswith('report of garbled not read: the kept report.json is not a record of the grader: ')
    assert lines[2].startswith('report of none not read: no report.json kept')
    assert len(lines) == 3

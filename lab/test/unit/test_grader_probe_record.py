"""The probe's result and the session's outcome as records: checked where root reads them, their
text made safe once there, a result of another shape the run's crash, a round trip through JSON."""
import dataclasses
import copy
import json
import math
import os

import pytest

from exam_lab.grader import runner
from exam_lab.grader.publish import grades
from exam_lab.grader.host import session
from exam_lab.grader.host import run as host_run
from exam_lab.grader.score import job as job_records, records
from exam_lab.grader.score.inspection import InspectRecord
from exam_lab.grader.score.records import ProbeRecord, RecordError, SessionRecord
from exam_lab.grader.score.schema import plain

from test_grader_kept import kept_copy

#: A real probe's result: the main run of a correct answer (make fairness, 2026-11-26).
REAL = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'data', 'probe-main.json')


def real_probe():
    with open(REAL) as f:
        return json.load(f)


def real_session(probe=None):
    """A session as host.session leaves it: built, the main run measured by ``probe``."""
    return {'outcome': 'ran', 'build': {'status': 0, 'seconds': 3.2, 'tail': 'done', 'timeout': 180.0},
            'launch_check': {'file': 'launch/exam.launch', 'status': 0, 'refused': '', 'warnings': [],
                             'nodes': ['/exam']},
            'runs': [{'tag': 'main', 'probe': probe if probe is not None else real_probe(),
                      'master': {'uid': 60001, 'memory': {'limit': 402653184, 'peak': 31457280, 'oom_kills': 0}},
                      'probe_uid': 60001, 'probe_status': 0, 'seconds': 41.5, 'launch_running': True, 'survivors': 0,
                      'launch': {'ended': [], 'not_started': [], 'tail': 'exam: started'}}],
            'survivors': 0, 'budget_used': None}


def keep_runs(folder, runs, checked=True):
    """The measurements a grading keeps in ``folder`` (what the flight plot draws), whose session
    measured ``runs`` (``[(tag, probe)]``, each probe over the real one), made a SessionRecord as the
    runner does (checked, its text made safe); with ``checked`` False, written as they are (a file as
    another grader, or a hand, left it)."""
    run = real_session()['runs'][0]
    session = dict(real_session(), runs=[dict(run, tag=tag, probe=dict(real_probe(), **probe) if checked else probe)
                                         for tag, probe in runs])
    if checked:
        session = SessionRecord.make(session).value
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, records.MEASUREMENTS), 'w') as f:
        json.dump(dict(kept_copy('version-1'), session=session), f)


def refused(value, record_type=ProbeRecord):
    with pytest.raises(RecordError) as err:
        record_type.make(value)
    return str(err.value)


def test_a_real_probes_result_is_a_record_and_round_trips():
    record = ProbeRecord.make(real_probe())
    assert record.kind == 'main' and record.sheet == 'altitude' and record.value == real_probe()
    again = ProbeRecord.from_json(record.to_json().encode(), ProbeRecord.MAX_BYTES)
    assert again.value == record.value and again.legs == record.legs


def test_a_session_round_trips_with_a_non_finite_value():
    probe = real_probe()
    probe['formula'][0]['published'] = float('nan')
    probe['legs']['rest']['last'] = float('inf')
    record = SessionRecord.make(real_session(probe))
    again = SessionRecord.from_json(record.to_json().encode(), SessionRecord.MAX_BYTES)
    assert again.outcome == 'ran' and again.build == record.build
    got = again.runs[0]['probe']
    assert math.isnan(got['formula'][0]['published']) and got['legs']['rest']['last'] == float('inf')
    assert got['calls'] == record.runs[0]['probe']['calls']


def test_a_hostile_probe_result_is_refused_saying_where_and_why():
    probe = real_probe()
    assert 'probe.json.threshold: a number expected, got str' in refused(dict(probe, threshold='high'))
    assert 'probe.json.threshold: inf is outside' in refused(dict(probe, threshold=float('inf')))
    assert 'probe.json: unexpected key(s) \'extra\'' in refused(dict(probe, extra=1))
    assert 'probe.json.node_watch: an object expected, got str' in refused(dict(probe, node_watch='odd'))
    calls = [[probe['t0'], 'WARNING']] * (records.MAX_CALLS + 1)
    assert 'probe.json.calls: %d calls (at most %d)' % (len(calls), records.MAX_CALLS) in refused(dict(probe, calls=calls))
    assert 'a list of 2 items expected' in refused(dict(probe, calls=[[probe['t0'], 'WARNING', 'more']]))
    graph = {'/n%d' % i: {'publishes': [], 'subscribes': [], 'services': []} for i in range(records.MAX_ITEMS + 1)}
    assert 'probe.json.graph: %d keys' % len(graph) in refused(dict(probe, graph=graph))
    legs = copy.deepcopy(probe['legs'])
    legs['rest']['why'] = 'a key the probe never writes'
    assert "probe.json.legs['rest']: unexpected key(s) 'why'" in refused(dict(probe, legs=legs))


def test_the_drones_answer_may_quote_the_longest_request():
    probe = real_probe()
    request = '\x07' * records.MAX_REQUEST
    answer = 'refused status %r: accepted values are WARNING, NORMAL; alarm LED stays GREEN' % request
    record = ProbeRecord.make(dict(probe, calls=[[probe['t0'], request]], answers=[[probe['t0'], request, False, answer]]))
    assert record.calls == [[probe['t0'], '']] and record.answers[0][3].startswith("refused status '\\x07\\x07")
    assert 'calls[0][1]: a string of %d characters' % (records.MAX_REQUEST + 1) in refused(
        dict(probe, calls=[[probe['t0'], request + 'x']]))


def test_a_students_control_characters_are_gone_once_the_record_is_made():
    probe = real_probe()
    probe['calls'] = [[probe['t0'] + 1, '"WARNING"\x07<b>\x1b[2J']]
    probe['graph'] = {'/exam\x1b]0;owned\x07': {'publishes': [['/alt\x00itude', 'std_msgs/Float32']],
                                                 'subscribes': [], 'services': []}}
    record = ProbeRecord.make(probe)
    assert record.calls == [[probe['t0'] + 1, '"WARNING"<b>']]
    assert record.graph == {'/exam': {'publishes': [['/altitude', 'std_msgs/Float32']], 'subscribes': [], 'services': []}}
    run = dict(real_session()['runs'][0], launch={'ended': [{'node': 'exam\x1b[31m', 'how': 'died', 'detail': ''}],
                                                  'not_started': [], 'tail': 'bell\x07 and \u202eevil'})
    made = SessionRecord.make(dict(real_session(), runs=[run]))
    assert made.runs[0]['launch']['ended'][0]['node'] == 'exam' and made.runs[0]['launch']['tail'] == 'bell and evil'


def test_the_outcome_is_one_of_fixed_values():
    assert 'session.json.outcome: \'exploded\' is not one of ran, ' in refused(dict(real_session(), outcome='exploded'),
                                                                          SessionRecord)
    assert 'session.json: outcome is missing' in refused({k: v for k, v in real_session().items() if k != 'outcome'},
                                                        SessionRecord)
    for outcome in records.OUTCOMES:
        assert grades.no_session(outcome, 'why').outcome == outcome


def write(path, text):
    with open(path, 'w') as f:
        f.write(text)
    return path


def test_the_session_takes_a_probe_result_that_is_not_one_for_the_runs_crash(tmp_path):
    good = write(str(tmp_path / 'good.json'), json.dumps(real_probe()))
    value, why = host_run.probe_record(good)
    assert value == real_probe() and why is None
    for text, said in (('{"kind": "main"', 'not JSON'), ('[1, 2]', 'an object expected, got list'),
                       (json.dumps(dict(real_probe(), sneaky=True)), "unexpected key(s) 'sneaky'"),
                       (' ' * (ProbeRecord.MAX_BYTES + 1), 'bytes (at most')):
        value, why = host_run.probe_record(write(str(tmp_path / 'bad.json'), text))
        assert value is None and why.startswith("the probe's result was refused (a crash of the run): ")
        assert said in why, why
    os.symlink(good, str(tmp_path / 'link.json'))
    value, why = host_run.probe_record(str(tmp_path / 'link.json'))
    assert value is None and 'a link, not followed' in why


def test_the_runner_reads_the_sessions_record_capped_and_checked(tmp_path):
    log_dir = str(tmp_path)
    write(os.path.join(log_dir, 'session.json'), SessionRecord.make(real_session()).to_json())
    got = runner.session_outcome(log_dir, 0, '', 100.0, 2)
    assert got.outcome == 'ran' and got.survivors == 2 and got.runs[0]['probe'] == real_probe()
    write(os.path.join(log_dir, 'session.json'), json.dumps(dict(real_session(), outcome='fine')))
    got = runner.session_outcome(log_dir, 0, '', 100.0, 0)
    assert got.outcome == 'session_failed' and got.runs == []
    assert got.error.startswith("the session's record was refused: session.json.outcome: 'fine' is not one of")
    os.remove(os.path.join(log_dir, 'session.json'))
    assert runner.session_outcome(log_dir, 0, '', 100.0, 0).error == \
        "the session's record was refused: session.json: missing"
    assert runner.session_outcome(log_dir, None, '', 100.0, 0).outcome == 'session_killed'
    got = runner.session_outcome(log_dir, 1, 'Traceback\nboom\x1b[2J', 100.0, 0)
    assert got.outcome == 'session_failed' and got.error == 'the session failed (exit 1): Traceback\nboom'


def test_a_rescore_reads_back_the_session_record_the_run_kept(tmp_path):
    """measurements.json holds the session's record as the run made it (NaN included); a rescore reads
    it back to the same record and the same grade."""
    probe = real_probe()
    probe['formula'][1]['published'] = float('nan')
    session_ = SessionRecord.make(real_session(probe)).value
    kept = {'version': 1, 'student': 'Ann', 'sheet': 'altitude', 'static': kept_copy('version-1')['static'], 'session': session_,
            'notes': [], 'fixes': [], 'comments': None, 'isolate': True, 'how_run': 'test', 'extra': {'seconds': 40.0}}
    folder = tmp_path / 'Ann'
    folder.mkdir()
    (folder / records.MEASUREMENTS).write_text(json.dumps(kept))
    graded = grades.score(kept)
    (folder / 'grade.json').write_text(json.dumps(graded))
    with open(str(folder / records.MEASUREMENTS), 'rb') as f:
        again = SessionRecord.from_json(json.dumps(json.load(f)['session']).encode(), SessionRecord.MAX_BYTES)
    assert math.isnan(again.runs[0]['probe']['formula'][1]['published'])
    assert again.to_json() == SessionRecord.make(session_).to_json()
    rescored, changes = grades.rescore(str(tmp_path))
    assert changes == [] and [i['points'] for i in rescored[0]['items']] == [i['points'] for i in graded['items']]


def inspected(**change):
    """An inspection's record of a package with a threshold run (the parts plan_job reads)."""
    value = {'uid': 1000, 'refused': None, 'sheet': 'altitude', 'notes': [], 'fixes': [], 'static': None,
             'threshold_value': 1300.0, 'calls_service': True, 'namespace': '/', 'main_launch': 'grader/main.launch',
             'threshold_launch': 'grader/threshold.launch', 'threshold_run_value': 900.0, 'handed_in_launch': None,
             'comments': None, 'facts': {'participant': None, 'folder': 'Ann', 'documents': []}}
    return InspectRecord.make(dict(value, **change))


def test_the_sessions_job_with_its_boxes_is_frozen_and_round_trips(tmp_path):
    """The job as run_session completes it (the boxes, the judges' folders, the twin's box on one run):
    read back equal, each box attached as it was described, nothing of it changeable."""
    from exam_lab.grader.host.sandbox import Box
    box = Box(str(tmp_path), bwrap=True, cpus=1.5)
    box.slot, box.cgroups, box.judge_cgroups = 3, ['/sys/fs/cgroup/x'], {'master': ['/sys/fs/cgroup/m']}
    twin = Box(str(tmp_path), bwrap=True, name='box-twin')
    job = runner.plan_job(inspected())
    runs = [plain(run) for run in job.runs]
    runs[1].update(box=twin.describe(), judge_home=str(tmp_path / 'judge-twin'))
    done = job.replaced(runs=runs, box=box.describe(), judge_home=str(tmp_path / 'judge'), side_by_side=True,
                        workspace='/box/ws', log_dir=str(tmp_path / 'logs'), budget=280.0, student_budget=300.0)
    again = job_records.JobRecord.from_json(done.to_json().encode())
    assert again == done and again.runs[0].box is None and again.runs[1].box.name == 'box-twin'
    attached = Box.attached(done.box_of(done.runs[0]))
    assert (attached.slot, attached.cpus, attached.judge_cgroups) == (3, 1.5, {'master': ['/sys/fs/cgroup/m']})
    assert Box.attached(done.box_of(done.runs[1])).folder == twin.folder
    assert done.judge_home_of(done.runs[1]) == str(tmp_path / 'judge-twin')
    assert done.judge_home_of(done.runs[0]) == str(tmp_path / 'judge')
    with pytest.raises(dataclasses.FrozenInstanceError):
        done.runs[0].plan.threshold = 0.0
    with pytest.raises(TypeError):
        done.box.judge_cgroups['probe'] = ('/elsewhere',)


def test_the_job_and_its_plans_are_records_that_round_trip(tmp_path, capsys):
    """The plan (runner), the job as the session reads it (job.json) and each run's plan as the judge
    reads it (from the same job: JobRecord.plan) are checked records: what the runner made is what they read."""
    job = runner.plan_job(inspected())
    assert isinstance(job, job_records.JobRecord) and [run.tag for run in job.runs] == ['main', 'threshold']
    main, threshold = job.plan('main'), job.plan('threshold')
    assert (main.threshold, threshold.threshold, threshold.margin) == (1300.0, 900.0, 130.0) and main.late_warning > 0
    assert job_records.JobRecord.from_json(job.to_json().encode()) == job
    assert runner.plan_job(inspected(calls_service=False)).runs[0].plan.late_warning == 0.0
    assert runner.plan_job(inspected(main_launch=None, threshold_launch=None, threshold_run_value=None)) is None
    with pytest.raises(RecordError, match='main run, then the threshold run'):
        job.replaced(runs=list(reversed(job.runs)))
    with pytest.raises(RecordError, match='the threshold run with a plan of a main run'):
        job.replaced(runs=[job.runs[0], dataclasses.replace(job.runs[1], plan=job.runs[0].plan)])
    with pytest.raises(RecordError, match='late_warning'):
        job.replaced(runs=[dataclasses.replace(job.runs[0], plan=dataclasses.replace(job.runs[0].plan, late_warning=-1.0)),
                           job.runs[1]])
    with pytest.raises(RecordError, match='no threshold run'):
        runner.plan_job(inspected(threshold_launch=None, threshold_run_value=None)).plan('threshold')
    # The judge's plan is the job's, field for field: what the runner made, nothing added on the way.
    again = job_records.JobRecord.from_json(job.to_json().encode()).plan('threshold')
    assert {key: getattr(again, key) for key in job_records.PLAN} == plain(job.runs[1].plan) and again == job.runs[1].plan
    # The session refuses a job that is not one, naming the field, and writes no record.
    bad = tmp_path / 'job.json'
    bad.write_text(json.dumps(dict(json.loads(job.to_json()), run_timeout='90')))
    assert session.main([str(bad)]) == 1
    assert 'job.json.run_timeout: a number expected' in capsys.readouterr().err

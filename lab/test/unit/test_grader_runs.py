"""score/runs.py: whether a run counts, the rubric's to say from the facts the session recorded (the
probe's result, the wall times of its run, the clock, the master), at grading and again at make rescore."""
import copy
import json
import os

from exam_lab.grader.publish import flightplot, grades
from exam_lab.grader.score import kept, records, rubric, runs

from test_grader_kept import kept_copy
from test_grader_probe_record import real_probe
from test_grader_rubric import STATIC, measured, points

CLEAN_CLOCK = {'use_sim_time': [None, None], 'messages': 0, 'publishers': [], 'ros_time_is_wall': True}


def test_threshold_run_only_after_a_warning_in_the_long_excursion():
    probe = {'schedule': {'long_up': 10.0, 'long_down': 17.5}, 'calls': [[5.0, 'WARNING'], [9.0, 'NORMAL']]}
    assert not runs.warned_in_long_excursion(probe)
    probe['calls'].append([15.0, 'WARNING'])
    assert runs.warned_in_long_excursion(probe)
    assert not runs.warned_in_long_excursion(None)
    assert not runs.warned_in_long_excursion({'calls': [[1.0, 'WARNING']]})


def test_probe_results_must_belong_to_the_run():
    plan = {'kind': 'main', 'delay': 5.0}
    real = {'t0': 100.0, 'schedule': {'rest': 110.0, 'long_up': 120.0, 'long_down': 127.5, 'end': 130.0},
            'clock': {'use_sim_time': [None, None], 'messages': 0, 'publishers': []}}
    assert runs.probe_problem(real, 99.0, 131.0, **plan) is None
    assert 'not within' in runs.probe_problem(real, 200.0, 240.0, **plan)       # an old run's file
    short = dict(real, schedule=dict(real['schedule'], long_down=121.0))
    assert 'less than' in runs.probe_problem(short, 99.0, 131.0, **plan)        # the flight did not last
    assert 'no times' in runs.probe_problem({}, 99.0, 131.0, **plan)


def test_a_run_whose_node_set_the_time_is_refused():
    """/use_sim_time set (before the probe's init or later) or /clock published: refused with the
    reason, whatever the times say; a probe that did not watch is refused too."""
    plan = {'kind': 'main', 'delay': 5.0}
    real = {'t0': 100.0, 'schedule': {'rest': 110.0, 'long_up': 120.0, 'long_down': 127.5, 'end': 130.0},
            'clock': CLEAN_CLOCK}
    assert runs.probe_problem(real, 99.0, 131.0, **plan) is None
    sim = dict(real, clock=dict(CLEAN_CLOCK, use_sim_time=[True, True]))
    assert '/use_sim_time was set' in runs.probe_problem(sim, 99.0, 131.0, **plan)
    late = dict(real, clock=dict(CLEAN_CLOCK, use_sim_time=[None, True]))
    assert '/use_sim_time was set' in runs.probe_problem(late, 99.0, 131.0, **plan)
    ticking = dict(real, clock=dict(CLEAN_CLOCK, messages=40, publishers=['/exam']))
    assert '/clock was published (40 messages by /exam)' in runs.probe_problem(ticking, 99.0, 131.0, **plan)
    unwatched = {k: v for k, v in real.items() if k != 'clock'}
    assert 'did not say' in runs.probe_problem(unwatched, 99.0, 131.0, **plan)


def test_a_run_whose_master_went_over_its_memory_is_refused():
    bounded = {'uid': 62000, 'memory': {'limit': 384 << 20, 'peak': 80 << 20, 'oom_kills': 0}}
    assert runs.master_problem(bounded, died=False) is None
    flooded = {'uid': 62000, 'memory': {'limit': 384 << 20, 'peak': 384 << 20, 'oom_kills': 1}}
    assert 'over its memory bound of 384 MB' in runs.master_problem(flooded, died=True)
    assert 'ended during the run' in runs.master_problem({'uid': 62000, 'memory': None}, died=True)


def test_a_refused_run_needs_a_hand_grade_with_its_reason():
    probe = {'nodes': ['/exam'], 'clock': CLEAN_CLOCK}
    measured_ = {'build': {'status': 0, 'tail': ''}, 'runs': [{'tag': 'main', 'probe': probe, 'launch': {}}]}
    assert rubric.status({}, measured_)[0] == rubric.GRADED
    refused = {'build': {'status': 0, 'tail': ''},
               'runs': [{'tag': 'main', 'probe': None, 'launch': {}, 'probe_error': 'result refused: x',
                         'probe_refused': '/clock was published (40 messages by /exam): grade it by hand'}]}
    status, reason = rubric.status({}, refused)
    assert status == rubric.HAND_GRADE
    assert reason.startswith('the main run was not measured: /clock was published'), reason


def test_a_refused_result_is_kept_for_the_plot_not_for_the_rubric():
    run = {'probe': real_probe()}
    runs.refuse(run, 'the master ended')
    assert run['probe'] is None and run['refused_probe'] == real_probe()
    assert run['probe_error'] == 'result refused: the master ended' and run['probe_refused'] == 'the master ended'
    assert runs.watched_deaths(real_probe()) == []


def facts(probe, started, finished, died=False, tag='main'):
    """A run's record as the session leaves it (host.run.run_one): facts only, judged by no one."""
    return {'tag': tag, 'probe': probe, 'probe_wall': [started, finished], 'seconds': finished - started,
            'master': {'uid': 62000, 'memory': {'limit': 384 << 20, 'peak': 80 << 20, 'oom_kills': 0}, 'died': died},
            'launch': {'ended': [], 'not_started': [], 'tail': ''}}


def test_the_rubric_judges_the_facts_the_session_recorded():
    """The probe's result is judged first, its master then (its problem the one said when both are);
    the run as recorded is not changed, and a judged run judged again stays as it is."""
    probe = real_probe()
    t0, end = probe['t0'], max(probe['schedule'].values())
    inside = facts(probe, t0 - 0.5, end + 2.0)
    assert runs.judged_run(inside)['probe'] == probe and 'probe_refused' not in runs.judged_run(inside)
    stale = facts(probe, t0 + 600.0, end + 660.0)
    judged = runs.judged_run(stale)
    assert judged['probe'] is None and judged['refused_probe'] == probe
    assert judged['probe_refused'].startswith('the probe\'s times (%.1f to ' % t0), judged['probe_refused']
    assert judged['probe_error'] == 'result refused: %s' % judged['probe_refused']
    assert stale['probe'] == probe and 'probe_wall' in stale  # the record as kept
    assert runs.judged_run(judged) == judged
    both = runs.judged_run(facts(probe, t0 + 600.0, end + 660.0, died=True))
    assert both['probe_refused'] == 'the master the node talks to ended during the run'
    assert both['refused_probe'] == probe
    gone = runs.judged_run(dict(facts(None, t0, end, died=True), probe_error='exit 1; '))
    assert gone['probe_error'] == 'result refused: the master the node talks to ended during the run'
    assert 'refused_probe' not in gone


def test_a_watched_death_costs_what_a_death_costs():
    """The rubric puts the watch's deaths with roslaunch's: runs loses its point, the node "died". A
    run kept without its facts (``probe_wall``) was judged by its session, the deaths put there already:
    they are counted as kept."""
    session_ = measured()
    probe = session_['runs'][0]['probe']
    probe['node_watch'] = {'deaths': [{'node': '/chatter', 't': 12.0,
                                       'detail': 'started again during the run (pid 11, then 12)'}], 'nodes': []}
    probe['clock'] = CLEAN_CLOCK
    assert points(session_)['runs'] == 2.0  # as judged by its session: the attack's 2/2 then
    session_['runs'][0]['probe_wall'] = [-10.0, 100.0]  # the session's facts: the rubric judges them
    assert points(session_)['runs'] == 1.0
    evidence = [i for i in rubric.score('altitude', STATIC, session_) if i['id'] == 'runs'][0]['evidence']
    assert 'node /chatter died (seen by the judge: started again during the run (pid 11, then 12))' in evidence
    status, reason = rubric.status(STATIC, session_)
    assert status == rubric.HAND_GRADE and 'died' in reason, reason
    assert session_['runs'][0]['launch']['ended'] == []  # the session's record as it was
    # A watch of another shape never reaches the deaths: the probe's record refuses it (test_grader_probe_record).


def kept_run(folder, walls, grade):
    """A student's folder holding measurements.json as today's grader keeps them (a real grading's:
    good_student), each run with the wall times ``walls[tag]`` ``(started, finished)`` of its probe as
    offsets from its own t0 and end, and ``grade`` as its grade.json."""
    measured_ = dict(kept_copy('before-version'), version=kept.VERSION, student=os.path.basename(folder))
    for run in measured_['session']['runs']:
        probe = run['probe']
        start, finish = walls[run['tag']]
        run['probe_wall'] = [probe['t0'] + start, max(probe['schedule'].values()) + finish]
        run['master']['died'] = False
    os.makedirs(folder)
    record = kept.MeasurementsRecord.make(measured_)  # the shape the runner keeps: checked as it does
    with open(os.path.join(folder, records.MEASUREMENTS), 'w') as f:
        f.write(record.to_json())
    with open(os.path.join(folder, 'grade.json'), 'w') as f:
        json.dump(dict(grade, student=os.path.basename(folder)), f)


def test_make_rescore_judges_the_runs_again(tmp_path, monkeypatch):
    """Two kept gradings of one node, both graded 17/17 (graded): the one whose probe's times lie in
    its run counts again; the one whose main run's result lies 10 minutes after its run (a stale
    file) is refused by the rubric at rescore, with the reason, its flight still drawn. A rule changed
    since (a longer delay than the 7 s flown) is applied to the kept runs by the next rescore."""
    inside = {'main': (-0.5, 2.0), 'threshold': (-0.5, 2.0)}
    graded = grades.score(dict(kept_copy('before-version'), version=kept.VERSION))
    assert (graded['total'], graded['status']) == (17.0, rubric.GRADED)
    kept_run(str(tmp_path / 'on_time'), inside, graded)
    kept_run(str(tmp_path / 'stale'), dict(inside, main=(600.0, 660.0)), graded)
    graded_now, changes = grades.rescore(str(tmp_path))
    stale = [r for r in graded_now if r['student'] == 'stale'][0]
    on_time = [r for r in graded_now if r['student'] == 'on_time'][0]
    assert (on_time['total'], on_time['status']) == (17.0, rubric.GRADED)
    assert stale['status'] == rubric.HAND_GRADE
    assert stale['status_reason'].startswith('the main run was not measured: the probe\'s times ('), stale['status_reason']
    assert 'are not within its run' in stale['status_reason']
    assert any(d.startswith('main run: result refused: the probe\'s times') for d in stale['doubts']), stale['doubts']
    assert [line.split(':')[0] for line in changes] == ['stale'] and 'status graded -> needs a hand grade' in changes[0]
    assert [tag for tag, _ in flightplot.load_runs(str(tmp_path / 'stale'))] == ['main', 'threshold']
    monkeypatch.setattr(runs, 'DELAY', 7.5)
    graded_now, changes = grades.rescore(str(tmp_path))
    on_time = [r for r in graded_now if r['student'] == 'on_time'][0]
    assert on_time['status'] == rubric.HAND_GRADE
    assert 'the long excursion lasted 7.0 s, less than the 7.5 s delay' in on_time['status_reason']


def test_a_run_judged_by_its_session_rescores_to_the_grade_it_had(tmp_path):
    """measurements.json kept by the grader of before (its session judged the runs: a refused result
    as ``refused_probe``, why as ``probe_refused``, the watch's deaths in roslaunch's): the rubric reads
    the verdict as kept, the rescore gives the grade it had."""
    measured_ = dict(kept_copy('before-version'), version=kept.VERSION, student='refused')
    main = measured_['session']['runs'][0]
    main['refused_probe'], main['probe'] = main['probe'], None
    main['probe_refused'] = '/clock was published (40 messages by /exam): grade it by hand'
    main['probe_error'] = 'result refused: %s' % main['probe_refused']
    session_ = copy.deepcopy(measured_['session'])
    assert runs.judged(session_) == measured_['session']
    folder = tmp_path / 'refused'
    grades.keep_and_score(str(folder), measured_)
    before = json.loads((folder / 'grade.json').read_text())
    assert before['status'] == rubric.HAND_GRADE
    assert before['status_reason'] == 'the main run was not measured: %s' % main['probe_refused']
    graded_now, changes = grades.rescore(str(tmp_path))
    assert changes == [] and graded_now[0]['total'] == before['total']
    assert graded_now[0]['status_reason'] == before['status_reason']

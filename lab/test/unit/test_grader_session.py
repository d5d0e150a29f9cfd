"""What the session reads in roslaunch's output, and when it runs the threshold check."""
from exam_lab.grader.host import run as host_run

DIED = ('\x1b[1mprocess[exam-1]: started with pid [17908]\x1b[0m\n'
        'Traceback (most recent call last):\n'
        '  File "/tmp/w/ws/src/exam/scripts/exam_node.py", line 26, in <module>\n'
        "KeyError: '~threshold'\n"
        '\x1b[31m================REQUIRED process [exam-1] has died!\n'
        'process has died [pid 17908, exit code 1, cmd /tmp/w/ws/devel/lib/exam/exam_node.py].\n'
        'Initiating shutdown!\n==========\x1b[0m\n[exam-1] killing on exit\n')


def test_a_required_node_that_died():
    outcome = host_run.launch_outcome(DIED, '/tmp/w/ws')
    assert outcome['ended'] == [{'node': 'exam-1', 'how': 'died', 'detail': 'exit code 1'}]
    assert 'exam/scripts/exam_node.py' in outcome['tail'] and '/tmp/w' not in outcome['tail']
    assert 'killing on exit' not in outcome['tail'] and '\x1b' not in outcome['tail']


def test_a_plain_node_that_finished_and_one_not_found():
    text = ('[exam-2] process has finished cleanly\n'
            'ERROR: cannot launch node of type [exam/exam_nod.py]: Cannot locate node of type [exam_nod.py]\n')
    outcome = host_run.launch_outcome(text)
    assert outcome['ended'] == [{'node': 'exam-2', 'how': 'finished cleanly', 'detail': ''}]
    assert outcome['not_started'][0].startswith('ERROR: cannot launch node')
    assert host_run.launch_outcome('[exam-1] killing on exit\n')['ended'] == []


def test_threshold_run_only_after_a_warning_in_the_long_excursion():
    probe = {'schedule': {'long_up': 10.0, 'long_down': 17.5}, 'calls': [[5.0, 'WARNING'], [9.0, 'NORMAL']]}
    assert not host_run.warned_in_long_excursion(probe)
    probe['calls'].append([15.0, 'WARNING'])
    assert host_run.warned_in_long_excursion(probe)
    assert not host_run.warned_in_long_excursion(None)
    assert not host_run.warned_in_long_excursion({'calls': [[1.0, 'WARNING']]})


def test_sheet_detection(tmp_path):
    from exam_lab.grader import runner
    from exam_lab.grader.boxed import derive, inspect, launch
    pkg = tmp_path / 'exam'
    (pkg / 'launch').mkdir(parents=True)
    (pkg / 'package.xml').write_text('<package><name>exam</name><depend>mydrone</depend>'
                                     '<depend>submarinedrone</depend></package>')
    assert inspect.detect_sheet('depth', str(pkg), [])[0] == 'depth'
    assert inspect.detect_sheet(None, str(pkg), [])[0] == 'altitude'
    assert 'SHEET=depth' in inspect.detect_sheet(None, str(pkg), [])[1], 'an ambiguous package says how to choose'
    (pkg / 'launch' / 'exam.launch').write_text('<launch><node pkg="submarinedrone" type="submarine_drone_node.py" '
                                                'name="d"/><node pkg="exam" type="n.py" name="exam"/></launch>')
    analyses = [launch.analyse(p, str(pkg)) for p in derive.launch_files(str(pkg))]
    assert inspect.detect_sheet(None, str(pkg), analyses)[0] == 'depth'
    (pkg / 'package.xml').write_text('<package><name>exam</name><exec_depend>mydrone</exec_depend></package>')
    assert inspect.detect_sheet(None, str(pkg), analyses)[0] == 'altitude', 'package.xml first'
    assert runner.margin_of(1300.0) == 130.0 and runner.margin_of(50.0) == 10.0


CLEAN_CLOCK = {'use_sim_time': [None, None], 'messages': 0, 'publishers': [], 'ros_time_is_wall': True}


def test_a_run_whose_node_set_the_time_is_refused():
    """/use_sim_time set (before the probe's init or later) or /clock published: refused with the
    reason, whatever the times say; a probe that did not watch is refused too."""
    plan = {'kind': 'main', 'delay': 5.0}
    real = {'t0': 100.0, 'schedule': {'rest': 110.0, 'long_up': 120.0, 'long_down': 127.5, 'end': 130.0},
            'clock': CLEAN_CLOCK}
    assert host_run.probe_problem(real, 99.0, 131.0, **plan) is None
    sim = dict(real, clock=dict(CLEAN_CLOCK, use_sim_time=[True, True]))
    assert '/use_sim_time was set' in host_run.probe_problem(sim, 99.0, 131.0, **plan)
    late = dict(real, clock=dict(CLEAN_CLOCK, use_sim_time=[None, True]))
    assert '/use_sim_time was set' in host_run.probe_problem(late, 99.0, 131.0, **plan)
    ticking = dict(real, clock=dict(CLEAN_CLOCK, messages=40, publishers=['/exam']))
    assert '/clock was published (40 messages by /exam)' in host_run.probe_problem(ticking, 99.0, 131.0, **plan)
    unwatched = {k: v for k, v in real.items() if k != 'clock'}
    assert 'did not say' in host_run.probe_problem(unwatched, 99.0, 131.0, **plan)


def test_a_run_whose_master_went_over_its_memory_is_refused():
    bounded = {'uid': 62000, 'memory': {'limit': 384 << 20, 'peak': 80 << 20, 'oom_kills': 0}}
    assert host_run.master_problem(bounded, died=False) is None
    flooded = {'uid': 62000, 'memory': {'limit': 384 << 20, 'peak': 384 << 20, 'oom_kills': 1}}
    assert 'over its memory bound of 384 MB' in host_run.master_problem(flooded, died=True)
    assert 'ended during the run' in host_run.master_problem({'uid': 62000, 'memory': None}, died=True)


def test_a_refused_run_needs_a_hand_grade_with_its_reason():
    from exam_lab.grader.score import rubric
    probe = {'nodes': ['/exam'], 'clock': CLEAN_CLOCK}
    measured = {'build': {'status': 0, 'tail': ''}, 'runs': [{'tag': 'main', 'probe': probe, 'launch': {}}]}
    assert rubric.status({}, measured)[0] == rubric.GRADED
    refused = {'build': {'status': 0, 'tail': ''},
               'runs': [{'tag': 'main', 'probe': None, 'launch': {}, 'probe_error': 'result refused: x',
                         'probe_refused': '/clock was published (40 messages by /exam): grade it by hand'}]}
    status, reason = rubric.status({}, refused)
    assert status == rubric.HAND_GRADE
    assert reason.startswith('the main run was not measured: /clock was published'), reason

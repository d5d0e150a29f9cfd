"""Issue 36 points 4 and 6 without ROS: roslaunch's verdict where the student cannot reach it, a death
the judge sees itself (the probe's NodeWatch), one budget for a student's whole grading."""
import math
import os

from exam_lab.grader import class_run, runner
from exam_lab.grader.publish import teacher
from exam_lab.grader.host import session
from exam_lab.grader.host import run as host_run
from exam_lab.grader.judge.graph import NodeWatch
from exam_lab.grader.score import rubric

from test_grader_desk import Clock
from test_grader_rubric import STATIC, measured
from test_grader_third_class import _Here

DUP = ('<launch><node pkg="mydrone" name="exam" type="mydrone_node.py"/>'
       '<node pkg="exam" name="exam" type="exam_node.py"/></launch>')


def refused_workspace(tmp_path):
    """A workspace whose launch file roslaunch refuses (two nodes named /exam)."""
    launch = tmp_path / 'src' / 'exam' / 'launch'
    launch.mkdir(parents=True)
    (launch / 'exam.launch').write_text(DUP)
    return {'workspace': str(tmp_path), 'handed_in_launch': 'exam/launch/exam.launch'}


def test_an_environment_hook_cannot_answer_for_roslaunch(tmp_path):
    """The student's devel/setup.bash (where catkin sources every package's env hooks) is never
    sourced for the verdict: a hook that says "/exam" and exits changes nothing."""
    job = refused_workspace(tmp_path)
    (tmp_path / 'devel' / 'etc' / 'catkin' / 'profile.d').mkdir(parents=True)
    (tmp_path / 'devel' / 'setup.bash').write_text('echo /exam; exit 0\n')
    verdict = session.launch_verdict(_Here(), _Here(), dict(os.environ), **job)
    assert verdict['status'] == 1 and 'multiple nodes named [/exam]' in verdict['refused'], verdict


def test_a_module_left_in_the_workspace_cannot_answer_for_roslaunch(tmp_path):
    """A ``roslaunch`` package the build left at the workspace's root (where the box's steps start) is
    not what the check imports: it runs from the box's fresh HOME."""
    job = refused_workspace(tmp_path)
    fake = tmp_path / 'roslaunch'
    fake.mkdir()
    (fake / '__init__.py').write_text('')
    (fake / 'config.py').write_text('import sys\ndef load_config_default(*a, **k):\n    print("/exam")\n'
                                    '    sys.exit(0)\n')
    here = _Here()
    here.home = str(tmp_path / 'home')
    os.mkdir(here.home)
    here.workspace = str(tmp_path)
    (tmp_path / 'devel').mkdir()
    (tmp_path / 'devel' / 'setup.bash').write_text('true\n')
    verdict = session.launch_verdict(here, here, dict(os.environ), **job)
    assert verdict['status'] == 1 and 'multiple nodes named [/exam]' in verdict['refused'], verdict


class Scripted(object):
    """The master and the nodes as a NodeWatch sees them, changed by the test between looks."""

    def __init__(self):
        self.running = {}   # name -> (uri, pid); pid None: the process is gone, its registration left
        self.slow = set()

    def names(self):
        return list(self.running)

    def lookup(self, name):
        return self.running[name][0] if name in self.running else None

    def pid_of(self, uri):
        for name, (known, pid) in self.running.items():
            if known == uri:
                if name in self.slow:
                    raise OSError('timed out')
                if pid is None:
                    raise ConnectionRefusedError(uri)
                return pid
        raise ConnectionRefusedError(uri)


def watch_of(world):
    return NodeWatch(world.names, world.lookup, world.pid_of, clock=lambda: 5.0)


def test_a_node_started_again_is_a_death_the_judge_sees():
    world = Scripted()
    watch = watch_of(world)
    watch.look()  # nothing registered yet: nothing to see
    world.running = {'/exam': ('http://a:1/', 10), '/chatter': ('http://a:2/', 11)}
    watch.look()
    world.running['/chatter'] = ('http://a:3/', 12)  # roslaunch's respawn: a new process, a new URI
    watch.look()
    world.running['/exam'] = ('http://a:1/', 13)     # the same URI (a fixed port), a new pid
    watch.look()
    seen = watch.stop()
    assert [(d['node'], d['detail']) for d in seen['deaths']] == [
        ('/chatter', 'started again during the run (pid 11, then 12)'),
        ('/exam', 'started again during the run (pid 10, then 13)')]


def test_a_node_gone_or_unreachable_is_a_death_a_slow_one_is_not():
    world = Scripted()
    watch = watch_of(world)
    world.running = {'/exam': ('http://a:1/', 10), '/helper': ('http://a:2/', 11), '/slow': ('http://a:3/', 12)}
    watch.look()
    world.slow.add('/slow')                       # its getPid times out: busy, not dead
    world.running['/helper'] = ('http://a:2/', None)   # killed: its registration stays, nothing listens
    del world.running['/exam']                    # unregistered: ended
    watch.look()
    watch.look()                                  # still gone: counted once
    world.running['/exam'] = ('http://a:4/', 14)  # back: the same death, said so
    watch.look()
    deaths = {d['node']: d['detail'] for d in watch.stop()['deaths']}
    assert deaths == {'/exam': 'ended during the run (pid 10), then started again (pid 14)',
                      '/helper': 'ended during the run (pid 11)'}


def test_each_step_gets_its_own_limit_or_what_is_left():
    clock = Clock()
    budget = host_run.Budget(120.0, 270.0, clock=clock)
    assert budget.limit(180.0, 5.0) == (115.0, True) and budget.limit(30.0, 5.0) == (30.0, False)
    clock.now += 100.0
    assert budget.left() == 20.0 and budget.left(30.0) == 0.0
    first = budget.spend('catkin_make was stopped after 115 s, nothing was run')
    budget.spend('the main run was not started')
    assert budget.used == first and 'budget of 270 s' in first and first.endswith('nothing was run')


def test_a_used_budget_is_on_the_students_row():
    session_ = measured()
    session_['build'] = {'status': None, 'seconds': 115.0, 'tail': '', 'timeout': 115.0,
                         'stopped': host_run.budget_sentence(270.0, 'catkin_make was stopped after 115 s')}
    session_['runs'], session_['budget_used'] = [], session_['build']['stopped']
    status, reason = rubric.status(STATIC, session_)
    assert status == rubric.HAND_GRADE and reason.startswith('its grading used up its budget of 270 s'), reason
    runs = [i for i in rubric.score('altitude', STATIC, session_) if i['id'] == 'runs'][0]
    assert runs['points'] == 0 and 'budget of 270 s' in runs['evidence']
    hints = teacher.hints(STATIC, session_, [], None, True)
    assert session_['budget_used'] in hints


def test_a_class_of_60_at_the_default_jobs_ends_within_75_minutes():
    """Every student at its budget: ceil(60 / JOBS) gradings in sequence, each at most its budget and
    what follows it."""
    jobs = class_run.default_jobs(cores=2, memory=64 << 30)
    assert jobs == 4
    assert class_run.worst_case(60, jobs) <= 75 * 60
    assert class_run.worst_case(60, jobs) == math.ceil(60 / 4) * (runner.STUDENT_BUDGET + runner.AFTER_BUDGET_S)

"""One mistake, one loss; evidence never false; a status for every student. The rubric, the probe's
leg check and the status on synthetic measurements (the stale-reading case included)."""
import importlib.util
import os

import pytest

from exam_lab.grader.boxed import derive, launch, source

from exam_lab.grader.judge import legs, pilot

from exam_lab.grader.score import flight, records, rubric, runs, tolerances, verdict
from exam_lab.grader.score.job import PLAN, Plan

from exam_lab.grader.publish import report

from test_grader_rubric import STATIC, SCHEDULE, flown, lost, measured, points


def main_of(session_record):
    return session_record['runs'][0]['probe']


def with_legs(session_record, reached=None, values=None):
    """The main run's legs as the probe checks them: each reached 0.1 s after its input changed,
    unless ``reached`` says otherwise (None: never reached)."""
    reached = reached or {}
    legs = {}
    for name in ('rest', 'short_up', 'short_down', 'long_up', 'long_down'):
        side = 'above' if name.endswith('up') else 'below'
        at = reached.get(name, SCHEDULE[name] + 0.1)
        first = (values or {}).get(name, 1430.0 if side == 'above' else 1170.0)
        legs[name] = {'side': side, 'reached': at, 'off_side': 0, 'first': first, 'last': first, 'samples': 30}
    main_of(session_record)['legs'] = legs
    main_of(session_record)['threshold'] = 1300.0
    return session_record


def test_the_stale_reading_leg_is_not_reached():
    """A node blocked 5 s in a callback keeps publishing 1040 m while the grader flies it "above":
    the leg is not reached, and nothing is judged on it."""
    samples = [(10.0 + 0.1 * i, 1040.0) for i in range(75)]  # the whole long excursion, stale
    leg = legs.leg_check(samples, 1300.0, 'above', 10.0, 17.5)
    assert leg['reached'] is None and leg['first'] == 1040.0 and leg['samples'] == 75
    record = with_legs(measured(calls=[[13.0, 'WARNING'], [16.1, 'NORMAL']]), reached={'long_up': None},
                       values={'long_up': 1040.0})
    items = {i['id']: i for i in rubric.score('altitude', STATIC, record)}
    for item_id in ('Q13', 'Q14b'):
        assert items[item_id]['points'] == 0
        assert 'never went above the threshold 1300 (it published 1040.0 to 1040.0)' in items[item_id]['evidence']
        assert 'stayed above' not in items[item_id]['evidence'], 'no false evidence'
    status, reason = rubric.status(STATIC, record)
    assert status == rubric.HAND_GRADE and 'long excursion above' in reason
    assert 'refused' not in reason


def test_an_unreached_leg_names_the_refused_input_the_drone_could_not_speak():
    """/pressure subscribed as a message the drone cannot publish (sensor_msgs/FluidPressure): the node
    never gets it, its value never moves, the legs are not reached: the hand grade says why."""
    record = with_legs(measured(calls=[]), reached={'long_up': None}, values={'long_up': 1040.0})
    record['runs'][0]['probe']['input_types'] = {
        '/pressure': {'type': 'sensor_msgs/FluidPressure', 'connected': False, 'adapted': None,
                      'refused': 'rospy refused the connection: the node asked for sensor_msgs/FluidPressure, '
                                 'the drone publishes std_msgs/Float32'}}
    status, reason = rubric.status(STATIC, record)
    assert status == rubric.HAND_GRADE
    assert 'rospy refused its subscription to /pressure as sensor_msgs/FluidPressure' in reason, reason


def test_a_leg_reached_late_counts_from_the_node_and_says_so():
    samples = [(10.0 + 0.1 * i, 1040.0 if i < 20 else 1430.0) for i in range(75)]
    leg = legs.leg_check(samples + [(17.6, 1040.0)], 1300.0, 'above', 10.0, 17.5)
    assert leg['reached'] == pytest.approx(12.0) and leg['off_side'] == 0 and leg['first'] == 1040.0
    leg = legs.leg_check(samples + [(17.4, 1040.0)], 1300.0, 'above', 10.0, 17.5)
    assert leg['off_side'] == 1
    assert not legs.on_side(float('nan'), 1300.0, 'below') and legs.on_side(1300.0, 1300.0, 'below')


def test_legs_reached_change_nothing_for_a_good_node():
    assert lost(with_legs(measured())) == {}
    assert rubric.status(STATIC, with_legs(measured())) == (rubric.GRADED, '')


def test_a_blocked_node_loses_the_short_excursion_only():
    """sleep(5) in the callback: its own value stays above 2 s after the short excursion; it warns."""
    calls = [[3.0 + 5.0, 'WARNING'], [8.1, 'NORMAL'], [8.5 + 5.0, 'WARNING'], [16.1, 'NORMAL']]
    record = with_legs(measured(calls=calls), reached={'short_down': 8.0})
    assert lost(record) == {'Q14b': 1.0}
    q14b = [i for i in rubric.score('altitude', STATIC, record) if i['id'] == 'Q14b'][0]['evidence']
    assert 'stayed above 2.0 s longer' in q14b


def test_a_late_warning_costs_the_delay_only():
    """500 ticks at 10 Hz: the flight waited for the WARNING (50 s), so Q13 and Q14a are judged."""
    schedule = dict(SCHEDULE, long_down=8.5 + 52.5, end=8.5 + 55.0)
    calls = [[8.5 + 50.0, 'WARNING'], [61.05, 'NORMAL']]
    record = measured(calls=calls)
    main_of(record)['schedule'] = schedule
    assert lost(record) == {'Q14b': 1.5}
    q13 = [i for i in rubric.score('altitude', STATIC, record) if i['id'] == 'Q13'][0]['evidence']
    assert 'the WARNING came late, 50.0 s' in q13
    assert runs.warning_latency(main_of(record)) == pytest.approx(50.0)
    assert runs.warning_latency({'schedule': schedule, 'calls': []}) is None


@pytest.mark.parametrize('kind', ['std_msgs/Float64', 'std_msgs/Int32', 'std_msgs/UInt16'])
def test_any_numeric_type_on_the_right_topic(kind):
    record = measured(output=('/altitude', kind))
    assert lost(record) == {}
    q11 = [i for i in rubric.score('altitude', STATIC, record) if i['id'] == 'Q11'][0]['evidence']
    assert '/altitude %s, a numeric type' % kind in q11


def test_a_launch_file_without_a_comment_gets_half():
    static = dict(STATIC, launch=dict(STATIC['launch'], comments=0))
    assert points(measured(), static)['Q12'] == 0.5
    static = dict(STATIC, launch=dict(STATIC['launch'], comments=0, starts_drone=False))
    assert points(measured(), static)['Q12'] == 0.0, 'no drone and no comment: two losses'
    static = dict(STATIC, launch=dict(STATIC['launch'], comments=2, package='exam_pkg'))
    q12 = [i for i in rubric.score('altitude', static, measured()) if i['id'] == 'Q12'][0]
    assert q12['points'] == 1 and 'exam_pkg/exam_node.py' in q12['evidence']


def test_launch_comments_and_a_package_named_otherwise(tmp_path):
    pkg = tmp_path / 'exam_pkg'
    (pkg / 'launch').mkdir(parents=True)
    (pkg / 'launch' / 'a.launch').write_text('<launch><include file="$(find exam_pkg)/launch/b.launch"/>'
                                             '<node pkg="exam_pkg" type="n.py" name="n"><param name="seuil" '
                                             'value="1300"/></node></launch>')
    (pkg / 'launch' / 'b.launch').write_text('<launch><!-- the drone --><node pkg="mydrone" '
                                             'type="mydrone_node.py" name="d"/></launch>')
    analysis = launch.analyse(str(pkg / 'launch' / 'a.launch'), str(pkg), 'exam_pkg')
    assert [n.type for n in analysis.exam_nodes] == ['n.py'] and analysis.starts_drone('altitude')
    assert analysis.comments() == 1
    assert derive.threshold_param(analysis, 'altitude')[0].name == '/n/seuil'
    assert launch.analyse(str(pkg / 'launch' / 'a.launch'), str(pkg)).exam_nodes == []


TRACEBACK = ('[ INFO] started\nTraceback (most recent call last):\n'
             '  File "exam/scripts/exam_node.py", line 26, in <module>\n'
             '    threshold = rospy.get_param("~threshold")\n'
             '  File "/opt/ros/noetic/lib/python3/dist-packages/rospy/client.py", line 467, in get_param\n'
             "KeyError: '~threshold'\n[exam-1] process has died [pid 1, exit code 1]\n")


def test_status_of_each_case():
    fixes = ['scripts/exam_node.py was not executable: made executable']
    assert rubric.status(STATIC, measured(), fixes) == (rubric.GRADED_WITH_FIXES, fixes[0])
    refused = {'build': None, 'runs': [], 'refused': True, 'error': 'submission refused: entry \'../x\' climbs'}
    assert rubric.status({}, refused) == (rubric.NOT_GRADED, "submission refused: entry '../x' climbs")
    failed = {'build': None, 'runs': [], 'error': 'the session did not finish within 540 s'}
    assert rubric.status(STATIC, failed)[0] == rubric.NOT_GRADED
    no_node = {'build': None, 'runs': [], 'no_node': True, 'error': 'no script of the package starts a ROS node'}
    assert rubric.status(STATIC, no_node) == (rubric.HAND_GRADE, 'no script of the package starts a ROS node')
    broken = measured()
    broken['build'] = {'status': 2, 'seconds': 1.0, 'tail': 'make: ***\nCMake Error: no mydrone\n', 'timeout': 180}
    assert rubric.status(STATIC, broken) == (rubric.HAND_GRADE, 'the package does not build: CMake Error: no mydrone')
    crashed = measured(died=True)
    main_of(crashed)['nodes'] = []
    crashed['runs'][0]['launch']['tail'] = TRACEBACK
    assert rubric.status(STATIC, crashed) == (
        rubric.HAND_GRADE, "the node does not start: KeyError: '~threshold' at exam/scripts/exam_node.py:26")
    seen = measured(died=True)  # the probe saw it register before the KeyError (a quiet machine): the same words
    main_of(seen)['nodes'], main_of(seen)['trace'] = ['/exam'], {'published': [], 'oracle': []}
    main_of(seen)['rate'] = {'hz': None, 'samples': 0, 'max_gap': None}
    seen['runs'][0]['launch']['tail'] = TRACEBACK
    assert rubric.status(STATIC, seen) == rubric.status(STATIC, crashed)
    main_of(seen)['trace']['published'] = [[3.0, 1040.0]]  # one value published, then the end: it died
    assert rubric.status(STATIC, seen)[1].startswith("the node died: KeyError: '~threshold'")
    python2 = dict(STATIC, python2=['scripts/exam_node.py:3: print statement'])
    status, reason = rubric.status(python2, crashed)
    assert status == rubric.HAND_GRADE and reason.startswith('Python 2 code (scripts/exam_node.py:3: print statement)')
    assert rubric.status(python2, measured()) == (rubric.GRADED, ''), 'an unused Python 2 file does not stop a node'
    assert set(rubric.STATUSES) == {'graded', 'graded with fixes', 'needs a hand grade', 'not graded'}


def test_crash_summary():
    assert verdict.crash_summary(TRACEBACK) == "KeyError: '~threshold' at exam/scripts/exam_node.py:26"
    syntax = ('  File "exam/scripts/exam_node.py", line 19\n    print "x"\n    ^\n'
              "SyntaxError: Missing parentheses in call to 'print'. Did you mean print(...)?\n")
    assert verdict.crash_summary(syntax).startswith("SyntaxError: Missing parentheses in call to 'print'")
    assert verdict.crash_summary(syntax).endswith('at exam/scripts/exam_node.py:19')
    assert verdict.crash_summary('[ INFO] all good\n') == ''


def test_python2_is_named(tmp_path):
    pkg = tmp_path / 'exam'
    (pkg / 'scripts').mkdir(parents=True)
    (pkg / 'scripts' / 'old.py').write_text('import rospy\nprinter = 1\nprint "hello"\n')
    (pkg / 'scripts' / 'new.py').write_text('print("hello")\nprint\n')
    (pkg / 'scripts' / 'typo.py').write_text('def f(:\n    pass\n')
    (pkg / 'scripts' / 'handler.py').write_text('try:\n    pass\nexcept ValueError, e:\n    pass\n')
    assert source.python2_evidence(str(pkg)) == ['scripts/handler.py:3: "except E, e:"',
                                                 'scripts/old.py:3: print statement']


def test_calls_a_service(tmp_path):
    pkg = tmp_path / 'exam'
    (pkg / 'scripts').mkdir(parents=True)
    (pkg / 'scripts' / 'n.py').write_text('import rospy\n')
    assert not source.calls_a_service(str(pkg))
    (pkg / 'scripts' / 'n.py').write_text('import rospy\nled = rospy.ServiceProxy("w", X)\n')
    assert source.calls_a_service(str(pkg))


def test_reports_say_the_status():
    items = rubric.score('altitude', {}, {'build': None, 'runs': [], 'refused': True, 'error': 'submission refused: x'})
    record = report.grade_record('Ann', 'altitude', items, [], status=rubric.status({}, {'refused': True,
                                                                                      'error': 'refused: x'}))
    text = report.markdown(record)
    assert '**Status: not graded** - refused: x' in text
    assert 'Graded by running the package' not in text and 'launch files: none' not in text
    assert 'no threshold parameter' not in text and 'did not build' not in text
    assert text.count('the upload was refused') == 4 and text.count('the package was not read') == 2
    assert report.needing_the_teacher([record, dict(record, student='Bob', status='graded')]) == [
        'Ann: not graded - refused: x']
    assert record['status'] == 'not graded' and record['status_reason'] == 'refused: x'


def test_jobs_default_from_the_cores_the_memory_and_the_cpu_a_grading_takes():
    """JOBS when the teacher gives none (issue 48 point 3): as many gradings as fill CPU_SHARE of the
    cores at the CPU one grading measured in its wall time, fewer when the memory cannot hold them,
    never 0; a grading that costs twice the CPU halves it."""
    from exam_lab.grader import class_run
    gib = 1 << 30
    assert class_run.default_jobs(cores=2, memory=24 * gib) == 4  # 2 x 0.6 x 50.2 / 13.2 = 4.6
    assert class_run.default_jobs(cores=2, memory=24 * gib, cpu=2 * class_run.GRADING_CPU_S) == 2
    assert class_run.default_jobs(cores=2, memory=24 * gib, cpu=1.0, wall=100.0) == 24  # the memory's 24 GB
    assert class_run.default_jobs(cores=16, memory=8 * gib) == 8
    assert class_run.default_jobs(cores=1, memory=gib // 2) == 1
    assert class_run.default_jobs(cores=1, memory=24 * gib, cpu=100.0, wall=1.0) == 1
    assert class_run.default_jobs() >= 1


def test_grade_refuses_jobs_below_one(capsys):
    path = os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', 'scripts', 'grade.py')
    spec = importlib.util.spec_from_file_location('grade_script', path)
    grade = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(grade)
    with pytest.raises(SystemExit) as stopped:
        grade.main(['--class', '/nonexistent', '--jobs', '0'])
    assert stopped.value.code == 2
    assert '--jobs (JOBS) must be 1 or more, not 0' in capsys.readouterr().err


# --- issue 35: a late NORMAL, and a WARNING at the next reading of the slowest input ------------------

class SyntheticClock(object):
    """The wall clock of the probe and of ``wait_until``, advanced only by their sleeps: a flight of
    100 s runs in a moment, and the same every time."""

    def __init__(self, now=1000.0):
        self.now = now

    def time(self):
        return self.now

    monotonic = time

    def sleep(self, seconds):
        self.now += max(0.0, seconds)


class ScriptedNode(object):
    """A student's node on the synthetic clock: its own value follows the flown value ``lag`` s later,
    published at 10 Hz; at each tick it warns after ``DELAY`` s above, and goes back to NORMAL after
    ``normal_after`` s below (0: at once; None: never)."""

    DELAY = 5.0

    def __init__(self, clock, threshold=1300.0, normal_after=0.0, lag=0.1):
        self.clock, self.threshold, self.normal_after, self.lag = clock, threshold, normal_after, lag
        self.flown = [(clock.now, threshold - 130.0)]
        self.tick = clock.now
        self.above_since = self.below_since = None
        self.warning = False
        self.made = []

    def fly(self, x):
        self.flown.append((self.clock.now, x))
        return self.clock.now

    def value(self, t):
        return [x for at, x in self.flown if at <= t - self.lag][-1] if t - self.lag >= self.flown[0][0] else None

    def samples(self, since, until=None):
        end = min(self.clock.now, until if until is not None else self.clock.now)
        first = self.flown[0][0] + 0.1 * max(0, int((since - self.flown[0][0]) / 0.1))
        out = []
        t = first
        while t <= end + 1e-9:
            v = self.value(t)
            if v is not None and t >= since:
                out.append((t, v))
            t += 0.1
        return out

    def calls(self):
        while self.tick + 0.1 <= self.clock.now:
            self.tick += 0.1
            v = self.value(self.tick)
            if v is None:
                continue
            if v > self.threshold:
                self.below_since = None
                self.above_since = self.tick if self.above_since is None else self.above_since
                if self.tick - self.above_since >= self.DELAY - 1e-9 and not self.warning:
                    self.made.append((self.tick, 'WARNING'))
                    self.warning = True
            else:
                self.above_since = None
                self.below_since = self.tick if self.below_since is None else self.below_since
                if self.warning and self.normal_after is not None and \
                        self.tick - self.below_since >= self.normal_after - 1e-9:
                    self.made.append((self.tick, 'NORMAL'))
                    self.warning = False
        return list(self.made)


def plan(**change):
    """A run's plan as the judge reads it from its job (:meth:`~exam_lab.grader.score.job.JobRecord.plan`):
    the main run's of a 1300 m threshold, checked."""
    value = dict({'kind': 'main', 'sheet': 'altitude', 'threshold': 1300.0, 'margin': 130.0, 'delay': 5.0,
                  'start_timeout': 20.0, 'output': '/altitude', 'late_warning': 60.0}, **change)
    return Plan(**records.check(value, PLAN, 'plan'))


def synthetic_flight(monkeypatch, node, clock, rates, warned_before=False):
    """The probe's flight (pilot.Flight.fly_legs, unchanged) around a scripted node on the synthetic
    clock; ``warned_before``: its value was above for 6 s just before (the calibration's high point),
    so it gave a WARNING there. Returns the main run's session record, scored as the grader does."""
    from exam_lab.harness import wait
    monkeypatch.setattr(pilot, 'time', clock)
    monkeypatch.setattr(wait, 'time', clock)
    drone = type('Drone', (), {'rates': rates, 'service': type('Service', (), {'calls': node.calls})()})()
    graph = type('Graph', (), {'student_nodes': lambda self: ['/exam']})()
    flying = pilot.Flight(plan(), node.fly, node, drone, graph)
    if warned_before:
        node.fly(1430.0)
        clock.sleep(6.0)
        node.fly(1299.9)
        clock.sleep(1.0)
    result = flying.fly_legs(1170.0, 1430.0, 1299.9)
    record = measured(calls=[[t, s] for t, s in node.calls()])
    main = main_of(record)
    main.update(schedule=result['schedule'], legs=result['legs'], threshold=1300.0,
                input_rates=dict(rates))
    main['calibration']['near'] = {'x': 1299.9, 'value': 1299.9, 'target': 1299.9}
    return record


ALTITUDE_RATES = {'temperature': 0.778, 'pressure': 2.0}


def test_a_node_back_to_normal_after_the_delay_loses_at_once_only(monkeypatch):
    """NORMAL only after 5 s below (a time, not a margin): the last leg waits for it, so the node loses
    Q14b's "at once" (0.5) only, not Q13's NORMAL as well."""
    clock = SyntheticClock()
    record = synthetic_flight(monkeypatch, ScriptedNode(clock, normal_after=5.0), clock, ALTITUDE_RATES)
    assert lost(record) == {'Q14b': 0.5}
    q14b = [i for i in rubric.score('altitude', STATIC, record) if i['id'] == 'Q14b'][0]['evidence']
    assert 'it waits for a time, not at once' in q14b and 'margin' not in q14b, q14b
    q13 = [i for i in rubric.score('altitude', STATIC, record) if i['id'] == 'Q13'][0]['evidence']
    assert 'the NORMAL came late, 5.0 s after the value came back below' in q13, q13


def test_a_warning_left_from_the_calibration_does_not_hide_the_flights(monkeypatch):
    """The same node warned during the calibration (its value above for 6 s): the rest waits for its
    NORMAL, so the long excursion sees its WARNING; it loses the 0.5 alone."""
    clock = SyntheticClock()
    node = ScriptedNode(clock, normal_after=5.0)
    record = synthetic_flight(monkeypatch, node, clock, ALTITUDE_RATES, warned_before=True)
    schedule = main_of(record)['schedule']
    assert [s for t, s in node.calls() if t < schedule['short_up']] == ['WARNING', 'NORMAL']
    assert lost(record) == {'Q14b': 0.5}


def test_a_right_node_flies_as_long_as_before_and_the_wait_is_bounded(monkeypatch):
    """A right node (NORMAL at once) owes nothing: no leg waits, whether it warned before or not. One
    that never goes back to NORMAL makes the rest (it warned before) and the last leg wait, each up to
    normal_wait after its own value came back below."""
    rests, lasts = {}, {}
    for name, normal_after, before in (('right', 0.0, False), ('right, warned before', 0.0, True),
                                       ('never', None, False), ('never, warned before', None, True)):
        clock = SyntheticClock()
        record = synthetic_flight(monkeypatch, ScriptedNode(clock, normal_after=normal_after), clock,
                                  ALTITUDE_RATES, warned_before=before)
        schedule = main_of(record)['schedule']
        rests[name] = schedule['short_up'] - schedule['rest']
        lasts[name] = schedule['end'] - schedule['long_down']
        if normal_after == 0.0:
            assert lost(record) == {}, name
        else:
            assert lost(record) == {'Q13': 2.0, 'Q14b': 0.5} or before, name
    wait = legs.normal_wait(5.0, ALTITUDE_RATES)
    assert wait == pytest.approx(5.0 + legs.AFTER_S + 1 / 0.778)
    # (a value already below when the rest begins reaches it at once, not a tick later)
    assert rests['right, warned before'] == pytest.approx(rests['right'], abs=0.15)
    assert rests['never'] == pytest.approx(rests['right'])
    assert lasts['right, warned before'] == pytest.approx(lasts['right'], abs=0.15)
    assert rests['never, warned before'] - rests['right'] == pytest.approx(wait - legs.REST_S, abs=0.15)
    assert lasts['never'] - lasts['right'] == pytest.approx(wait - legs.BACK_S - legs.DEEP_S, abs=0.3)



def test_a_value_is_read_once_it_moved_and_a_stale_one_at_stale_s(monkeypatch):
    """The node's value after an input change (legs.settled, on the synthetic clock): read SETTLE_S
    later; a node that follows late (blocked in a callback) is waited for until its value moved, but no
    longer than STALE_S, and then its stale value is what it published."""
    from exam_lab.harness import wait
    for lag, value, read_after in ((0.1, 1430.0, legs.SETTLE_S), (3.0, 1430.0, 3.1),
                                   (legs.STALE_S + 1.0, 1170.0, legs.STALE_S)):
        clock = SyntheticClock()
        monkeypatch.setattr(legs, 'time', clock)
        monkeypatch.setattr(wait, 'time', clock)
        node = ScriptedNode(clock, lag=lag)
        clock.sleep(lag + 1.0)
        since = node.fly(1430.0)
        got, count = legs.settled(node, since, before=1170.0)
        assert got == value and count > 0, lag
        assert clock.now - since == pytest.approx(read_after, abs=0.11), lag

def test_owes():
    calls = [(1.0, 'WARNING'), (2.0, 'NORMAL'), (3.0, 'WARNING')]
    assert legs.owes(calls, 'below', 0.0) and not legs.owes(calls[:2], 'below', 0.0)
    assert not legs.owes([], 'below', 0.0) and not legs.owes([(1.0, 'whatever')], 'below', 0.0)
    assert legs.owes(calls, 'above', 3.5) and not legs.owes(calls, 'above', 2.5)


def _sheets_drones():
    from exam_lab.harness import fake_drone
    return [(sheet, fake_drone.SHEETS[sheet]['rates']) for sheet in ('altitude', 'depth')]


@pytest.mark.parametrize('sheet, rates', _sheets_drones())
def test_a_warning_at_the_next_reading_of_the_slowest_input_is_on_time(sheet, rates):
    """A node that checks its time stamps at each synchronised pair warns at the first pair at or after
    5 s: up to one period of the slowest input later (c18: 5.98 s on the depth drone's 1 Hz). On time up
    to that and a tick, from the sheet's drone's own rates; the long excursion lasts past it."""
    period = 1.0 / min(rates.values())
    late = 5.0 + max(tolerances.WARNING_LATE_S, period + 1.0 / tolerances.RATE_HZ)
    early = 5.0 - tolerances.WARNING_EARLY_S
    assert late < 5.0 + legs.AFTER_S, 'the long excursion must outlast the window'
    for latency, ok in ((early - 0.01, False), (early + 0.01, True), (5.0 + period - 0.02, True),
                        (late - 0.01, True), (late + 0.01, False)):
        record = flown([[7.6 + latency, 'WARNING'], [14.6 + 0.05, 'NORMAL']])
        main_of(record)['input_rates'] = dict(rates)
        assert lost(record) == ({} if ok else {'Q14b': 1.5}), (sheet, latency)
        assert flight.warning_window(main_of(record)) == pytest.approx((early, late))

"""Issue 48: the two runs of a student side by side, each stage timed by the grading itself. The pure
parts: the threshold run's late wait told by the main run as it flies (MainWord, the pilot's late
bound asked as it goes), the stopwatch, the cgroup's CPU count, two supervisors sharing a log folder.
No ROS master needed."""
import json
import os
import subprocess

from exam_lab.grader import runner
from exam_lab.grader.host import cgroups, side_by_side, timings
from exam_lab.grader.judge import pilot, probe
from exam_lab.grader.score import records
from exam_lab.harness.supervisor import Supervisor, alive
from exam_lab.harness.wait import wait_until

from test_grader_fairness import ALTITUDE_RATES, ScriptedNode, SyntheticClock, plan


def threshold_plan():
    return plan(kind='threshold')


def test_the_threshold_run_waits_as_long_as_the_main_run_says_once_it_says_it(tmp_path):
    """Before the main run's word, a late WARNING is waited for the plan's 60 s; then as long as the
    main run's took (its latency or the delay, and AFTER_S), or not at all when it never warned."""
    word = str(tmp_path / side_by_side.MAIN_WORD)
    told = probe.MainWord(threshold_plan(), word)
    assert told.late_warning() == 60.0
    with open(word, 'w') as f:
        json.dump({'warned': True, 'warn_after': 12.0}, f)
    assert told.late_warning() == 12.0 + 1.5
    for said, bound in (({'warned': True, 'warn_after': 4.6}, 6.5), ({'warned': True, 'warn_after': 90.0}, 60.0),
                        ({'warned': False, 'warn_after': None}, 0.0)):
        with open(word, 'w') as f:
            json.dump(said, f)
        assert probe.MainWord(threshold_plan(), word).late_warning() == bound
    # The main run's latency: the same bound from it (one after the other, the word is there before the run).
    assert probe.late_bound(threshold_plan(), 12.0) == 13.5


def fly_never_warning(monkeypatch, late_warning):
    """The legs flown around a node that never warns (a threshold it does not read), on the synthetic
    clock: the long excursion's length."""
    from exam_lab.harness import wait
    clock = SyntheticClock()
    node = ScriptedNode(clock)
    node.DELAY = 1e9
    monkeypatch.setattr(pilot, 'time', clock)
    monkeypatch.setattr(wait, 'time', clock)
    drone = type('Drone', (), {'rates': ALTITUDE_RATES, 'service': type('Service', (), {'calls': node.calls})()})()
    graph = type('Graph', (), {'student_nodes': lambda self: ['/exam']})()
    flying = pilot.Flight(threshold_plan(), node.fly, node, drone, graph, late_warning(clock))
    schedule = flying.fly_legs(1170.0, 1430.0, 1299.9)['schedule']
    return schedule['long_down'] - schedule['long_up']


def test_a_word_that_comes_during_the_long_excursion_ends_its_wait(monkeypatch):
    """The main run's word arrives 3 s into the wait for a late WARNING (its WARNING took 5 s): the
    threshold run's long excursion ends then, not after the plan's 60 s; without a word it waits 60 s."""
    def told_after(seconds):
        def late_warning(clock):
            asked = []

            def bound():
                asked.append(clock.now)
                return 60.0 if clock.now < asked[0] + seconds else 6.5
            return bound
        return late_warning
    assert fly_never_warning(monkeypatch, lambda clock: None) > 59.0
    assert fly_never_warning(monkeypatch, lambda clock: (lambda: 6.5)) < 7.5
    assert 9.0 < fly_never_warning(monkeypatch, told_after(3.0)) < 10.5


def test_the_stopwatch_times_each_stage_wall_and_cpu(tmp_path):
    ticks = iter([0.0, 1.5, 1.5, 4.0])
    watch = timings.Stopwatch(cpu=lambda: next(ticks))
    with watch.stage('build'):
        watch.add_cpu(0.5)  # a box's, by its cgroup
    with watch.stage('runs'):
        pass
    assert watch.stages['build']['cpu'] == 2.0 and watch.stages['runs']['cpu'] == 2.5
    assert watch.stages['build']['wall'] >= 0.0
    watch.extra['side_by_side'] = True
    watch.write(str(tmp_path))
    assert timings.read(str(tmp_path)) == dict(watch.value())
    assert timings.read(str(tmp_path / 'none')) == {}
    # Read and written by the contract: a link in its place is replaced, never written through nor read.
    (tmp_path / 'logs').mkdir()
    (tmp_path / 'elsewhere.json').write_text('{"planted": true}')
    (tmp_path / 'logs' / timings.FILE).symlink_to(tmp_path / 'elsewhere.json')
    assert timings.read(str(tmp_path / 'logs')) == {}
    watch.write(str(tmp_path / 'logs'))
    assert (tmp_path / 'elsewhere.json').read_text() == '{"planted": true}'
    assert timings.read(str(tmp_path / 'logs')) == dict(watch.value())


def test_a_cgroups_cpu_is_read_from_either_version(tmp_path):
    v1, v2, neither = tmp_path / 'v1', tmp_path / 'v2', tmp_path / 'memory'
    for folder in (v1, v2, neither):
        folder.mkdir()
    (v1 / 'cpuacct.usage').write_text('2500000000\n')
    (v2 / 'cpu.stat').write_text('usage_usec 1500000\nuser_usec 1000000\n')
    (neither / 'cpu.stat').write_text('nr_periods 3\nnr_throttled 0\n')  # v1's cpu controller counts no usage
    assert cgroups.cpu_use([str(neither), str(v1)]) == 2.5
    assert cgroups.cpu_use([str(v2)]) == 1.5
    assert cgroups.cpu_use([str(neither)]) is None and cgroups.cpu_use([]) is None


def test_two_supervisors_sharing_a_log_folder_end_their_own_processes_only(tmp_path):
    """The two runs side by side log into one folder; each one's supervisor, closed, ends its processes
    and leaves the other run's (they carry a marker each: side_by_side.run_marker)."""
    logs = str(tmp_path)
    main = Supervisor(logs, marker=side_by_side.run_marker(logs, 'main'))
    other = Supervisor(logs, marker=side_by_side.run_marker(logs, 'threshold'))
    kept = other.start('sleeper', ['sleep', '60'])
    # Started by neither supervisor's Popen: found only by its marker.
    stray = subprocess.Popen(['sleep', '60'], env=dict(os.environ, **{'EXAM_LAB_RUN': main.marker}))
    try:
        main.close(grace=1.0)
        assert wait_until(lambda: not alive(stray.pid) or stray.poll() is not None, 5.0)
        assert kept.poll() is None
        assert side_by_side.markers(logs) == [logs, main.marker, other.marker]
    finally:
        other.close(grace=1.0)
        stray.kill()
        stray.wait()
    assert kept.poll() is not None


def test_the_two_runs_fly_side_by_side_only_where_the_cpu_allows():
    """A machine whose load average is at its cores or above flies them one after the other."""
    assert runner.cpu_allows_two_runs(cores=2, load=0.5)
    assert not runner.cpu_allows_two_runs(cores=2, load=2.0) and not runner.cpu_allows_two_runs(cores=2, load=18.0)
    assert runner.cpu_allows_two_runs(cores=16, load=8.0)

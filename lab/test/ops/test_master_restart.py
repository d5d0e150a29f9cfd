"""The ground station's master is killed mid-flight and restarted on the same port (issue 13).

The scenario of the issue, on a master of its own on a free port: ``exam.launch threshold:=1450``
(mydrone and the exam node) flies a climb through 1450 m; at 8 s after the launch the master gets
SIGKILL (and its rosout with it), and 2 s later a new roscore starts on the same port. Asserted:

1. the nodes are back on the new master within a few seconds: ``rosnode list`` names them, a subscriber
   started after the restart receives ``/altitude``, and ``/diagnostics`` carries the exam node's
   statuses; the launch's parameters are on the new master again (``/exam/threshold`` is 1450);
2. the LED turns RED within 1 s of the deadline of the 1450 m threshold (the first published altitude
   above 1450 m plus the 5 s delay), not at the default threshold's;
3. nothing died: the same processes run the nodes, roslaunch is still up, no traceback in any log;
4. each node's "<node>: master" status on /diagnostics (issue 19) said WARN "master down" during the
   outage, and says up, re-registered once, at a time within the outage's end, once it is back.

Then a second fault: the master is killed again once the LED is RED and stays down while the drone
descends, so NORMAL is decided with no master at all: the LED must turn GREEN within 1 s of the
altitude's return below 1450 m, over the connection the exam node opened before; once a new master is
up, the nodes are back on it again, and a new subscriber reads the LED GREEN.

A watcher connected before the first fault times the whole flight (topics are peer to peer: its
connections survive the master), and a ``rostopic echo /diagnostics`` connected before it records the
statuses through both faults; every other check is a process started against the new master.

A second test hangs the master (SIGSTOP) instead: its connections stay open, so only the master
link's heartbeat can notice it (issue 19: the link waits for the master's connection to close rather
than asking every second).
"""
import json
import os
import re
import signal
import time

from exam_lab.harness.supervisor import Supervisor
from exam_lab.harness.wait import wait_until

#: The flight, [time_s, altitude_m] from mydrone's start: 1200 m (estimate 1183.6 m), a climb at
#: 25 m/s from 12 s to 1600 m (estimate 1567 m), a descent from 34 s. The estimate crosses 1300 m at
#: about 16.8 s and 1450 m at about 23 s on the way up (WARNING due at about 28 s), and 1450 m again
#: at about 35.9 s on the way down (NORMAL at once).
PROFILE = [[0, 1200], [12, 1200], [28, 1600], [34, 1600], [40, 1200], [120, 1200]]
THRESHOLD = 1450.0
#: exam.launch's default delay [s].
DELAY = 5.0
#: The threshold the node would use had it fallen back to its default [m].
DEFAULT_THRESHOLD = 1300.0
#: The issue's schedule: SIGKILL at 8 s (after the launch), a new master 2 s later.
KILL_AT = 8.0
DOWN_FOR = 2.0
#: The issue's bounds: back on the new master "within a few seconds", the LED within 1 s.
REAPPEAR_BOUND = 5.0
LED_BOUND = 1.0
NODES = ('/exam', '/mydrone')


def echoed(output):
    """The probe's --echo lines: [(topic, arrival time s, data)], in arrival order."""
    return [(s['echo'], s['t'], s['data']) for s in
            (json.loads(line) for line in output.splitlines() if line.startswith('{"echo"'))]


def run_start(samples, above, threshold, until):
    """Start time of the last uninterrupted run of values ``above`` (or not) ``threshold`` up to
    ``until``, or None."""
    start = None
    for t, value in samples:
        if t > until:
            break
        if (value > threshold) == above:
            start = t if start is None else start
        else:
            start = None
    return start


class Flight(object):
    """The watcher's view: what it received so far, read from its --echo lines."""

    def __init__(self, procs):
        self.procs = procs

    def samples(self):
        return echoed(self.procs.output('watch'))

    def altitudes(self):
        return [(t, data) for topic, t, data in self.samples() if topic == '/altitude']

    def led_turned(self, colour, after=0.0):
        """Arrival time of the first LED report ``colour`` after ``after``, or None."""
        return next((t for topic, t, data in self.samples()
                     if topic == '/alt_warn_led' and data == colour and t > after), None)


def statuses(output):
    """The diagnostic statuses ``rostopic echo /diagnostics`` printed: [(name, level, message)]."""
    found, level = [], None
    lines = output.splitlines()
    for i, line in enumerate(lines):
        match = re.match(r'\s*level: (\d+)', line)
        if match:
            level = int(match.group(1))
        match = re.match(r'\s*name: "(.*)"', line)
        if match and i + 1 < len(lines):
            message = re.match(r'\s*message: "(.*)"', lines[i + 1])
            if message:
                found.append((match.group(1), level, message.group(1)))
    return found


def status_values(output, name):
    """The key/values of each status ``name`` that ``rostopic echo /diagnostics`` printed: [dict]."""
    found, current, key = [], None, None
    for line in output.splitlines():
        match = re.match(r'\s*(name|key|value): "(.*)"', line)
        if not match:
            continue
        field, text = match.groups()
        if field == 'name':
            current = {} if text == name else None
            if current is not None:
                found.append(current)
        elif current is not None and field == 'key':
            key = text
        elif current is not None:
            current[key] = text
    return found


def master_statuses(output, node):
    """(level, message) of each "<node>: master" status, in order."""
    return [(level, message) for name, level, message in statuses(output) if name == node + ': master']


def registered(master):
    """True when ``master`` lists the nodes' topics and service (knowing a node's name is not enough:
    a node that merely read a parameter from a new master is known to it)."""
    try:
        publishers, subscribers, services = (dict(kind) for kind in master.system_state())
    except OSError:
        return False
    return ('/exam' in publishers.get('/altitude', []) and '/exam' in subscribers.get('/pressure', [])
            and '/mydrone' in publishers.get('/pressure', [])
            and '/mydrone' in services.get('/altitude_warning', []))


def restart(master):
    """SIGKILL the master, wait the issue's 2 s, start a new one on its port; once it answers, return
    (time of the kill, time it answered), monotonic s."""
    master.kill()
    killed = time.monotonic()
    time.sleep(DOWN_FOR)
    master.start()
    return killed, time.monotonic()


def assert_back(procs, master, since, what):
    """The nodes are registered with the new master within REAPPEAR_BOUND s; returns how long it took."""
    assert wait_until(lambda: registered(master), REAPPEAR_BOUND), \
        '%s: not registered with the new master after %.0f s: %s\n%s' % (
            what, REAPPEAR_BOUND, master.system_state(), procs.output('launch'))
    assert master.graph.getParam('/exam/threshold') == THRESHOLD
    assert master.graph.getParam('/mydrone/profile') == PROFILE
    return time.monotonic() - since


def test_master_killed_and_restarted_mid_flight(tmp_path):
    with Supervisor(tmp_path) as procs:
        master = procs.start_master()
        env = master.env
        launched = time.monotonic()
        launch = procs.start('launch', ['roslaunch', 'exam', 'exam.launch', 'threshold:=%g' % THRESHOLD,
                                        'profile:=%s' % json.dumps(PROFILE)], env)
        # Connected before the fault, it records the whole flight (its conditions are never met: it
        # runs until it is stopped).
        watch = procs.start('watch', ['rosrun', 'exam_lab', 'probe.py', '--echo', '--timeout', '120',
                                      '--count', '100000', '--value', '/altitude',
                                      '--led', '/alt_warn_led=RED'], env)
        diagnostics = procs.start('diag', ['rostopic', 'echo', '/diagnostics'], env)
        flight = Flight(procs)
        assert wait_until(lambda: {topic for topic, _, _ in flight.samples()}
                          == {'/altitude', '/alt_warn_led'}, 30.0), \
            procs.output('watch') + procs.output('launch')
        assert registered(master), procs.output('launch')
        pids = {name: master.node_pid(name) for name in NODES}

        # The fault, on the schedule (the flight is scripted in time: this is not a wait).
        time.sleep(max(0.0, launched + KILL_AT - time.monotonic()))
        killed_wall = time.time()
        killed, back = restart(master)
        print('master killed at %.1f s after the launch, a new one answering at %.1f s'
              % (killed - launched, back - launched))

        # 1. Back on the new master, with the launch's parameters.
        reappeared = assert_back(procs, master, back, 'first restart')
        status, out, _ = procs.run('rosnode', ['rosnode', 'list'], 20.0, env)
        assert status == 0 and set(NODES) <= set(out.split()), out
        status, out, _ = procs.run('fresh', ['rosrun', 'exam_lab', 'probe.py', '--timeout', '15',
                                             '--value', '/altitude'], 30.0, env)
        assert status == 0, 'a subscriber started after the restart got no /altitude: ' + out
        fresh = time.monotonic() - back
        # Every node publishes its own /diagnostics now (the master status): read until the exam
        # node's statuses come, whatever arrives first.
        echo = procs.start('diagnostics', ['rostopic', 'echo', '/diagnostics'], env)
        assert wait_until(lambda: 'exam: inputs' in procs.output('diagnostics')
                          and 'exam: warning' in procs.output('diagnostics'), 20.0), \
            procs.output('diagnostics')
        procs.stop(echo)
        # 4. The master link's status: up and re-registered once, during this outage's end.
        for node in NODES:
            seen = wait_until(lambda: [m for level, m in master_statuses(procs.output('diag'), node[1:])
                                       if level == 0 and 're-registered 1 times' in m], 10.0)
            assert seen, '%s: no re-registered status:\n%s' % (node, procs.output('diag')[-3000:])
            at = float(seen[0].rsplit(' ', 1)[1])
            assert killed_wall < at < time.time(), (node, seen[0])
            print('%s: "%s"' % (node, seen[0]))
        print('on the new master %.2f s after it answered; a subscriber started then had 5 '
              '/altitude messages %.2f s after it answered' % (reappeared, fresh))

        # 2. The WARNING of the 1450 m threshold, on time, decided after the restart.
        red = wait_until(lambda: flight.led_turned('RED'), 40.0)
        assert red is not None, 'the LED never turned RED:\n' + procs.output('launch')[-4000:]
        altitudes = flight.altitudes()
        deadline = run_start(altitudes, True, THRESHOLD, red) + DELAY
        default_deadline = run_start(altitudes, True, DEFAULT_THRESHOLD, red) + DELAY
        print('LED RED %+.3f s from the 1450 m deadline (the 1300 m one was %.1f s earlier)'
              % (red - deadline, deadline - default_deadline))
        assert abs(red - deadline) <= LED_BOUND, 'RED %+.3f s from the deadline' % (red - deadline)

        # Second fault: no master while the drone descends; NORMAL goes out over the open connection.
        master.kill()
        killed = time.time()
        green = wait_until(lambda: flight.led_turned('GREEN', red), 20.0)
        assert green is not None, 'the LED never turned GREEN with the master down:\n' \
            + procs.output('launch')[-4000:]
        time.sleep(max(0.0, killed + DOWN_FOR - time.time()))
        master.start()
        back = time.monotonic()
        # The node acts on the reading itself; /altitude shows it at the next 10 Hz tick, after GREEN.
        below = run_start(flight.altitudes(), False, THRESHOLD, green + LED_BOUND)
        print('master down from %.1f s before to %.1f s after NORMAL; LED GREEN %+.3f s from the '
              'return below 1450 m' % (green - killed, time.time() - green, green - below))
        assert killed < below, 'the master was killed after the return below the threshold'
        assert abs(green - below) <= LED_BOUND, 'GREEN %+.3f s from the return' % (green - below)
        reappeared = assert_back(procs, master, back, 'second restart')
        print('on the second new master %.2f s after it answered' % reappeared)
        # What a subscriber started now reads from the latched LED is what the drone shows.
        status, out, _ = procs.run('led', ['rosrun', 'exam_lab', 'probe.py', '--timeout', '15',
                                           '--led', '/alt_warn_led=GREEN'], 30.0, env)
        assert status == 0, out

        # 4. ... and WARN while the master was down (the second outage lasts seconds at least).
        for node in NODES:
            down = [m for level, m in master_statuses(procs.output('diag'), node[1:]) if level == 1]
            assert down and all(m.startswith('master down for') for m in down), (node, down)
            assert wait_until(lambda: [m for level, m in master_statuses(procs.output('diag'), node[1:])
                                       if level == 0 and 're-registered 2 times' in m], 10.0), node
            print('%s: %d WARN statuses while the master was down: "%s" ... "%s"'
                  % (node, len(down), down[0], down[-1]))

        # 3. Nothing died, nothing was respawned.
        assert launch.poll() is None, procs.output('launch')
        assert {name: master.node_pid(name) for name in NODES} == pids
        procs.stop(watch)
        procs.stop(diagnostics)
        procs.stop(launch)
        log = procs.output('launch')
        assert 'Traceback' not in log, log
        print('\n'.join(line for line in log.splitlines() if 'master' in line or 'connect' in line))


#: A hung master keeps its connections open: only the master link's heartbeat (every 2 s, a call that
#: times out after 2 s) notices it. Generous, but a link without a heartbeat never gets there.
HUNG_NOTICED_BOUND = 30.0


def test_a_hung_master_is_noticed_and_found_unchanged(tmp_path):
    """A master that hangs (SIGSTOP) leaves the nodes' connections to it open, so no close tells of
    it: each node says "unreachable" after its next heartbeat's call times out, and once the master
    runs again, that it still knows the node: nothing re-registered, nothing died."""
    with Supervisor(tmp_path) as procs:
        master = procs.start_master()
        launch = procs.start('launch', ['roslaunch', 'exam', 'exam.launch', 'profile:=calm'], master.env)
        assert wait_until(lambda: registered(master) and all(
            master.node_pid(name) for name in NODES), 60.0), procs.output('launch')
        pids = {name: master.node_pid(name) for name in NODES}
        # Each node's link has had its first answer, so it holds a connection that a hang keeps open.
        procs.start('diag', ['rostopic', 'echo', '/diagnostics'], master.env)
        assert wait_until(lambda: all(
            any(v.get('last answer at [s]', 'never') != 'never'
                for v in status_values(procs.output('diag'), node[1:] + ': master'))
            for node in NODES), 30.0), procs.output('diag')[-3000:]
        rosmaster = master.graph.getPid()
        out = lambda: procs.output('launch')
        os.kill(rosmaster, signal.SIGSTOP)
        stopped = time.monotonic()
        try:
            noticed = wait_until(lambda: out().count('unreachable (TimeoutError') >= len(NODES),
                                 HUNG_NOTICED_BOUND)
            took = time.monotonic() - stopped
        finally:
            os.kill(rosmaster, signal.SIGCONT)
        assert noticed, 'a hung master went unnoticed for %.0f s:\n%s' % (took, out()[-3000:])
        assert wait_until(lambda: out().count('it still knows') >= len(NODES), 30.0), out()[-3000:]
        print('a hung master noticed by both nodes %.1f s after SIGSTOP' % took)
        assert 're-registered' not in out(), out()
        assert {name: master.node_pid(name) for name in NODES} == pids
        assert launch.poll() is None, out()
        procs.stop(launch)
        assert 'Traceback' not in out(), out()

"""Clean at every stop (issue 19): the full launch of each sheet, Ctrl-C'd at many moments, never prints
a traceback.

Each sheet's launch (``exam.launch``, ``exam_submarine.launch``: the drone and the exam node) is
started and stopped again and again, with SIGINT to roslaunch's process group as a terminal's Ctrl-C
sends it, at one of these moments, each announced by the launch's own output (an event, not a time):

- ``start-up``: as soon as the exam node says it started, before or around its first reading;
- ``first reading``: a little after that (0.1 to 0.6 s), while the first readings arrive;
- ``pending``: the flight is above the threshold from the start, with the 5 s delay: stopped once the
  exam node logs the excess and its WARNING's due time, 0 to 2 s later, while the WARNING is pending;
- ``service call``: the flight swings across the threshold every 1.5 s with no delay (the sensors'
  2 Hz readings land on both sides), so the exam node calls the drone's service at every crossing:
  stopped 0 to 0.3 s after a call was delivered, while the next ones run;
- ``master down``: the master gets SIGKILL once the exam node is connected to the service; stopped
  once the nodes have logged the outage (the master is started again for the next run).

Asserted for every run: zero ``Traceback`` and zero ``Exception in thread`` in the screen output
and in every log file of the run (the nodes' own logs under ROS_LOG_DIR, roslaunch's), and no node
that roslaunch had to escalate to SIGTERM (a node that hangs at the stop). Runs go in SLOTS parallel
lanes, each with a master of its own: the 40 stops take 1 to 3 minutes on a loaded machine.
"""
import glob
import json
import os
import random
import threading
import time

from exam_lab.harness.supervisor import Supervisor
from exam_lab.harness.wait import wait_until

SHEETS = {
    'altitude': dict(launch='exam.launch', threshold=1300,
                     above=[[0, 1500], [100, 1500]],
                     chatter=[[0, 1100], [0.75, 1600], [1.5, 1100]]),
    'depth': dict(launch='exam_submarine.launch', threshold=150,
                  above=[[0, 200], [100, 200]],
                  chatter=[[0, 100], [0.75, 200], [1.5, 100]]),
}
MOMENTS = ('start-up', 'first reading', 'pending', 'service call', 'master down')
#: Runs per (sheet, moment): 2 x 5 x 4 = 40 stops.
REPEAT = 4
#: Parallel lanes, each with its own master: start-up (2-5 s of roslaunch) dominates a run.
SLOTS = 3
#: Generous bounds for events a run waits for; a run that misses one fails with the output.
EVENT_TIMEOUT = 60.0
#: roslaunch escalates SIGINT to SIGTERM after 15 s; a clean stop takes a second or two.
STOP_GRACE = 30.0
#: A traceback, a thread's uncaught exception, a node that roslaunch had to kill (it hung at the stop).
BAD = ('Traceback', 'Exception in thread', 'escalating to SIG')
#: What the exam node prints once it is built, and once it holds the service connection.
STARTED = ': mode '
CONNECTED = 'the connection is kept for every call'


def arguments(sheet, moment):
    spec = SHEETS[sheet]
    args = ['threshold:=%g' % spec['threshold']]
    if moment == 'pending':
        args += ['delay:=5', 'profile:=%s' % json.dumps(spec['above'])]
    elif moment == 'service call':
        args += ['delay:=0', 'profile:=%s' % json.dumps(spec['chatter'])]
    return ['roslaunch', 'exam', spec['launch']] + args


class Lane(object):
    """One master and the runs made on it, one after the other."""

    def __init__(self, tmp_path, index):
        self.procs = Supervisor(tmp_path / ('lane%d' % index))
        self.master = self.procs.start_master()
        self.rng = random.Random(index)
        self.failures = []
        self.ran = []

    def run(self, sheet, moment, number):
        name = '%s-%s-%d' % (sheet, moment.replace(' ', '_'), number)
        procs, master = self.procs, self.master
        launch = procs.start(name, arguments(sheet, moment), master.env)
        out = lambda: procs.output(name)  # noqa: E731
        started = time.monotonic()
        waited = {
            'start-up': lambda: STARTED in out(),
            'first reading': lambda: STARTED in out(),
            'pending': lambda: 'WARNING due at' in out(),
            'service call': lambda: 'LED set to' in out(),
            'master down': lambda: CONNECTED in out(),
        }[moment]
        if not wait_until(lambda: waited() or launch.poll() is not None, EVENT_TIMEOUT) or \
                launch.poll() is not None:
            self.failures.append('%s: the moment never came (or the launch ended):\n%s' % (name, out()))
            procs.stop(launch, STOP_GRACE)
            return
        pause = {'start-up': 0.0, 'first reading': self.rng.uniform(0.1, 0.6),
                 'pending': self.rng.uniform(0.0, 2.0), 'service call': self.rng.uniform(0.0, 0.3),
                 'master down': 0.0}[moment]
        if moment == 'master down':
            master.kill()
            if not wait_until(lambda: out().count('unreachable') >= 1, EVENT_TIMEOUT):
                self.failures.append('%s: no node noticed the outage:\n%s' % (name, out()))
        time.sleep(pause)  # the moment itself, drawn at random: the stop lands anywhere in it
        stopped_at = time.monotonic()
        status = procs.stop(launch, STOP_GRACE)
        took = time.monotonic() - stopped_at
        if moment == 'master down':
            master.start()
        self.ran.append((name, stopped_at - started, took, status))
        if took >= STOP_GRACE - 1.0:
            self.failures.append('%s: the launch took %.1f s to stop:\n%s' % (name, took, out()))

    def close(self):
        self.procs.close()


#: Log files of the nodes under test (ROS_LOG_DIR/<run_id>/<node>-<n>.log).
NODE_LOGS = ('exam-', 'mydrone-', 'submarine_drone-')


def ours(root, path):
    """True for the files of the launches under test: each run's screen output (``laneN/<run>.log``),
    the nodes' log files, the launches' own roslaunch logs. The master's are left out (roscore's
    screen output, its launcher's log, ``master.log``): rosmaster logs a traceback of its own whenever
    a node it tells of a publisher has just gone, and roscore's launcher when it is killed while it
    starts rosout; neither is a node's stop."""
    name = os.path.basename(path)
    if len(os.path.relpath(path, str(root)).split(os.sep)) == 2:
        return name != 'master.log'
    if name.startswith('roslaunch-'):
        with open(path, errors='replace') as f:
            return "starting with args ['roscore'" not in f.read(4000)
    return name.startswith(NODE_LOGS)


def bad_lines(root):
    """``(file, line)`` for every line naming a traceback or an uncaught thread exception in the
    files of the launches under test (:func:`ours`)."""
    found = []
    for path in sorted(glob.glob(os.path.join(str(root), '**', '*'), recursive=True)):
        if not os.path.isfile(path) or not ours(root, path):
            continue
        with open(path, errors='replace') as f:
            for line in f:
                if any(word in line for word in BAD):
                    found.append((os.path.relpath(path, str(root)), line.rstrip()))
    return found


def excerpt(root, relpath, around='Traceback', lines=25):
    with open(os.path.join(str(root), relpath), errors='replace') as f:
        text = f.read().splitlines()
    first = next((i for i, line in enumerate(text) if any(w in line for w in BAD)), 0)
    return '\n'.join(text[max(0, first - 3):first + lines])


def test_every_stop_is_clean(tmp_path):
    runs = [(sheet, moment, n) for n in range(REPEAT) for sheet in SHEETS for moment in MOMENTS]
    random.Random(19).shuffle(runs)
    lanes = []
    try:
        lanes = [Lane(tmp_path, i) for i in range(SLOTS)]
        queue = list(runs)
        lock = threading.Lock()

        def work(lane):
            while True:
                with lock:
                    if not queue:
                        return
                    run = queue.pop()
                lane.run(*run)

        threads = [threading.Thread(target=work, args=(lane,)) for lane in lanes]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        for lane in lanes:
            lane.close()
    failures = [f for lane in lanes for f in lane.failures]
    ran = sorted(r for lane in lanes for r in lane.ran)
    for name, after, took, status in ran:
        print('%-28s stopped %5.1f s after its start, in %4.1f s, exit %s' % (name, after, took, status))
    assert not failures, '\n\n'.join(failures)
    assert len(ran) == len(runs) >= 30
    bad = bad_lines(tmp_path)
    runs_with_bad = sorted({path.split(os.sep)[1] if path.count(os.sep) else path for path, _ in bad})
    print('%d stops, %d lines with a traceback in %d files' % (len(ran), len(bad), len({p for p, _ in bad})))
    assert not bad, 'tracebacks at a stop in %s:\n%s' % (
        runs_with_bad, '\n----\n'.join(excerpt(tmp_path, path) for path in sorted({p for p, _ in bad})[:5]))

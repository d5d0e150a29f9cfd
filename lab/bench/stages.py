"""The measurements of `make bench`, one function per stage, each for one kind of node.

A kind is ``ours`` (exam/scripts/exam_node.py), ``baseline`` (lab/bench/baseline_exam_node.py), ``floor``
(lab/bench/floor_node.py, the cheapest rospy node with the same topics) or ``ours_without_numpy`` (ours
through lab/bench/without_numpy.py, the memory experiment). Every stage starts its node(s) in a namespace
of its own, measures, stops them, and returns a plain dict that report.py renders.
"""

import os
import subprocess
import time

from exam_lab.harness.wait import wait_until

import driver
import procs
import stats

PYTHON = '/usr/bin/python3'
BENCH = os.path.dirname(os.path.realpath(__file__))
REPO = os.path.dirname(os.path.dirname(BENCH))
SCRIPTS = {
    'ours': os.path.join(REPO, 'exam', 'scripts', 'exam_node.py'),
    'baseline': os.path.join(BENCH, 'baseline_exam_node.py'),
    'floor': os.path.join(BENCH, 'floor_node.py'),
}
# Variants run through a wrapper instead of their script alone.
COMMANDS = {
    'ours_without_numpy': [os.path.join(BENCH, 'without_numpy.py'), SCRIPTS['ours']],
}
SIMULATOR = os.path.join(REPO, 'mydrone', 'scripts', 'mydrone_node.py')
BELOW, ABOVE = 1000.0, 1600.0
THRESHOLD = 1300.0
STARTUP_TIMEOUT = 30.0


def progress(message):
    print('[bench %s] %s' % (time.strftime('%H:%M:%S'), message), flush=True)


def available(path):
    """A script counts only once it has content: another engineer may have created it empty."""
    return os.path.isfile(path) and os.path.getsize(path) > 0


class Lab:
    """What every stage needs: the harness's supervisor of the child processes and their master."""

    def __init__(self, supervisor, master):
        self.supervisor = supervisor
        self.master = master
        self.env = master.env
        self._serial = 0

    def namespace(self, stage, kind):
        self._serial += 1
        return '/%s_%s_%d' % (stage, kind, self._serial)

    def start_node(self, kind, ns, **params):
        command = COMMANDS[kind] if kind in COMMANDS else [SCRIPTS[kind]]
        argv = [PYTHON] + command + ['__ns:=' + ns, '__name:=exam']
        argv += ['_%s:=%s' % (k, v) for k, v in sorted(params.items())]
        return self.supervisor.start(ns.strip('/') + '_exam', argv, self.env)

    def start_simulator(self, ns):
        argv = [PYTHON, SIMULATOR, '__ns:=' + ns, '__name:=mydrone']
        return self.supervisor.start(ns.strip('/') + '_mydrone', argv, self.env)


class Rig:
    """One node under test with the bench as its drone (the harness's fake drone) and a script to fly."""

    def __init__(self, lab, kind, ns, steps, slow=0.0, **params):
        self.lab = lab
        self.drone = driver.drone(ns, slow)
        self.player = driver.Player(self.drone, steps)
        self.proc = lab.start_node(kind, ns, **params)

    def start(self):
        """Play the script once the node is subscribed; raise if it never publishes."""
        if not wait_until(self.drone.feeder.connected, STARTUP_TIMEOUT,
                          alive=lambda: self.proc.poll() is None):
            raise RuntimeError('node %s did not subscribe (exit code %s)'
                               % (self.proc.args, self.proc.poll()))
        self.player.start()
        if self.drone.output.wait_for(lambda value: True, STARTUP_TIMEOUT) is None:
            raise RuntimeError('node %s published no altitude' % (self.proc.args,))

    def close(self):
        self.lab.supervisor.stop(self.proc, grace=5.0)
        self.player.stop()
        self.drone.close()


def rate_and_cost(lab, kind, window, rate=None, during=None, **extra):
    """Altitude stream timing, CPU and RSS of one node fed steady readings below the threshold.

    ``during(pid, window)``, when given, runs instead of the plain wait (a profiler attaching);
    ``extra`` are more private params of the node.
    """
    params = dict(extra, threshold=THRESHOLD)
    if rate is not None:
        params['rate'] = rate
    rig = Rig(lab, kind, lab.namespace('rate', kind), [(0.0, BELOW)], **params)
    try:
        rig.start()
        time.sleep(1.0)  # past the first messages' connection setup
        rig.drone.output.clear()
        cpu = procs.CpuWindow([rig.proc.pid])
        cpu.start()
        if during is None:
            time.sleep(window)
        else:
            during(rig.proc.pid, window)
        usage = cpu.stop()[rig.proc.pid]
        result = stats.interval_stats(driver.stamps(rig.drone.output))
        result.update(cpu_percent=usage, rss_mb=_mb(procs.rss_kb(rig.proc.pid)),
                      machine_busy_percent=cpu.machine_busy(), window_s=window,
                      loadavg=procs.loadavg())
        return result
    finally:
        rig.close()


def latency(lab, kind, count, delay, hold, seed, slow=0.0):
    """Scripted excursions above the threshold; latency of each WARNING and NORMAL call.

    With ``slow`` > 0 the service takes that long per call and the stage is about the longest gap in
    /altitude while calls are in flight.
    """
    steps = stats.crossing_script(count, delay, hold, stats.new_rng(seed), BELOW, ABOVE)
    rig = Rig(lab, kind, lab.namespace('slow' if slow else 'latency', kind), steps, slow=slow,
              threshold=THRESHOLD, delay=delay)
    try:
        rig.start()
        rig.drone.output.clear()
        # The last NORMAL call may wait behind a slow call already in flight.
        time.sleep(steps[-1][0] + hold + 2 * slow + 1.0)
        stamps = rig.player.step_stamps
        # Step 0 is the initial reading below; then pairs (above, back below).
        cycles = list(zip(stamps[1::2], stamps[2::2]))
        # Every call as it arrived, before the slow service's delay.
        calls = rig.drone.service.attempts()
        warning, normal, anomalies = stats.match_warning_calls(cycles, calls, delay)
        return {
            'excursions': len(cycles),
            'delay_s': delay,
            'slow_s': slow,
            'warning': stats.summarize_ms(warning),
            'normal': stats.summarize_ms(normal),
            'anomalies': anomalies,
            'anomaly_count': len(anomalies),
            'stream': stats.interval_stats(driver.stamps(rig.drone.output)),
            'loadavg': procs.loadavg(),
        }
    finally:
        rig.close()


def fleet(lab, kind, count, window):
    """``count`` drone + exam pairs: each pair's /altitude rate, total CPU and RSS by role, and the
    master's CPU (issue 19: 100 pairs on one master, every /altitude at 10 Hz, the master under 10 %).

    Every pair gets a namespace never used before on this master, and the bench starts each node
    itself rather than through lab/scripts/fleet_launch.py, whose names drone1..droneN repeat from
    one fleet to the next. A rospy node never withdraws its param subscriptions (rosout's
    /rosout_disable_topics_generation, diagnostic_updater's ~diagnostic_period), so the master keeps
    every stopped node's XML-RPC address; when a node of the same name registers again, the master
    tells the old address to shut down, and if the OS has meanwhile given that port to a node of the
    new fleet, that node dies ("new node registered with same name"). The first full run lost a
    simulator of the 20-pair fleet exactly so.
    """
    namespaces = [lab.namespace('fleet%d' % count, kind) for _ in range(count)]
    pids = {}
    started = []
    for ns in namespaces:
        started.append(lab.start_simulator(ns))
        pids[ns + '/mydrone'] = started[-1].pid
        started.append(lab.start_node(kind, ns, threshold=THRESHOLD))
        pids[ns + '/exam'] = started[-1].pid
    monitors = {ns: driver.recorder(ns + '/altitude') for ns in namespaces}
    try:
        deadline = time.monotonic() + STARTUP_TIMEOUT + 3.0 * count
        silent = [ns for ns, monitor in monitors.items()
                  if monitor.wait_for(lambda value: True, max(0.1, deadline - time.monotonic())) is None]
        if silent:
            raise RuntimeError('fleet of %d: no altitude from %s (registered nodes there: %s)'
                               % (count, ', '.join(silent), registered(lab.master, silent)))
        time.sleep(2.0)
        for monitor in monitors.values():
            monitor.clear()
        master_pid = lab.master.graph.getPid()
        cpu = procs.CpuWindow(list(pids.values()) + [master_pid])
        cpu.start()
        time.sleep(window)
        usage = cpu.stop()
        master_cpu = usage.pop(master_pid)
        busy = cpu.machine_busy()
        rss = {name: procs.rss_kb(pid) for name, pid in pids.items()}
        streams = {ns: stats.interval_stats(driver.stamps(m)) for ns, m in monitors.items()}
        # A pair that fell silent has no rate: it counts as 0 Hz, not as missing.
        rates = [s['rate_hz'] or 0.0 for s in streams.values()]
        return {
            'pairs': count,
            'window_s': window,
            'rates_hz': rates,
            'min_rate_hz': min(rates),
            'max_rate_hz': max(rates),
            'max_gap_ms': max((s['max_gap_ms'] or 0.0) for s in streams.values()),
            'cpu_percent': _by_role(usage, pids),
            # rosmaster alone (roscore's own launcher and rosout left out): what the fleet's liveness
            # checks, registrations and logs cost the one process every node depends on.
            'master_cpu_percent': master_cpu,
            'rss_mb': _by_role({pids[n]: v and v / 1024.0 for n, v in rss.items()}, pids),
            'machine_busy_percent': busy,
            'loadavg': procs.loadavg(),
        }
    finally:
        for monitor in monitors.values():
            monitor.close()
        lab.supervisor.stop_all(started, grace=5.0)


def _by_role(values_by_pid, pids):
    """Sum per role (exam, mydrone) of a per-pid value."""
    roles = {}
    for name, pid in pids.items():
        role = name.rsplit('/', 1)[-1]
        value = values_by_pid.get(pid)
        if value is not None:
            roles[role] = roles.get(role, 0.0) + value
    return roles


def registered(master, namespaces):
    """Names of the nodes of ``namespaces`` that the master knows: tells a crash from a slow start."""
    state = master.system_state()
    nodes = {node for _, names in state[0] + state[1] + state[2] for node in names}
    return sorted(n for n in nodes if any(n.startswith(ns + '/') for ns in namespaces)) or 'none'


def _mb(kb):
    return kb / 1024.0 if kb is not None else None


def max_rate(lab, kind, rates, window):
    """The highest ``~rate`` sustained within 1 % with interval sd < 1 ms, and each attempt."""
    runs = []
    for target in rates:
        progress('  %s at ~rate %g Hz' % (kind, target))
        try:
            run = rate_and_cost(lab, kind, window, rate=target)
        except RuntimeError as e:
            run = {'error': str(e)}
        run['target_hz'] = target
        run['sustained'] = (stats.within(run.get('rate_hz'), target, 0.01)
                            and run.get('sd_ms') is not None and run['sd_ms'] < 1.0)
        runs.append(run)
    sustained = [x['target_hz'] for x in runs if x['sustained']]
    return {'runs': runs, 'highest_hz': max(sustained) if sustained else 0}


# Each snippet prints its own VmRSS (kB) once it has done one more step of what every rospy node does.
MEMORY_STEPS = [
    ('python3 interpreter', ''),
    # genpy.message imports numpy, so every rospy node pays for it; measured apart to show its share.
    ('+ import numpy', 'import numpy'),
    ('+ import rospy, std_msgs', 'import numpy, rospy, std_msgs.msg'),
    ('+ rospy.init_node', 'import numpy, rospy, std_msgs.msg; rospy.init_node("rss_probe", anonymous=True)'),
    ('rospy.init_node with numpy blocked (lab/bench/without_numpy.py)',
     'import sys; sys.modules["numpy"] = None; import rospy, std_msgs.msg; '
     'rospy.init_node("rss_probe", anonymous=True)'),
]


def memory_floor(lab):
    """RSS after each step a rospy node cannot skip: what bounds the memory of any such node."""
    steps = []
    for label, code in MEMORY_STEPS:
        probe = code + ('; ' if code else '') + (
            'print([l.split()[1] for l in open("/proc/self/status") if l.startswith("VmRSS")][0])')
        out = subprocess.run([PYTHON, '-c', probe], env=lab.env, capture_output=True, text=True,
                             timeout=60, check=True).stdout
        steps.append((label, int(out.strip().splitlines()[-1]) / 1024.0))
    return steps


# What can make a 10 Hz stream wobble, one suspect per variant: the node's own code (ours vs floor),
# rospy's writer thread (floor vs floor, synchronous), and the load of the shared machine (the rounds).
JITTER_VARIANTS = [
    ('ours', 'ours', {}),
    ('baseline', 'baseline', {}),
    ('floor', 'floor', {}),
    ('floor, synchronous publish', 'floor', {'synchronous': 'true'}),
]


def jitter(lab, rounds, window):
    """Interval statistics of each variant at 10 Hz, interleaved over ``rounds`` so a burst of load
    from other work on the machine hits every variant alike rather than one of them."""
    runs = []
    for i in range(rounds):
        for label, kind, params in JITTER_VARIANTS:
            progress('  jitter round %d/%d: %s' % (i + 1, rounds, label))
            run = rate_and_cost(lab, kind, window, **params)
            run['variant'] = label
            runs.append(run)
    return runs

"""Processes of the benchmark: a master on a free port, the nodes under test, and their CPU and RSS.

Every child runs in its own session (process group), so stopping it also stops anything it forked
(roscore's rosmaster and rosout). Each group id is appended to ``pid_file`` the moment it exists:
lab/bench/run.sh's trap kills exactly those groups if this Python process itself dies without cleaning up.
"""

import os
import signal
import socket
import subprocess
import time

from stats import cpu_percent

CLOCK_TICKS = os.sysconf('SC_CLK_TCK')


def free_port():
    """A TCP port nobody listens on right now: bind to port 0 and let the kernel choose."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


def cpu_ticks(pid):
    """utime + stime of ``pid`` in clock ticks, or None once it has exited."""
    try:
        with open('/proc/%d/stat' % pid) as f:
            stat = f.read()
    except OSError:
        return None
    # The command name (field 2) may hold spaces and parentheses: split after its last ')'.
    fields = stat[stat.rindex(')') + 2:].split()
    return int(fields[11]) + int(fields[12])


def rss_kb(pid):
    """Resident set size (VmRSS, kB) of ``pid``, or None once it has exited."""
    try:
        with open('/proc/%d/status' % pid) as f:
            for line in f:
                if line.startswith('VmRSS:'):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def loadavg():
    """The 1, 5 and 15 minute load averages: how busy the shared machine was around a measurement."""
    with open('/proc/loadavg') as f:
        return [float(x) for x in f.read().split()[:3]]


def machine_ticks():
    """(busy, total) clock ticks of all cores since boot, from the first line of /proc/stat."""
    with open('/proc/stat') as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    # user nice system idle iowait irq softirq steal [guest guest_nice, already counted in user/nice]
    idle = fields[3] + fields[4]
    total = sum(fields[:8])
    return total - idle, total


class CpuWindow:
    """CPU share of a set of processes between ``start()`` and ``stop()``, from /proc."""

    def __init__(self, pids):
        self.pids = list(pids)
        self._t0 = None
        self._ticks0 = None

    def start(self):
        self._t0 = time.monotonic()
        self._ticks0 = {pid: cpu_ticks(pid) for pid in self.pids}
        self._machine0 = machine_ticks()

    def machine_busy(self):
        """Percent of all cores busy (anyone's work, steal included) since ``start()``: how loaded the
        shared machine was while this window measured timing."""
        busy, total = machine_ticks()
        busy0, total0 = self._machine0
        return 100.0 * (busy - busy0) / (total - total0) if total > total0 else None

    def stop(self):
        """Percent of one core for each pid (None for a process that died meanwhile)."""
        seconds = time.monotonic() - self._t0
        result = {}
        for pid in self.pids:
            now, before = cpu_ticks(pid), self._ticks0[pid]
            if now is None or before is None:
                result[pid] = None
            else:
                result[pid] = cpu_percent(now - before, seconds, CLOCK_TICKS)
        return result


class Children:
    """The processes this benchmark started, stopped by their own process group id only."""

    def __init__(self, pid_file, log_dir):
        self.pid_file = pid_file
        self.log_dir = log_dir
        self.procs = []

    def start(self, name, argv, env):
        """Start ``argv`` in a new session with output to ``<log_dir>/<name>.log``."""
        log = open(os.path.join(self.log_dir, name + '.log'), 'ab')
        proc = subprocess.Popen(argv, env=env, stdout=log, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, start_new_session=True)
        log.close()
        self.procs.append(proc)
        with open(self.pid_file, 'a') as f:
            f.write('%d\n' % proc.pid)
        return proc

    def stop(self, procs=None, grace=5.0):
        """SIGINT (rospy's clean shutdown), then SIGKILL after ``grace`` seconds, per process group."""
        procs = list(self.procs if procs is None else procs)
        for proc in procs:
            _signal_group(proc, signal.SIGINT)
        deadline = time.monotonic() + grace
        for proc in procs:
            try:
                proc.wait(timeout=max(0.1, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
            # The leader may be gone while a forked child (rosout under roscore) still runs.
            _signal_group(proc, signal.SIGKILL)
            proc.wait()
            if proc in self.procs:
                self.procs.remove(proc)


def _signal_group(proc, sig):
    try:
        os.killpg(proc.pid, sig)
    except ProcessLookupError:
        pass


def start_master(children, env):
    """Start ``roscore`` on a free port; return its process and URI once the master answers."""
    import rosgraph  # the ROS environment is only needed from here on

    port = free_port()
    uri = 'http://127.0.0.1:%d/' % port
    env = dict(env, ROS_MASTER_URI=uri)
    proc = children.start('roscore', ['roscore', '-p', str(port)], env)
    deadline = time.monotonic() + 30.0
    master = rosgraph.Master('/bench', master_uri=uri)
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise RuntimeError('roscore on port %d exited with %d' % (port, proc.returncode))
        if master.is_online():
            return proc, uri
        time.sleep(0.2)
    raise RuntimeError('roscore on port %d did not answer within 30 s' % port)

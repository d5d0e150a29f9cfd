"""What the benchmark measures of its processes, from /proc: CPU share, resident memory, machine load.

Starting and stopping them is the harness's job (:class:`exam_lab.harness.supervisor.Supervisor`).
"""

import os
import time

from stats import cpu_percent

CLOCK_TICKS = os.sysconf('SC_CLK_TCK')


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

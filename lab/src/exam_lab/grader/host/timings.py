"""Where a grading spends its time: each stage's wall clock and CPU, recorded by the grading itself.

A :class:`Stopwatch` times the stages of one process (the runner's thread: staging, the inspection's
box, the session, the logs, the grade; the session: roslaunch's check, the build, the runs) and writes
them as ``timings.json`` (``{"stages": {name: {"wall": s, "cpu": s}}, ...}``), which ``make bench``
reads (``lab/bench/stages.py``) instead of timing the grading again from outside. CPU is what the
stage's own process (or thread) used, what the processes it waited for used (``getrusage``: the
judge's masters and probes, the tools) and what the boxes' cgroups counted (their processes run under
bubblewrap, which is never waited for: :func:`~exam_lab.grader.host.cgroups.cpu_use`). No rospy here.
"""
import contextlib
import json
import os
import resource
import time

from exam_lab.grader import contract
from exam_lab.grader.host.cgroups import cpu_use

FILE = 'timings.json'
#: Most bytes of a timings.json read back (a few stages and their numbers: a few kB)
MAX_BYTES = 1 << 20


def process_cpu():
    """CPU s of this process and of every child it has waited for (their own waited-for children too)."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


def boxes_cpu(*boxes):
    """A CPU clock: this process's and its children's (:func:`process_cpu`) with what the cgroups of
    ``boxes`` (:class:`~exam_lab.grader.host.sandbox.Box`) counted."""
    return lambda: process_cpu() + sum(cpu_use(box.cgroups) or 0.0 for box in boxes)


class Stopwatch(object):
    """Wall and CPU seconds of each named stage (:meth:`stage`), in the order they ran.

    :param cpu: the CPU clock (default :func:`process_cpu`; a thread among others,
        ``time.thread_time``, and :meth:`add_cpu` for what its boxes used).
    """

    def __init__(self, cpu=process_cpu):
        self.cpu, self.stages, self.extra = cpu, {}, {}
        self._children = 0.0

    def add_cpu(self, seconds):
        """CPU s that ``cpu`` does not count (a box's, by its cgroup), counted in the current stage."""
        self._children += seconds or 0.0

    def now(self):
        return time.monotonic(), self.cpu() + self._children

    @contextlib.contextmanager
    def stage(self, name):
        wall, cpu = self.now()
        try:
            yield
        finally:
            self.record(name, wall, cpu)

    def record(self, name, wall, cpu):
        """The stage ``name`` that began at ``(wall, cpu)`` (:meth:`now`) ends now."""
        end_wall, end_cpu = self.now()
        self.stages[name] = {'wall': round(end_wall - wall, 3), 'cpu': round(end_cpu - cpu, 3)}

    def value(self):
        return dict(self.extra, stages=self.stages)

    def write(self, folder, name=FILE):
        """``<folder>/<name>`` (timings.json), written whole by the contract's writer (a reader never sees
        half of it; in OUT, never through an entry there)."""
        contract.write_text(os.path.join(folder, name), json.dumps(self.value(), indent=1, sort_keys=True))


def read(folder, name=FILE):
    """The timings a grading's session (or one of its runs) wrote as ``<folder>/<name>`` (its own file,
    never a box's), read through the contract, or {}."""
    try:
        value = json.loads(contract.read_text(os.path.join(folder, name), MAX_BYTES))
        return value if isinstance(value, dict) else {}
    except (contract.ContractError, ValueError):
        return {}

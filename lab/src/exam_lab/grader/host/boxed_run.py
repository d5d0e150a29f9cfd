"""One of the grader's own modules run on student bytes in a box, as the box's uid, without network,
within its bounds; its one record read back through :mod:`~exam_lab.grader.contract`
(:class:`Boxed`): the inspection of an upload, a class archive's intake, the class's similarity check.
"""
import os
import sys

from exam_lab.grader import contract
from exam_lab.grader.host import limits
from exam_lab.grader.score import records

#: Bounds of the boxes that read student bytes: (wall clock s, CPU s, address space bytes). One upload's
#: inspection (measured: 0.2 s a package, box included); a class archive's intake; the class's similarity check.
INSPECT_BOUNDS = (60.0, 60, 1 << 30)
INTAKE_BOUNDS = (300.0, 300, 1 << 30)
SIMILARITY_BOUNDS = (900.0, 300, 3 << 30)


class InspectionFailed(Exception):
    """The inspection of an upload crashed, overran its bounds or handed back no valid record."""


def _grader_source():
    """The folder that holds the grader's own Python package (``exam_lab``), which a box sees read-only."""
    import exam_lab.grader
    return os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(exam_lab.grader.__file__))))


class Boxed(object):
    """One of the grader's own modules run on student bytes in ``box``, as its uid, without network:
    ``<work>/upload`` (staged by root, :func:`~exam_lab.grader.host.staging.stage_upload`) read-only at
    ``/box/upload``, ``<work>/out`` writable at ``/box/out``, the grader's source read-only; its one
    record is read back through :func:`~exam_lab.grader.host.contract.read_record`. Unsandboxed, the same
    folders are used at their host paths.

    :param mounts: more ``(host, in the box, writable)``; ``(host, None, ...)`` keeps the host path.
    """

    def __init__(self, box, work, mounts=()):
        self.box, self.work = box, work
        self.out = os.path.join(work, 'out')
        os.mkdir(self.out, 0o700)
        if box.slot is not None:
            os.chown(self.out, box.uid, box.uid)
        self.source = _grader_source()
        self.places = [(os.path.join(work, 'upload'), '/box/upload', False), (self.out, '/box/out', True),
                       (self.source, self.source, False)] + [(h, b or h, w) for h, b, w in mounts]

    def path(self, host):
        """``host`` (below one of the mounted folders) as the box's process sees it."""
        if not self.box.bwrap:
            return host
        for outside, inside, _ in self.places:
            if host == outside or host.startswith(outside + '/'):
                return inside + host[len(outside):]
        raise ValueError('%s is not visible in the box' % host)

    def run(self, module, args, record, bounds, python=sys.executable):
        """Run ``python -m module args`` bounded by ``bounds`` (wall clock s, CPU s, address space
        bytes); return the checked record ``record`` (a type of :mod:`~exam_lab.grader.score.records`)
        it wrote as ``/box/out/<record.FILE>``.

        :raises InspectionFailed: with the reason and the end of its log.
        """
        timeout, cpu, memory = bounds
        # Only lowered: a box's process cannot raise its hard limits (sandbox.Box.argv's prlimit).
        cpu, memory = min(cpu, limits.CPU_SECONDS), min(memory, limits.ADDRESS_SPACE_BYTES)
        command = ['prlimit', '--as=%d' % memory, '--cpu=%d' % cpu, '--', python, '-m', module] + list(args)
        env = {'PATH': '/usr/bin:/bin', 'PYTHONPATH': self.source, 'PYTHONDONTWRITEBYTECODE': '1'}
        log = os.path.join(self.work, '%s.log' % module.rsplit('.', 1)[-1])
        status, why = self.box.run(command, env, log, timeout, cwd=self.path(self.out),
                                   mounts=self.places if self.box.bwrap else None, network=False)
        if status == 0:
            try:
                return contract.read_record(os.path.join(self.out, record.FILE), record, record.MAX_BYTES)
            except records.RecordError as err:
                why = 'its record was refused: %s' % err
        tail = session_tail(contract.read_capped(log, 4096) or '')
        if status not in (0, None) and why is None:  # bwrap reports its child's death by signal N as exit 128 + N
            why, tail = bound_hit(status, tail, cpu, memory)
        raise InspectionFailed('%s%s' % (why, ': %s' % tail if tail else ''))


def bound_hit(status, tail, cpu, memory):
    """``(why, tail)`` of a box's module that ended with ``status`` (not 0), its log ending in ``tail``,
    run within ``cpu`` s and ``memory`` bytes of address space: a bound it hit said as that bound (its
    traceback left out: Python's MemoryError), else its exit or signal (its bounds named)."""
    signum = -status if status < 0 else status - 128 if status > 128 else None
    lines = tail.splitlines()
    if signum is None and lines and lines[-1].startswith('MemoryError'):
        return 'it ran out of memory: its bound is %d MB of address space' % (memory >> 20), ''
    if signum is None:
        return 'it failed (exit %d)' % status, tail
    return 'it was killed by signal %d (its bounds: %d s of CPU, %d MB of address space)' % (signum, cpu, memory >> 20), tail



def session_tail(output):
    return '\n'.join(output.strip().splitlines()[-10:])

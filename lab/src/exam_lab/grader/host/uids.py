"""The uids of the boxes and their judges: a slot each, taken under a lock, dropped to, and emptied.

Each box holds a slot N (an exclusive ``flock`` on ``LOCK_DIR/box-N``, so concurrent gradings on one
machine, even of two graders, never share one) and runs as uid ``BOX_UID_BASE + N``; its judge (the
session's masters and probe) as ``JUDGE_UID_BASE + N``: uids no account and no process uses.
"""
import fcntl
import os
import pwd
import signal
import sys

from exam_lab.harness.supervisor import MARKER, OWNER
from exam_lab.harness.wait import wait_until

#: First uid of the boxes (isolate uses 60000+); slot N runs as BOX_UID_BASE + N.
BOX_UID_BASE = 61000
#: First uid of the judges: slot N's masters and probe run as JUDGE_UID_BASE + N.
JUDGE_UID_BASE = 62000
SLOTS = 64
LOCK_DIR = '/run/lock/exam-grader'


def take_slot():
    """``(slot, its lock file, held open)`` of a free slot: locked by no grader, neither uid an account's
    nor used by a process other than a grading's; None when every slot is taken. What an earlier
    grading left in the slot (:func:`leftover`: it was killed before it could end them) is ended first."""
    os.makedirs(LOCK_DIR, mode=0o700, exist_ok=True)
    for slot in range(SLOTS):
        lock = open(os.path.join(LOCK_DIR, 'box-%d' % slot), 'w')
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            lock.close()
            continue
        if any(_uid_in_use(base + slot) for base in (BOX_UID_BASE, JUDGE_UID_BASE)):
            lock.close()
            continue
        end_uid(BOX_UID_BASE + slot)
        end_uid(JUDGE_UID_BASE + slot)
        return slot, lock
    return None


def end_slot(slot):
    """End what a grading left running as slot ``slot``'s uids (:func:`leftover`, strangers left
    alone), unless a grader holds the slot (it is that grader's, and its take_slot swept it first).
    The owner's watch calls it for each slot its grader took (``python3 -m ...uids --end-slot N``)."""
    try:
        lock = open(os.path.join(LOCK_DIR, 'box-%d' % slot), 'w')
    except OSError:
        return
    with lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return
        if not any(_uid_in_use(base + slot) for base in (BOX_UID_BASE, JUDGE_UID_BASE)):
            end_uid(BOX_UID_BASE + slot)
            end_uid(JUDGE_UID_BASE + slot)


def as_user(uid):
    """The command-line prefix that drops root for ``uid`` (its own group, none else, no capabilities).
    The parent death signal a change of uid clears is set again (the supervisor's "Lifetime")."""
    return ['setpriv', '--reuid=%d' % uid, '--regid=%d' % uid, '--clear-groups', '--no-new-privs',
            '--inh-caps=-all', '--pdeathsig', 'keep', '--']


def _uid_in_use(uid):
    """Whether ``uid`` is an account's, or a process not a grading's leftover (:func:`leftover`) runs as it."""
    try:
        pwd.getpwuid(uid)
        return True
    except KeyError:
        return not all(leftover(pid) for pid in pids_of_uid(uid))


#: What marks the processes of a grading: the supervisor's marks in their environment (the judge's).
_MARKS = tuple(('\0%s=' % name).encode() for name in (MARKER, OWNER))


def leftover(pid):
    """Whether process ``pid`` is one a grading started, so one that may be ended when its slot's lock is
    free: its environment carries the supervisor's marks (the judge's processes), or it is a box's
    (bubblewrap, or in a PID namespace below this one: every process of a box is). False once it is gone."""
    try:
        with open('/proc/%d/environ' % pid, 'rb') as f:
            environ = b'\0' + f.read()
        with open('/proc/%d/cmdline' % pid, 'rb') as f:
            program = os.path.basename(f.read().split(b'\0')[0])
        with open('/proc/%d/status' % pid) as f:
            nspids = next((line.split()[1:] for line in f if line.startswith('NSpid:')), [])
    except OSError:
        return False
    return any(mark in environ for mark in _MARKS) or program == b'bwrap' or len(nspids) > 1


def pids_of_uid(uid):
    """Living processes whose real or effective uid is ``uid`` (zombies left out: they are dead)."""
    found = []
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open('/proc/%s/status' % entry) as f:
                status = dict(line.split(':', 1) for line in f if ':' in line)
        except (OSError, ValueError):
            continue
        uids = status.get('Uid', '').split()
        if status.get('State', '').strip().startswith('Z') or len(uids) < 2:
            continue
        if str(uid) in uids[:2]:
            found.append(int(entry))
    return found


def left_behind(base):
    """The uids ``base + N`` (``BOX_UID_BASE`` or ``JUDGE_UID_BASE``) with a living process while no
    grader holds slot N: what a grading left behind. A slot another grader holds is that grading's
    business, so two graders on one machine never take each other's boxes for leftovers."""
    found = []
    for slot in range(SLOTS):
        if pids_of_uid(base + slot) and not _held(slot):
            found.append(base + slot)
    return found


def _held(slot):
    """Whether a grader holds slot ``slot``'s lock now (tried without waiting, and let go at once)."""
    try:
        lock = open(os.path.join(LOCK_DIR, 'box-%d' % slot))
    except FileNotFoundError:
        return False
    with lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            return True
        return False


def end_uid(uid):
    """Kill whatever still runs as ``uid``; returns how many there were."""
    left = pids_of_uid(uid)
    for _ in range(3 if left else 0):
        for pid in pids_of_uid(uid):
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        if wait_until(lambda: not pids_of_uid(uid), 5.0, period=0.05):
            break
    return len(left)


if __name__ == '__main__':
    if len(sys.argv) == 3 and sys.argv[1] == '--end-slot':
        end_slot(int(sys.argv[2]))

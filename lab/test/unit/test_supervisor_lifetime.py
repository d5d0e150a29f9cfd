"""Every process a run starts ends with the run's owner, however it ends (harness.supervisor's "Lifetime"),
on plain processes: an owner (a Python process that calls own_processes, as grade.py does) starts a
shell through its Supervisor that leaves an orphan behind (``sleep &``: as roscore's rosmaster, no parent
death signal of its own), then is killed or stopped; no process of its mark may be left. And the
parent death signal alone across a change of uid, and a slot's start sweep (host/uids.py)."""
import os
import signal
import subprocess
import sys
import textwrap

import pytest

from exam_lab.harness.supervisor import OWNER, alive, marked, owner_mark
from exam_lab.harness.wait import wait_until

#: The owner: its Supervisor's shell starts an orphan and a child, then says so on stdout.
OWNER_SCRIPT = textwrap.dedent('''
    import sys, time
    from exam_lab.harness.supervisor import Supervisor, own_processes
    own_processes()
    with Supervisor(sys.argv[1]) as sup:
        sup.start('family', ['sh', '-c', 'sleep 300 & echo started; exec sleep 301'])
        while 'started' not in sup.output('family'):
            time.sleep(0.02)
        print('ready', flush=True)
        time.sleep(300)
''')
#: Generous: the watch's round is a SIGINT, then a SIGKILL 2 s later, on a shared machine.
GONE_S = 30.0


def start_owner(tmp_path):
    """The owner, started as from a terminal (Ctrl-C and SIGHUP not ignored, whatever this process
    ignores), once its two sleeps and its watch run; ``(its Popen, its mark)``."""
    owner = subprocess.Popen(['env', '--default-signal=INT,HUP', sys.executable, '-c', OWNER_SCRIPT,
                              str(tmp_path / 'run')], stdout=subprocess.PIPE, universal_newlines=True)
    assert owner.stdout.readline().strip() == 'ready'
    mark = owner_mark(owner.pid)
    assert wait_until(lambda: _names(marked(mark, OWNER)) == ['python', 'sleep', 'sleep'], 10.0), \
        _names(marked(mark, OWNER))  # the watch, and the shell's two sleeps
    return owner, mark


def _names(pids):
    names = []
    for pid in pids:
        try:
            with open('/proc/%d/comm' % pid) as f:
                name = f.read().strip()
        except OSError:
            continue
        names.append('python' if name.startswith('python') else name)
    return sorted(names)


@pytest.mark.parametrize('sig', [signal.SIGKILL, signal.SIGTERM, signal.SIGINT, signal.SIGHUP],
                         ids=lambda s: signal.Signals(s).name)
def test_every_process_of_the_owner_ends_with_it(tmp_path, sig):
    owner, mark = start_owner(tmp_path)
    owner.send_signal(sig)
    status = owner.wait(GONE_S)
    left = wait_until(lambda: not marked(mark, OWNER), GONE_S, period=0.1)
    for pid in marked(mark, OWNER):  # a failure leaves nothing behind either
        os.kill(pid, signal.SIGKILL)
    assert left, 'left running after the owner\'s %s' % signal.Signals(sig).name
    assert status == -signal.SIGKILL if sig == signal.SIGKILL else status != 0


def test_a_grading_leftover_is_told_from_a_stranger(tmp_path):
    """The start sweep of a slot (uids.take_slot) ends only a grading's processes: the supervisor's marks
    in the environment, or a box's; a process of another uid's owner is passed over."""
    from exam_lab.grader.host import uids
    ours = subprocess.Popen(['sleep', '60'], env=dict(os.environ, EXAM_LAB_RUN=str(tmp_path)))
    stranger = subprocess.Popen(['sleep', '60'], env={k: v for k, v in os.environ.items()
                                                       if k not in ('EXAM_LAB_RUN', OWNER)})
    try:
        assert uids.leftover(ours.pid) and not uids.leftover(stranger.pid)
    finally:
        for proc in (ours, stranger):
            proc.kill()
            proc.wait()
    assert not uids.leftover(ours.pid)  # gone


#: A parent that starts ``sleep`` under DIES_WITH_PARENT (as another uid when it is root, as the judge
#: and the box are started), says its pid, then waits to be killed.
PARENT_SCRIPT = textwrap.dedent('''
    import os, subprocess, sys, time
    from exam_lab.grader.host import uids
    from exam_lab.harness.supervisor import DIES_WITH_PARENT
    other = uids.as_user(65534) if os.geteuid() == 0 else []
    child = subprocess.Popen(DIES_WITH_PARENT + other + ['sleep', '300'])
    print(child.pid, flush=True)
    time.sleep(300)
''')


def test_a_child_dies_with_its_parent_even_as_another_uid():
    """The parent death signal alone (no owner, no watch): SIGKILL of the parent ends its child, also
    when the child changed its uid on the way (which clears the signal unless it is kept)."""
    parent = subprocess.Popen([sys.executable, '-c', PARENT_SCRIPT], stdout=subprocess.PIPE, universal_newlines=True)
    child = int(parent.stdout.readline())
    assert wait_until(lambda: _names([child]) == ['sleep'], 10.0)
    parent.kill()
    parent.wait()
    gone = wait_until(lambda: not alive(child), GONE_S, period=0.05)
    if not gone:
        os.kill(child, signal.SIGKILL)
    assert gone


@pytest.mark.skipif(os.geteuid() != 0, reason='processes of another uid are started by root')
def test_a_slot_ends_what_a_killed_grading_left_in_it_and_nothing_else(tmp_path, monkeypatch):
    """A slot whose lock is free but whose judge uid still runs a marked process (a grader killed
    before it could end it) is taken, the process ended first; a slot whose uid runs a stranger's
    process is passed over, the process left alone. Uids of their own, far from the real slots'."""
    from exam_lab.grader.host import uids
    monkeypatch.setattr(uids, 'LOCK_DIR', str(tmp_path))
    monkeypatch.setattr(uids, 'SLOTS', 1)
    monkeypatch.setattr(uids, 'BOX_UID_BASE', 64100)
    monkeypatch.setattr(uids, 'JUDGE_UID_BASE', 64200)
    plain = {k: v for k, v in os.environ.items() if k not in ('EXAM_LAB_RUN', OWNER)}
    left = subprocess.Popen(uids.as_user(64200) + ['sleep', '60'], env=dict(plain, EXAM_LAB_RUN=str(tmp_path)))
    stranger = None
    try:
        assert wait_until(lambda: uids.pids_of_uid(64200) == [left.pid], 10.0)
        taken = uids.take_slot()
        assert taken is not None and taken[0] == 0 and left.wait(10) == -signal.SIGKILL
        taken[1].close()
        stranger = subprocess.Popen(uids.as_user(64100) + ['sleep', '60'], env=plain)
        assert wait_until(lambda: uids.pids_of_uid(64100) == [stranger.pid], 10.0)
        assert uids.take_slot() is None and stranger.poll() is None
    finally:
        for proc in (left, stranger):
            if proc is not None and proc.poll() is None:
                proc.kill()
                proc.wait()

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


def test_the_watch_runs_what_the_owner_asked_once_it_has_ended(tmp_path):
    """What no mark shows (a box's slot) is ended by what the owner asked its watch to run at its end
    (supervisor.at_owner_end): run once however often asked, and only after the owner is gone."""
    ran = tmp_path / 'ran'
    script = textwrap.dedent('''
        import sys, time
        from exam_lab.harness.supervisor import at_owner_end, own_processes
        own_processes()
        for _ in range(3):
            at_owner_end(['sh', '-c', 'echo x >> "$1"', 'sh', sys.argv[1]])
        print('ready', flush=True)
        time.sleep(300)
    ''')
    owner = subprocess.Popen(['env', '--default-signal=INT,HUP', sys.executable, '-c', script, str(ran)],
                             stdout=subprocess.PIPE, universal_newlines=True)
    assert owner.stdout.readline().strip() == 'ready'
    mark = owner_mark(owner.pid)
    assert not ran.exists()
    owner.kill()
    owner.wait()
    assert wait_until(lambda: not marked(mark, OWNER), GONE_S, period=0.05)  # the watch too: it has run all
    assert ran.read_text() == 'x\n'


@pytest.mark.skipif(os.geteuid() != 0, reason='processes of another uid are started by root')
def test_the_watch_empties_a_slot_whose_box_lost_its_parent(tmp_path, monkeypatch):
    """A box whose bubblewrap was still setting up when its grader died never bound itself to its
    parent: uids.end_slot (what the watch runs for each slot its owner took) ends it, unless a grader
    holds the slot. The box: a real bubblewrap as the slot's uid, without --die-with-parent."""
    import fcntl
    from exam_lab.grader.host import uids
    monkeypatch.setattr(uids, 'LOCK_DIR', str(tmp_path))
    monkeypatch.setattr(uids, 'BOX_UID_BASE', 64100)
    monkeypatch.setattr(uids, 'JUDGE_UID_BASE', 64200)
    box = subprocess.Popen(uids.as_user(64100) + ['bwrap', '--unshare-user', '--unshare-pid', '--dev-bind', '/', '/',
                                                  'sleep', '60'])
    try:
        assert wait_until(lambda: len(uids.pids_of_uid(64100)) == 3, 10.0)  # bwrap, its pid 1, sleep
        with open(str(tmp_path / 'box-0'), 'w') as held:  # another grader's slot: left alone
            fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
            uids.end_slot(0)
            assert len(uids.pids_of_uid(64100)) == 3
        uids.end_slot(0)
        assert uids.pids_of_uid(64100) == []
    finally:
        if box.poll() is None:
            box.kill()
        box.wait()

"""Supervisor.stop and stop_all on plain processes, no master needed."""
import os
import signal
import sys
import time

from exam_lab.harness.supervisor import Supervisor, alive, descendants
from exam_lab.harness.wait import wait_until


def test_stop_all_ends_every_group_in_one_grace_period(tmp_path):
    with Supervisor(tmp_path) as sup:
        # Each ignores Ctrl-C, so only the SIGKILL after the shared grace period ends it, with its child.
        procs = [sup.start('stubborn%d' % i, ['sh', '-c', "trap '' INT; sleep 60 & wait"])
                 for i in range(4)]
        # The shells have set their traps once they have started their sleep.
        assert wait_until(lambda: all(descendants(proc.pid) for proc in procs), 5.0)
        start = time.monotonic()
        statuses = sup.stop_all(procs, grace=1.0)
        assert time.monotonic() - start < 3.0, 'one grace period for all, not one each'
        assert all(status is not None for status in statuses)
        assert not any(alive(proc.pid) for proc in procs)
        assert sup.procs == []


def test_stop_all_lets_a_clean_exit_keep_its_status(tmp_path):
    with Supervisor(tmp_path) as sup:
        quick = sup.start('quick', ['sh', '-c', 'exit 3'])
        quick.wait()
        polite = sup.start('polite', ['sleep', '60'])
        assert sup.stop_all([quick, polite], grace=5.0) == [3, -2]


def test_ctrl_c_reaches_a_child_when_the_supervisor_itself_ignores_it(tmp_path):
    """A supervisor started by nohup or as ``cmd &`` from a script ignores SIGINT, and an ignored
    signal is inherited through exec: its children must still get the user's Ctrl-C."""
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with Supervisor(tmp_path) as sup:
            polite = sup.start('polite', ['sleep', '60'])
            assert sup.stop_all([polite], grace=5.0) == [-signal.SIGINT]
    finally:
        signal.signal(signal.SIGINT, before)


def test_stop_lets_the_children_of_a_leader_that_is_gone_finish(tmp_path):
    """As rosbag record: the leader exits on Ctrl-C at once, its child still closes its file."""
    done = tmp_path / 'closed'
    child = "trap 'sleep 0.5; touch %s; exit 0' INT; while :; do sleep 0.1; done" % done
    leader = 'import subprocess; subprocess.Popen(["sh", "-c", %r]).wait()' % child
    with Supervisor(tmp_path) as sup:
        proc = sup.start('leader', [sys.executable, '-c', leader])
        assert wait_until(lambda: len(descendants(proc.pid)) > 0, 5.0)
        sup.stop(proc, grace=5.0)
        assert os.path.exists(str(done)), 'the child was killed before it finished'

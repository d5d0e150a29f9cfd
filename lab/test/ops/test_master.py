"""The lab's master (harness.supervisor.Master) is roscore's without roscore's roslaunch parent: the same
graph (/rosout subscribed to /rosout, publishing /rosout_agg), roscore's parameters as its
/etc/ros/roscore.xml sets them (``rosversion roslaunch`` and ``rosversion -d`` as printed) and a
/run_id, and a Ctrl-C to its process group ends rosmaster and rosout both (rosout is started from a
background job of bash, which ignores SIGINT unless told otherwise)."""
import os
import re
import signal
import subprocess
import uuid

from exam_lab.harness.supervisor import Supervisor, alive, descendants
from exam_lab.harness.wait import wait_until

#: Generous bounds on a shared machine: a master's start, and the end of both processes after Ctrl-C.
START_S, END_S = 30.0, 30.0


def _rosout_up(master):
    publishers, subscribers, _ = master.system_state()
    return ['/rosout'] == dict(subscribers).get('/rosout') and ['/rosout'] == dict(publishers).get('/rosout_agg')


def test_the_master_is_roscores_and_ends_on_ctrl_c(tmp_path):
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / 'ros_log'), ROS_HOME=str(tmp_path / 'ros_home'))
    with Supervisor(str(tmp_path / 'logs'), env=env) as sup:
        master = sup.start_master(timeout=START_S)
        assert wait_until(lambda: _rosout_up(master), START_S, period=0.05), master.system_state()
        for key, command in (('/rosversion', ['rosversion', 'roslaunch']), ('/rosdistro', ['rosversion', '-d'])):
            printed = subprocess.run(command, stdout=subprocess.PIPE, universal_newlines=True, env=env).stdout
            assert master.graph.getParam(key) == printed, key
        assert uuid.UUID(master.graph.getParam('/run_id'))
        listed = subprocess.run(['rosnode', 'list'], stdout=subprocess.PIPE, universal_newlines=True,
                                env=master.env, timeout=START_S).stdout.split()
        assert listed == ['/rosout']
        family = [master.proc.pid] + descendants(master.proc.pid)
        with open('/proc/%d/cmdline' % family[-1], 'rb') as f:
            assert re.search(rb'rosout\x00__name:=rosout\x00$', f.read())
        os.killpg(master.proc.pid, signal.SIGINT)  # what a user's Ctrl-C does, and Supervisor.stop first
        assert wait_until(lambda: not any(alive(pid) for pid in family) and master.proc.poll() is not None,
                          END_S, period=0.05), [pid for pid in family if alive(pid)]
        assert master.proc.returncode != -signal.SIGKILL

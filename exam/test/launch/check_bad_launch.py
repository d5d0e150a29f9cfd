#!/usr/bin/env python3
"""rostest: a launch whose drone or exam node refuses a parameter ends, with the reason as its last line.

Launched by ``bad_launch.test``. Runs ``tools/run_launch.sh`` (the recipe of ``make run`` and
``make run-submarine``) as a user would, with one bad launch argument, on a master of its own (a free
port, its own log directory), and checks:

- roslaunch stops by itself: the node that refused its parameter is ``required``, so roslaunch reports
  ``REQUIRED process [...] has died!`` and shuts everything down (without it the launch went on forever,
  the exam node "waiting for the first reading");
- the script exits 1 (roslaunch itself exits 0 in that case);
- the last line of the output is the node's FATAL message, naming the parameter and its value.

The master rostest starts for this node is not used.
"""
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

import rospy
import rostest

#: How long a launch may take to start, see its node die and shut down (s); about 4 s on a quiet machine.
DEADLINE = 25.0


def repository():
    """The checkout holding tools/run_launch.sh (this file is reached through the workspace's links)."""
    path = os.path.dirname(os.path.realpath(__file__))
    while not os.path.isfile(os.path.join(path, 'tools', 'run_launch.sh')):
        parent = os.path.dirname(path)
        if parent == path:
            raise RuntimeError('tools/run_launch.sh not found above %s' % __file__)
        path = parent
    return path


def free_port():
    with socket.socket() as sock:
        sock.bind(('localhost', 0))
        return sock.getsockname()[1]


def run_launch(launch, *args):
    """(exit status, seconds, output lines) of tools/run_launch.sh on a master of its own."""
    logs = tempfile.mkdtemp(prefix='exam-bad-launch-')
    env = dict(os.environ, ROS_MASTER_URI='http://localhost:%d' % free_port(), ROS_LOG_DIR=logs)
    env.pop('ROS_NAMESPACE', None)
    command = [os.path.join(repository(), 'tools', 'run_launch.sh'), launch] + list(args)
    start = time.monotonic()
    # A session of its own: on a timeout, roslaunch, its master and its nodes are stopped with the script.
    proc = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            stdin=subprocess.DEVNULL, universal_newlines=True, start_new_session=True)
    try:
        output, _ = proc.communicate(timeout=DEADLINE)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGINT)
        try:
            output, _ = proc.communicate(timeout=10.0)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            output, _ = proc.communicate()
        output += '\n(still running after %.0f s: stopped)' % DEADLINE
    finally:
        shutil.rmtree(logs, ignore_errors=True)
    lines = [line for line in output.splitlines() if line.strip()]
    return proc.returncode, time.monotonic() - start, lines


class BadLaunch(unittest.TestCase):

    def check(self, launch, argument, process, reason):
        status, seconds, lines = run_launch(launch, argument)
        rospy.loginfo('%s %s: exit %d after %.1f s; last line: %s', launch, argument, status, seconds,
                      lines[-1] if lines else '(no output)')
        output = '\n'.join(lines[-15:])
        self.assertEqual(status, 1, 'exit status %d; output ends:\n%s' % (status, output))
        self.assertTrue(any('REQUIRED process [%s-' % process in line for line in lines),
                        'roslaunch did not stop on %s:\n%s' % (process, output))
        self.assertIn(reason, lines[-1], 'the last line is not the reason:\n%s' % output)

    def test_bad_profile_ends_exam_launch(self):
        self.check('exam.launch', 'profile:=bogus', 'mydrone',
                   "parameter /mydrone/profile = 'bogus': unknown profile 'bogus'")

    def test_bad_threshold_ends_exam_submarine_launch(self):
        self.check('exam_submarine.launch', 'threshold:=deep', 'exam',
                   "parameter /exam/threshold = 'deep'")


if __name__ == '__main__':
    rospy.init_node('check_bad_launch')
    rostest.rosrun('exam', 'bad_launch', BadLaunch, sys.argv)

#!/usr/bin/env python3
"""rostest: each bad parameter makes the exam node log it and exit non-zero within seconds.

Launched alone by ``bad_params.test``: this test starts each exam node itself, as a child process
under a name of its own (``exam_<test method>``), with exactly one bad private parameter set on the
master beforehand. A fresh name per test matters: private parameters outlive the node on the master,
so a leftover from one case would otherwise leak into the next. A good run under the same harness must
keep running, or a node that dies on every start would pass.

Parameters set on the master: ``/exam_<test method>/<param>`` (deleted after each test).
"""
import signal
import subprocess
import sys
import unittest

import roslib.packages
import rosgraph
import rospy
import rostest

from exam_lab.harness.wait import wait_until

# Seconds within which a bad parameter must have ended the node: rospy start-up on a loaded machine
# takes one or two of them.
EXIT_WITHIN = 10.0

def renderings(value):
    """The ways a log line may print ``value`` (str, repr, %g), any of which names it."""
    if isinstance(value, float):
        return {str(value), repr(value), '%g' % value}
    return {str(value)}


def exam_node_script():
    found = roslib.packages.find_node('exam', 'exam_node.py')
    if not found:
        raise AssertionError('exam_node.py not found in package exam')
    return found[0]


class BadParams(unittest.TestCase):

    def run_node(self, name, params):
        """Start the exam node as ``/name`` with these private params; return the process."""
        for key, value in params.items():
            rospy.set_param('/%s/%s' % (name, key), value)
        self.addCleanup(self.forget_params, name)
        return subprocess.Popen([sys.executable, exam_node_script(), '__name:=' + name],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                universal_newlines=True)

    @staticmethod
    def forget_params(name):
        if rospy.has_param('/' + name):
            rospy.delete_param('/' + name)

    def check_exits(self, key, value):
        """The node with ``~key`` = ``value`` exits non-zero in time, naming the parameter and value."""
        name = 'exam_' + self._testMethodName
        process = self.run_node(name, {key: value})
        try:
            output, _ = process.communicate(timeout=EXIT_WITHIN)
        except subprocess.TimeoutExpired:
            process.kill()
            process.communicate()
            self.fail('~%s=%r: the node still ran after %.0f s' % (key, value, EXIT_WITHIN))
        self.assertNotEqual(process.returncode, 0, '~%s=%r: exit status 0' % (key, value))
        resolved = '/%s/%s' % (name, key)
        self.assertIn(resolved, output,
                      '~%s=%r: the log does not name %s:\n%s' % (key, value, resolved, output))
        self.assertTrue(any(text in output for text in renderings(value)),
                        '~%s=%r: the log does not show the value:\n%s' % (key, value, output))

    def test_unknown_mode(self):
        self.check_exits('mode', 'foo')

    def test_threshold_nan(self):
        self.check_exits('threshold', float('nan'))

    def test_threshold_inf(self):
        self.check_exits('threshold', float('inf'))

    def test_threshold_not_a_number(self):
        self.check_exits('threshold', 'abc')

    def test_negative_delay(self):
        self.check_exits('delay', -1.0)

    def test_zero_rate(self):
        self.check_exits('rate', 0.0)

    def test_zero_timeout(self):
        self.check_exits('timeout', 0.0)

    def test_good_params_keep_running(self):
        name = 'exam_good'
        process = self.run_node(name, {'threshold': 1500.0, 'delay': 0.0, 'rate': 20.0, 'timeout': 2.0})
        try:
            master = rosgraph.Master(rospy.get_name())

            def registered():
                try:
                    master.lookupNode('/' + name)
                    return True
                except rosgraph.MasterError:
                    return process.poll() is not None
            self.assertTrue(wait_until(registered, EXIT_WITHIN))
            # Running for a few seconds more, so the bad cases above fail by their params only.
            if wait_until(lambda: process.poll() is not None, 3.0):
                self.fail('a valid node exited:\n%s' % process.communicate()[0])
        finally:
            if process.poll() is None:
                process.send_signal(signal.SIGINT)
                try:
                    process.communicate(timeout=EXIT_WITHIN)
                except subprocess.TimeoutExpired:
                    process.kill()
                    process.communicate()


if __name__ == '__main__':
    rospy.init_node('bad_params')
    rostest.rosrun('exam_lab', 'bad_params', BadParams, sys.argv)

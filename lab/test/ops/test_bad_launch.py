"""A launch whose drone or exam node refuses a parameter ends, with the reason as its last line.

Runs ``tools/run_launch.sh`` (the recipe of ``make run`` and ``make run-submarine``) as a user would,
with one bad launch argument, against a master port of its own (roslaunch starts the master), and
checks:

- roslaunch stops by itself: the node that refused its parameter is ``required``, so roslaunch reports
  ``REQUIRED process [...] has died!`` and shuts everything down (without it the launch went on forever,
  the exam node "waiting for the first reading");
- the script exits 1 (roslaunch itself exits 0 in that case);
- the last line of the output is the node's FATAL message, naming the parameter and its value.
"""
import os

import pytest

from exam_lab.harness.supervisor import Supervisor, free_port

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
#: How long a launch may take to start, see its node die and shut down (s); about 4 s on a quiet machine.
DEADLINE = 25.0


@pytest.mark.parametrize('launch, argument, process, reason', [
    ('exam.launch', 'profile:=bogus', 'mydrone',
     "parameter /mydrone/profile = 'bogus': unknown profile 'bogus'"),
    ('exam_submarine.launch', 'threshold:=deep', 'exam', "parameter /exam/threshold = 'deep'"),
])
def test_bad_parameter_ends_the_launch(tmp_path, launch, argument, process, reason):
    with Supervisor(tmp_path) as procs:
        env = dict(procs.env, ROS_MASTER_URI='http://localhost:%d' % free_port())
        env.pop('ROS_NAMESPACE', None)
        status, output, seconds = procs.run('launch', [os.path.join(REPO, 'tools', 'run_launch.sh'),
                                                       launch, argument], timeout=DEADLINE, env=env)
    lines = [line for line in output.splitlines() if line.strip()]
    print('%s %s: exit %s after %.1f s; last line: %s' % (launch, argument, status, seconds,
                                                         lines[-1] if lines else '(no output)'))
    tail = '\n'.join(lines[-15:])
    assert status == 1, 'exit status %s (None: still running after %.0f s); output ends:\n%s' % (
        status, DEADLINE, tail)
    assert any('REQUIRED process [%s-' % process in line for line in lines), \
        'roslaunch did not stop on %s:\n%s' % (process, tail)
    assert reason in lines[-1], 'the last line is not the reason:\n%s' % tail

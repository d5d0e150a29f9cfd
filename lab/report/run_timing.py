"""README's `make run` timings, measured from a real run, never typed.

Starts ``tools/run_launch.sh exam.launch`` (what `make run` runs), then ``exam_submarine.launch``, each
on a master of its own, and notes when the banner ("Running: roslaunch ...") appears and when the
drone's LED topic (``/alt_warn_led``, ``/depth_warn_led``, latched) first says RED after it, then GREEN
again. Everything is stopped as a user would (Ctrl-C) by the lab's supervisor. It writes, between the
markers of README.md, the sentence that quotes those times with the run's date and commit. About 75 s a
launch. The docs test (lab/test/docs/test_docs_quote_code.py) holds the block to that form and to the
banner's own "about N s" promises.

Usage (in the workspace environment: ``source tools/env.sh``)::

    python3 lab/report/run_timing.py
"""
import datetime
import os
import sys
import tempfile
import threading
import time

import console_excerpt  # the block splicing and the commit, shared with the other generated excerpts
from exam_lab.harness.supervisor import Supervisor
from exam_lab.harness.wait import wait_until

REPO = console_excerpt.REPO
DOC = os.path.join(REPO, 'README.md')
BEGIN = '<!-- run timing: written by lab/report/run_timing.py from a run of tools/run_launch.sh; do not edit -->'
END = '<!-- end of run timing -->'
BANNER = 'Running: roslaunch exam '
#: (launch file, LED topic) of `make run` and `make run-submarine`.
LAUNCHES = (('exam.launch', '/alt_warn_led'), ('exam_submarine.launch', '/depth_warn_led'))
#: The default flight reaches RED about 50 s after the banner and GREEN 22 s later: a run that has not
#: seen both within this long has failed, and says so rather than hang.
TIMEOUT_S = 150.0


class Led(object):
    """The LED's messages as they arrive: [(monotonic time, colour)]."""

    def __init__(self, topic):
        import rospy
        from std_msgs.msg import String
        self.lock = threading.Lock()
        self.seen = []
        self.sub = rospy.Subscriber(topic, String, self._on_message)

    def _on_message(self, msg):
        with self.lock:
            self.seen.append((time.monotonic(), msg.data))

    def first(self, colour, after):
        """Time of the first ``colour`` at or after ``after``, or None."""
        with self.lock:
            return next((t for t, c in self.seen if c == colour and t >= after), None)


def measure(supervisor, launch, topic):
    """(seconds to RED, seconds to GREEN) after the banner of one `make run`."""
    import rospy
    master = supervisor.start_master(launch + '.master')
    # This process's own node (the LED's listener) joins that master and logs into the run's folder.
    os.environ.update((k, master.env[k]) for k in ('ROS_MASTER_URI', 'ROS_LOG_DIR', 'ROS_HOME'))
    rospy.init_node('run_timing', anonymous=True, disable_signals=True)
    led = Led(topic)
    try:
        proc = supervisor.start(launch, [os.path.join(REPO, 'tools', 'run_launch.sh'), launch], master.env)
        alive = lambda: proc.poll() is None  # noqa: E731
        banner = wait_until(lambda: BANNER in supervisor.output(launch) and time.monotonic(), 30.0, alive=alive)
        if banner is None:
            raise RuntimeError('no banner from %s; see %s' % (launch, supervisor.log(launch)))
        red = wait_until(lambda: led.first('RED', banner), TIMEOUT_S, alive=alive)
        green = red and wait_until(lambda: led.first('GREEN', red), TIMEOUT_S, alive=alive)
        if not green:
            raise RuntimeError('%s: no RED then GREEN on %s within %.0f s; see %s'
                               % (launch, topic, TIMEOUT_S, supervisor.log(launch)))
        supervisor.stop(proc)
        return red - banner, green - banner
    finally:
        led.sub.unregister()
        rospy.signal_shutdown('measured')
        master.kill()


def block(times, date, commit):
    """README's sentences, between (and with) the markers."""
    (red, green), (red_sub, green_sub) = times
    return '\n'.join([
        BEGIN,
        'Measured by `lab/report/run_timing.py` on %s at commit %s: `data: "RED"` %.1f s after that '
        'banner, `data: "GREEN"` %.1f s after it. `make run-submarine` runs the underwater drone instead '
        '(`/depth`, `/depth_warn_led`: RED %.1f s, GREEN %.1f s after the banner).'
        % (date, commit, red, green, red_sub, green_sub),
        END])


def main():
    date = datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M UTC')
    commit = console_excerpt.commit()  # the code that runs, before anything is written
    times = []
    # rospy allows one init_node per process: each launch is measured in a process of its own.
    if len(sys.argv) == 3 and sys.argv[1] == '--one':
        launch, topic = [pair for pair in LAUNCHES if pair[0] == sys.argv[2]][0]
        with tempfile.TemporaryDirectory(prefix='run-timing-') as scratch, Supervisor(scratch) as supervisor:
            print('%.3f %.3f' % measure(supervisor, launch, topic))
        return
    import subprocess
    for launch, topic in LAUNCHES:
        out = subprocess.run([sys.executable, os.path.realpath(__file__), '--one', launch], stdout=subprocess.PIPE,
                             universal_newlines=True)
        if out.returncode != 0:
            sys.exit('run_timing: %s failed; README.md is left as it was' % launch)
        times.append(tuple(float(x) for x in out.stdout.split()[-2:]))
        print('run_timing: %s: RED %.1f s, GREEN %.1f s after the banner' % ((launch,) + times[-1]))
    with open(DOC, encoding='utf-8') as f:
        text = f.read()
    with open(DOC, 'w', encoding='utf-8') as f:
        f.write(console_excerpt.splice(text, block(times, date, commit), BEGIN, END))
    print('run_timing: written into README.md')


if __name__ == '__main__':
    main()

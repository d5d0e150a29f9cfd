"""Process helpers for the pytest operations tests: ROS environments, and process groups that are
always stopped (SIGINT, then SIGKILL), whatever the test's outcome. Imported, not a test.
"""
import os
import signal
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PROBE = os.path.join(HERE, 'probe.py')


def free_port():
    """A TCP port free right now on this host (for a master of our own)."""
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


def ros_env(master_uri, log_dir, ip=None):
    """The environment of a ROS process: its master, where it logs, and the address it advertises."""
    env = dict(os.environ, ROS_MASTER_URI=master_uri, ROS_LOG_DIR=str(log_dir), PYTHONUNBUFFERED='1')
    env.pop('ROS_HOSTNAME', None)
    env.pop('ROS_IP', None)
    if ip is not None:
        env['ROS_IP'] = ip
    return env


class Processes(object):
    """Starts processes in their own sessions and stops every one of them on exit from the `with`."""

    def __init__(self, log_dir):
        self.log_dir = str(log_dir)
        self.procs = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.stop_all()
        return False

    def start(self, name, cmd, env):
        """Start cmd; its output goes to LOG_DIR/name.out (read it with output())."""
        out = open(os.path.join(self.log_dir, name + '.out'), 'wb')
        proc = subprocess.Popen(cmd, env=env, stdout=out, stderr=subprocess.STDOUT,
                                start_new_session=True)
        out.close()
        self.procs.append((name, proc))
        return proc

    def output(self, name):
        with open(os.path.join(self.log_dir, name + '.out'), errors='replace') as out:
            return out.read()

    @staticmethod
    def stop(proc, grace=15.0):
        """Ctrl-C the process group, as a user would; SIGKILL what is left after `grace` seconds.

        roslaunch (hence roscore) starts each node in a session of its own, so the group alone does not
        hold the nodes: their launcher stops them on SIGINT, and the SIGKILL fallback takes every
        descendant found in /proc beforehand.
        """
        if proc.poll() is not None:
            return proc.returncode
        family = descendants(proc.pid)
        try:
            os.killpg(proc.pid, signal.SIGINT)
            return proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            for pid in [proc.pid] + family:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            return proc.wait()
        except ProcessLookupError:
            return proc.wait()

    def stop_all(self):
        for _name, proc in reversed(self.procs):
            self.stop(proc)


def descendants(pid):
    """Pids of every living descendant of pid, from the parent links in /proc."""
    children = {}
    for entry in os.listdir('/proc'):
        if entry.isdigit():
            try:
                with open('/proc/%s/stat' % entry) as stat:
                    ppid = int(stat.read().rsplit(')', 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def probe(args, env, prefix=(), timeout=90.0):
    """Run probe.py (optionally under a prefix such as `ip netns exec NS`); returns (ok, output)."""
    cmd = list(prefix) + [sys.executable, PROBE] + list(args)
    try:
        done = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                              timeout=timeout, universal_newlines=True)
    except subprocess.TimeoutExpired as err:
        return False, 'probe timed out: %s' % err
    return done.returncode == 0, done.stdout


def wait_until(predicate, timeout, period=0.2):
    """Poll predicate until true or timeout [s]; returns its last value."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value or time.monotonic() >= deadline:
            return value
        time.sleep(period)

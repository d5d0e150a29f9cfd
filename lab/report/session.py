"""The processes of one report run: masters on free ports, background nodes, bounded commands.

Every process gets ROS_HOME and ROS_LOG_DIR inside this run's private folder (``run_dir``) and the
variable EXAM_REPORT_RUN=<run_dir>, which the nodes roslaunch starts in sessions of their own inherit
too, so :func:`leftovers` finds exactly this run's processes and :meth:`Session.close` ends them by pid. lab/report/report.sh calls ``session.py --cleanup <run_dir>``
from its trap in case this Python process itself dies.
"""
import os
import shlex
import signal
import socket
import subprocess
import sys
import time


def free_port():
    """A TCP port nobody listens on right now: bind port 0 and let the kernel choose."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


def leftovers(run_dir):
    """Pids of the processes started for this run: their environment carries EXAM_REPORT_RUN=run_dir.

    Children inherit the environment, and roslaunch passes its own to the nodes it starts in sessions
    of their own; the processes that started this run (the shell, make) do not carry it.
    """
    marker = b'\0EXAM_REPORT_RUN=' + run_dir.encode() + b'\0'
    pids = []
    for entry in os.listdir('/proc'):
        if not entry.isdigit() or int(entry) == os.getpid():
            continue
        try:
            with open('/proc/%s/environ' % entry, 'rb') as f:
                environ = b'\0' + f.read()
        except OSError:
            continue
        if marker in environ:
            pids.append(int(entry))
    return pids


def end_pids(pids, grace=5.0):
    """SIGINT (a clean rospy shutdown), then SIGKILL what is still there after ``grace`` seconds."""
    for pid in pids:
        _kill(pid, signal.SIGINT)
    deadline = time.monotonic() + grace
    while time.monotonic() < deadline and any(_alive(pid) for pid in pids):
        time.sleep(0.1)
    for pid in pids:
        if _alive(pid):
            _kill(pid, signal.SIGKILL)


def _kill(pid, sig):
    try:
        os.kill(pid, sig)
    except ProcessLookupError:
        pass


def _alive(pid):
    try:
        with open('/proc/%d/stat' % pid) as f:
            return f.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except OSError:
        return False


class Master(object):
    """One roscore on a free port, and the environment that talks to it."""

    def __init__(self, session, name):
        import rosgraph  # only once the ROS environment is known to be there
        self.port = free_port()
        self.uri = 'http://127.0.0.1:%d/' % self.port
        self.env = dict(session.env, ROS_MASTER_URI=self.uri)
        self.proc = session.start(name + '.roscore', 'roscore -p %d' % self.port, self.env)
        self.graph = rosgraph.Master('/report', master_uri=self.uri)
        session.wait_for('master on port %d' % self.port, self.graph.is_online, 30.0, self.proc)

    def publishers(self, topic):
        """Nodes publishing ``topic`` right now."""
        for name, nodes in self.graph.getSystemState()[0]:
            if name == topic:
                return nodes
        return []

    def subscribers(self, topic):
        """Nodes subscribed to ``topic`` right now."""
        for name, nodes in self.graph.getSystemState()[1]:
            if name == topic:
                return nodes
        return []


class Session(object):
    """Starts processes for the report and ends every one of them on close (use it as a context)."""

    def __init__(self, run_dir, work_dir):
        self.run_dir = run_dir
        self.work_dir = work_dir
        self.env = dict(os.environ, ROS_HOME=os.path.join(run_dir, 'ros_home'),
                        ROS_LOG_DIR=os.path.join(run_dir, 'log'), PYTHONUNBUFFERED='1',
                        EXAM_REPORT_RUN=run_dir)
        self.procs = []
        #: command key -> {'line', 'output', 'status', ...}, filled by collect.py.
        self.results = {}

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def console(self, name):
        return os.path.join(self.run_dir, name + '.console')

    def start(self, name, line, env, cwd=None):
        """Start ``line`` in the background, in a session of its own; its console goes to a file."""
        with open(self.console(name), 'wb') as out:
            proc = subprocess.Popen(shlex.split(line), env=env, cwd=cwd or self.work_dir, stdout=out,
                                    stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL,
                                    start_new_session=True)
        self.procs.append(proc)
        return proc

    def stop(self, proc, grace=10.0):
        """SIGINT to the process group (as Ctrl-C), SIGKILL after ``grace`` seconds."""
        try:
            os.killpg(proc.pid, signal.SIGINT)
        except ProcessLookupError:
            pass
        try:
            proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            proc.wait()
        if proc in self.procs:
            self.procs.remove(proc)

    def run(self, command, env, cwd=None):
        """Run a Command to completion; return (its output, exit status, seconds it took)."""
        start = time.monotonic()
        try:
            done = subprocess.run(shlex.split(command.line), env=env, cwd=cwd or self.work_dir,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                  stdin=subprocess.DEVNULL, timeout=command.limit,
                                  start_new_session=True)
            output, status = done.stdout.decode('utf-8', 'replace'), done.returncode
        except subprocess.TimeoutExpired as err:
            output = (err.output or b'').decode('utf-8', 'replace')
            status = 'killed after %d s' % command.limit
        return output.rstrip(), status, time.monotonic() - start

    def wait_for(self, what, condition, timeout, proc=None):
        """Poll ``condition`` until it holds; raise if ``proc`` dies or ``timeout`` seconds pass."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if proc is not None and proc.poll() is not None:
                raise RuntimeError('waiting for %s: process exited with %s' % (what, proc.returncode))
            try:
                if condition():
                    return
            except OSError:  # the master is not up yet
                pass
            time.sleep(0.2)
        raise RuntimeError('%s not there after %.0f s' % (what, timeout))

    def close(self):
        """Stop what was started, newest first, then anything else that carries this run's marker."""
        for proc in reversed(list(self.procs)):
            self.stop(proc, grace=5.0)
        end_pids(leftovers(self.run_dir))


if __name__ == '__main__':
    if len(sys.argv) == 3 and sys.argv[1] == '--cleanup':
        end_pids(leftovers(sys.argv[2]))
    else:
        sys.exit('usage: session.py --cleanup RUN_DIR')

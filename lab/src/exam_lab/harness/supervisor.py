"""The lab's supervisor of ROS processes: masters on free ports, nodes in process groups, logs kept.

Everything the lab starts from outside the product goes through :class:`Supervisor`: the operations
tests, the benchmark, the report generator, the soak run and the grader. One run's processes share a
log folder and a marker in their environment (``EXAM_LAB_RUN=<log folder>``). roslaunch starts each
node in a session of its own, so a process group does not hold a launch's nodes; the marker does, since
children inherit the environment. :meth:`Supervisor.close` therefore ends exactly this run's processes,
and ``python3 -m exam_lab.harness.supervisor --cleanup DIR`` does the same from a shell trap when the
Python process that started them died.

Stopping is what a user does: Ctrl-C (SIGINT) to the process group, so rospy shuts down cleanly and
roslaunch stops its nodes; SIGKILL for whatever is left after a grace period.

Lifetime: every process a run starts ends when the process that owns the run ends, however it ends
(Ctrl-C, SIGTERM, SIGHUP of a closed terminal, SIGKILL, a crash). No one mechanism covers every way:

- **The parent's death.** Every process :meth:`Supervisor.start` starts (and the grader's other
  children) runs under :data:`DIES_WITH_PARENT`: the kernel SIGKILLs it when the *thread* that started
  it ends, the whole process with it, SIGKILL included. A change of uid clears that signal: the
  judge's and the box's ``setpriv --reuid`` set it again (``--pdeathsig keep``), and a box's
  bubblewrap has ``--die-with-parent``, its PID namespace taking every process of the box with it.
  Start processes from a thread that lives as long as they should (the main thread, a pool's worker).
- **The owner's watch.** A process the started ones start in turn (a master's rosout, a launch's
  nodes) gets no such signal, and an orphan is not killed with its parent. So the run's owner (a
  script as it starts: grade.py, check.py; never a library function, since it changes
  this process's signals) calls :func:`own_processes`: from then on every process started carries
  ``EXAM_LAB_OWNER=<its owner's pid and start time>`` (:data:`OWNER`, inherited down every chain,
  added by :meth:`Supervisor.start` to environments built from scratch), and a watch process in a
  session of its own waits for the end of a pipe only the owner holds (any end closes it), then ends
  whatever still carries that mark. A box's processes, whose environment is emptied, are ended by
  bubblewrap, and, should its bubblewrap have died while the box was still being set up (before
  it bound itself to its parent), by the watch again: the owner tells it each box slot it takes
  (:func:`at_owner_end`), whose uids it empties once no grader holds the slot.
- **Signals.** :func:`own_processes` turns SIGTERM and SIGHUP into KeyboardInterrupt, as Ctrl-C is, so
  the owner's ``finally`` blocks and :meth:`Supervisor.close` stop what they started as a user would
  (an ignored SIGHUP, ``nohup``'s, stays ignored).

Usage::

    with Supervisor(log_dir) as sup:
        master = sup.start_master()
        node = sup.start('exam', ['rosrun', 'exam', 'exam_node.py'], master.env)
        ...
    # every process of the run is gone here; the logs stay in log_dir
"""
import json
import os
import signal
import socket
import subprocess
import sys
import time
import uuid

from exam_lab.harness.wait import wait_until

#: Environment variable that marks every process of one supervised run.
MARKER = 'EXAM_LAB_RUN'
#: Run before a command when this process ignores SIGINT (started by nohup, as ``cmd &`` from a script,
#: from cron): an ignored signal stays ignored through exec, so without it Ctrl-C would not reach a
#: child that keeps the default (a ``sleep``, a student's shell script), which would sit out its grace
#: period and be killed. coreutils' ``env`` resets it and execs the command (same pid).
DEFAULT_SIGINT = ['env', '--default-signal=INT']
#: Run before a command so that the kernel SIGKILLs it when the thread that started it ends (util-linux's
#: setpriv sets the parent death signal, then execs the command: same pid). The module's "Lifetime".
DIES_WITH_PARENT = ['setpriv', '--pdeathsig', 'KILL', '--']
#: Environment variable that marks every process a run's owner started (:func:`own_processes`).
OWNER = 'EXAM_LAB_OWNER'


def free_port():
    """A TCP port nobody listens on right now: bind port 0 on loopback and let the kernel choose."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


def ros_env(base, master_uri, log_dir, ip=None):
    """The environment of a ROS process: ``base`` plus its master, where it logs, what it advertises.

    ROS_HOSTNAME and ROS_IP are dropped unless ``ip`` is given (then ROS_IP=ip), so a test's nodes
    never advertise an address inherited from the developer's shell.
    """
    env = dict(base, ROS_MASTER_URI=master_uri, ROS_LOG_DIR=str(log_dir),
               ROS_HOME=os.path.join(str(log_dir), 'ros_home'), PYTHONUNBUFFERED='1')
    env.pop('ROS_HOSTNAME', None)
    env.pop('ROS_IP', None)
    if ip is not None:
        env['ROS_IP'] = ip
    return env


#: Variables through which a sourced catkin workspace (and its underlays) reaches a process.
WORKSPACE_VARS = ('CMAKE_PREFIX_PATH', 'ROS_PACKAGE_PATH', 'PYTHONPATH', 'LD_LIBRARY_PATH',
                  'PKG_CONFIG_PATH', 'ROSLISP_PACKAGE_DIRECTORIES', 'CPATH', 'PATH')


def workspace_env(setup_script, base=None, timeout=60.0):
    """The environment of ``base`` (default: this process's) once ``setup_script`` is sourced in bash,
    without any workspace ``base`` had sourced: a catkin workspace's own view, with only its
    underlays. PATH keeps /usr/bin first (ROS 1 needs the system python3).

    Used to build a package against one workspace and to run its nodes in it (the grader's student
    workspaces); the caller's own workspace never leaks in.
    """
    env = dict(os.environ if base is None else base)
    for name in WORKSPACE_VARS:
        env.pop(name, None)
    env['PATH'] = '/usr/bin:/bin:/usr/sbin:/sbin:/usr/local/bin'
    out = subprocess.run(['bash', '-c', 'source "$1" >/dev/null 2>&1 && env -0', 'bash', str(setup_script)],
                         env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, timeout=timeout,
                         check=True).stdout
    sourced = dict(item.split('=', 1) for item in out.decode('utf-8', 'replace').split('\0') if '=' in item)
    return {name: value for name, value in sourced.items() if name not in ('_', 'SHLVL', 'PWD', 'OLDPWD')}


def cmdline(pid):
    """The command line of process ``pid``, its arguments joined by spaces; '' once it is gone."""
    try:
        with open('/proc/%d/cmdline' % pid, 'rb') as f:
            return f.read().replace(b'\0', b' ').decode('utf-8', 'replace')
    except OSError:
        return ''


def descendants(pid):
    """Pids of every living descendant of ``pid``, from the parent links in /proc."""
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


def marked(run_dir, variable=MARKER):
    """Pids of the processes whose environment carries ``EXAM_LAB_RUN=run_dir`` (``variable=run_dir``:
    an owner's :data:`OWNER` mark), this one excluded."""
    marker = ('\0%s=%s\0' % (variable, run_dir)).encode()
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


def alive(pid):
    """True while ``pid`` exists and is not a zombie."""
    try:
        with open('/proc/%d/stat' % pid) as f:
            return f.read().rsplit(')', 1)[1].split()[0] != 'Z'
    except (OSError, IndexError):
        return False


def end_pids(pids, grace=5.0):
    """SIGINT each pid, then SIGKILL those still alive after ``grace`` seconds."""
    for pid in pids:
        _kill(pid, signal.SIGINT)
    wait_until(lambda: not any(alive(pid) for pid in pids), grace, period=0.05)
    for pid in pids:
        if alive(pid):
            _kill(pid, signal.SIGKILL)


def _kill(pid, sig):
    try:
        os.kill(pid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def _killpg(pgid, sig):
    try:
        os.killpg(pgid, sig)
    except (ProcessLookupError, PermissionError):
        pass


def node_pid(name, master_uri=None, caller='/exam_lab'):
    """Pid of the running node ``name`` (asked over its XML-RPC API), or None when it is not reachable.

    :param master_uri: the master to ask (default: ROS_MASTER_URI of this process).
    """
    import rosgraph
    from xmlrpc.client import ServerProxy
    try:
        uri = rosgraph.Master(caller, master_uri=master_uri).lookupNode(name)
        code, _msg, pid = ServerProxy(uri).getPid(caller)
        return pid if code == 1 else None
    except (IOError, OSError, rosgraph.MasterException):
        return None


#: The master as ``roscore`` makes it, without roscore's roslaunch parent (measured: 0.65 s of CPU and
#: 0.4 s of wall time less a start, two starts a grading): bash execs rosmaster (the process
#: :attr:`Master.proc` is, same pid), and a child of it starts rosout (``$2...``) once the master's port
#: answers, or ends with the master. A background job of bash ignores SIGINT: rosout is started under
#: DEFAULT_SIGINT, so a Ctrl-C to the group stops both.
_CORE = ('( until (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; do kill -0 $$ 2>/dev/null || exit 0; '
         'sleep 0.05; done; exec "${@:2}" __name:=rosout ) & exec rosmaster --core -p "$1" -w 3')
_found = {}


def _rosout():
    """The rosout executable (the ROS package rosout's), found once."""
    if 'rosout' not in _found:
        from roslib.packages import find_node
        paths = find_node('rosout', 'rosout')
        if not paths:
            raise RuntimeError('no rosout executable: is the ROS package rosout installed?')
        _found['rosout'] = paths[0]
    return _found['rosout']


def _core_params():
    """roscore's parameters (its /etc/ros/roscore.xml): ``rosversion roslaunch`` and ``rosversion -d``
    as their commands print them, a newline included."""
    if 'params' not in _found:
        from rospkg import rosversion
        version = rosversion.get_version_from_package_name('roslaunch') or '<unversioned>'
        distro = os.environ.get('ROS_DISTRO') or rosversion.get_distro_name_from_roscore() or 'Debian'
        _found['params'] = {'/rosversion': version + '\n', '/rosdistro': distro + '\n'}
    return _found['params']


class Master(object):
    """One ROS master on a port of its own, as ``roscore`` makes it (rosmaster, rosout and roscore's
    parameters, :data:`_CORE`), and the environment that talks to it.

    :ivar uri: ``http://127.0.0.1:<port>/``.
    :ivar env: the supervisor's environment with ROS_MASTER_URI set to :attr:`uri`.
    :param wrap: a command-line prefix the master runs under (the grader's: another uid, a cgroup).
    """

    def __init__(self, supervisor, name, port, wrap=()):
        import rosgraph  # only once the ROS environment is known to be there
        self.supervisor = supervisor
        self.name = name
        self.port = port
        self.uri = 'http://127.0.0.1:%d/' % port
        self.env = dict(supervisor.env, ROS_MASTER_URI=self.uri)
        self.graph = rosgraph.Master('/exam_lab', master_uri=self.uri)
        self.wrap = list(wrap)
        self.proc = None

    def start(self, timeout=30.0):
        """Start the master (again, after :meth:`kill`), wait until it answers, and set roscore's
        parameters and a new /run_id (roslaunch's log folder) before anyone else talks to it."""
        argv = ['bash', '-c', _CORE, 'master', str(self.port)] + DEFAULT_SIGINT + [_rosout()]
        self.proc = self.supervisor.start(self.name, self.wrap + argv, self.env)
        wait_until(lambda: self.proc.poll() is not None or self.is_online(), timeout, period=0.05)
        if self.proc.poll() is not None:
            raise RuntimeError('the master on port %d exited with %s; see %s'
                               % (self.port, self.proc.returncode, self.supervisor.log(self.name)))
        if not self.is_online():
            raise RuntimeError('the master on port %d did not answer within %.0f s' % (self.port, timeout))
        for key, value in sorted(dict(_core_params(), **{'/run_id': str(uuid.uuid1())}).items()):
            self.graph.setParam(key, value)
        return self

    def is_online(self):
        try:
            return self.graph.is_online()
        except OSError:
            return False

    def kill(self):
        """SIGKILL the master and its rosout (a crashed ground station); the port stays ours."""
        family = descendants(self.proc.pid)
        _killpg(self.proc.pid, signal.SIGKILL)
        for pid in family:
            _kill(pid, signal.SIGKILL)
        self.proc.wait()

    def system_state(self):
        """(publishers, subscribers, services) as the master lists them: [(name, [nodes])] each."""
        return self.graph.getSystemState()

    def node_pid(self, name):
        """Pid of the node ``name`` registered on this master, or None."""
        return node_pid(name, self.uri)

    def publishers(self, topic):
        return dict(self.system_state()[0]).get(topic, [])

    def subscribers(self, topic):
        return dict(self.system_state()[1]).get(topic, [])


class Supervisor(object):
    """Starts processes in sessions of their own, logs each to ``<log_dir>/<name>.log``, ends them all.

    :param log_dir: the run's folder (created); logs stay there after :meth:`close`.
    :param env: the base environment (default: this process's).
    :param pid_file: if given, every started process's group id is appended to it at once, for a shell
        trap (the marker cleanup is the better way; this is for scripts that predate it).
    :param marker: the run's marker (default the log folder): two supervisors that share a log folder,
        side by side, each end their own processes only.
    """

    def __init__(self, log_dir, env=None, pid_file=None, marker=None):
        self.log_dir = os.path.abspath(str(log_dir))
        os.makedirs(self.log_dir, exist_ok=True)
        self.marker = marker or self.log_dir
        self.env = dict(os.environ if env is None else env)
        self.env[MARKER] = self.marker
        self.env.setdefault('ROS_LOG_DIR', os.path.join(self.log_dir, 'ros_log'))
        self.env.setdefault('ROS_HOME', os.path.join(self.log_dir, 'ros_home'))
        self.env['PYTHONUNBUFFERED'] = '1'
        self.pid_file = pid_file
        self.procs = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def log(self, name):
        """Path of the log of the process started as ``name``."""
        return os.path.join(self.log_dir, name + '.log')

    def output(self, name):
        """What the process started as ``name`` printed so far."""
        try:
            with open(self.log(name), errors='replace') as f:
                return f.read()
        except OSError:
            return ''

    def start(self, name, argv, env=None, cwd=None):
        """Start ``argv`` in the background, in a session (process group) of its own.

        :param env: its environment (default the supervisor's); the run's marker is always added.
        :returns: the ``subprocess.Popen``; stdout and stderr go to :meth:`log`.
        """
        env = dict(self.env if env is None else env)
        env[MARKER] = self.marker
        if OWNER in os.environ:
            env[OWNER] = os.environ[OWNER]
        ignoring = signal.getsignal(signal.SIGINT) == signal.SIG_IGN
        argv = DIES_WITH_PARENT + (DEFAULT_SIGINT if ignoring else []) + list(argv)
        with open(self.log(name), 'ab') as out:
            proc = subprocess.Popen(list(argv), env=env, cwd=cwd, stdout=out, stderr=subprocess.STDOUT,
                                    stdin=subprocess.DEVNULL, start_new_session=True)
        if ignoring:
            # Until `env` has reset it, the child ignores SIGINT as we do: a stop right after the start
            # would be lost. Wait for the reset (or the child's end), a few milliseconds.
            wait_until(lambda: proc.poll() is not None or not _ignores_sigint(proc.pid), 5.0, period=0.005)
        self.procs.append(proc)
        if self.pid_file:
            with open(self.pid_file, 'a') as f:
                f.write('%d\n' % proc.pid)
        return proc

    def run(self, name, argv, timeout, env=None, cwd=None):
        """Run ``argv`` to completion within ``timeout`` s; its whole process group dies at the limit.

        :returns: ``(status, output, seconds)``; status is the exit code, or None when it was killed
            at the time limit. The output is also kept in :meth:`log`.
        """
        start = time.monotonic()
        proc = self.start(name, argv, env, cwd)
        try:
            status = proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            self.stop(proc, grace=2.0)
            status = None
        if proc in self.procs:
            self.procs.remove(proc)
        return status, self.output(name), time.monotonic() - start

    def stop(self, proc, grace=10.0):
        """Ctrl-C the process group, as a user would; SIGKILL the group and every descendant found
        beforehand if it is not gone after ``grace`` s. A leader that exits at once may leave children
        still finishing their work (``rosbag record``'s recorder closing its bag): they get the rest
        of the grace period too. Returns the exit status."""
        return self.stop_all([proc], grace)[0]

    def stop_all(self, procs, grace=10.0):
        """:meth:`stop` for several processes at once: every group gets its Ctrl-C first and they share
        one grace period, so a fleet of nodes stops as fast as one. Returns their exit statuses."""
        procs = list(procs)
        running = [proc for proc in procs if proc.poll() is None]
        families = {proc.pid: descendants(proc.pid) for proc in running}
        for proc in running:
            _killpg(proc.pid, signal.SIGINT)
        deadline = time.monotonic() + grace
        for proc in running:
            try:
                proc.wait(timeout=max(0.0, deadline - time.monotonic()))
            except subprocess.TimeoutExpired:
                pass
        family = [pid for proc in running for pid in families[proc.pid]]
        wait_until(lambda: not any(alive(pid) for pid in family), max(0.0, deadline - time.monotonic()),
                   period=0.1)
        for proc in running:
            # The leader may be gone while a forked child (rosout under roscore) still runs.
            _killpg(proc.pid, signal.SIGKILL)
            for pid in families[proc.pid]:
                if alive(pid):
                    _kill(pid, signal.SIGKILL)
        for proc in procs:
            proc.wait()
            if proc in self.procs:
                self.procs.remove(proc)
        return [proc.returncode for proc in procs]

    def start_master(self, name='master', port=None, timeout=30.0, wrap=()):
        """Start a master (:class:`Master`) on ``port`` (default: a free one) and wait until it answers.

        :param wrap: a command-line prefix the master runs under (see :class:`Master`).
        """
        return Master(self, name, port or free_port(), wrap).start(timeout)

    def close(self, grace=5.0):
        """Stop what was started, newest first, then anything else that carries this run's marker."""
        for proc in reversed(list(self.procs)):
            self.stop(proc, grace)
        end_pids(marked(self.marker), grace)


def _ignores_sigint(pid):
    """Whether process ``pid`` ignores SIGINT (its SigIgn mask in /proc); False once it is gone."""
    try:
        with open('/proc/%d/status' % pid) as f:
            for line in f:
                if line.startswith('SigIgn:'):
                    return bool(int(line.split()[1], 16) & (1 << (signal.SIGINT - 1)))
    except (OSError, ValueError):
        pass
    return False


def owner_mark(pid):
    """The :data:`OWNER` mark of the processes process ``pid`` owns: its pid and start time (a pid used
    again later is another owner), or None when ``pid`` is gone."""
    try:
        with open('/proc/%d/stat' % pid) as f:
            return '%d-%s' % (pid, f.read().rsplit(')', 1)[1].split()[19])
    except (OSError, IndexError):
        return None


#: The write end of the pipe the owner's watch waits on: held open, never written, until this process ends.
_owner = {}


def own_processes():
    """Make this process (a script as it starts, in its main thread) the owner of every process it starts
    from now on, of their children and theirs (the module's "Lifetime"): they carry its :data:`OWNER`
    mark, a watch ends them when this process ends, and SIGTERM and SIGHUP raise KeyboardInterrupt here
    as Ctrl-C does (even when started with SIGINT ignored, a background job of a script: it is the
    user's way to stop it). Returns the mark."""
    if 'mark' not in _owner:
        mark = owner_mark(os.getpid())
        os.environ[OWNER] = mark
        read, write = os.pipe()  # neither end is inherited by the processes started later (PEP 446)
        subprocess.Popen([sys.executable, '-m', 'exam_lab.harness.supervisor', '--watch', mark], stdin=read,
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        os.close(read)
        _owner.update(mark=mark, pipe=write)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, _interrupt)
        if signal.getsignal(signal.SIGHUP) != signal.SIG_IGN:
            signal.signal(signal.SIGHUP, _interrupt)
    return _owner['mark']


def at_owner_end(argv):
    """Have the owner's watch run ``argv`` once this process, the owner, has ended and its marked
    processes are gone: for what the owner took that no mark shows (a box's slot, whose processes'
    environment is emptied). Nothing when this process owns nothing (:func:`own_processes`)."""
    if 'pipe' in _owner:
        os.write(_owner['pipe'], (json.dumps(list(argv)) + '\n').encode())  # one write, atomic: threads may call


def _interrupt(signum, frame):
    raise KeyboardInterrupt('signal %d' % signum)


#: Seconds the watch goes on ending an owner's processes (each round: SIGINT, then SIGKILL after 2 s).
WATCH_S = 60.0


def watch(mark):
    """The owner's watch: wait until the owner's pipe (stdin) closes, then end every process that
    carries its ``mark``, again until none is left (a process may start one while it is stopped),
    then run what the owner asked for on the pipe (:func:`at_owner_end`), each once."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C to the owner's group, should it be in it
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    said = b''
    while True:
        chunk = os.read(0, 65536)
        if not chunk:
            break
        said += chunk
    deadline = time.monotonic() + WATCH_S
    while time.monotonic() < deadline:
        left = marked(mark, OWNER)
        if not left:
            break
        end_pids(left, grace=2.0)
    asked = []
    for line in said.decode('utf-8', 'replace').splitlines():
        if line not in asked:
            asked.append(line)
    for line in asked:
        try:
            subprocess.run(json.loads(line), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=60)
        except (ValueError, TypeError, OSError, subprocess.SubprocessError):
            pass


def main(argv):
    if len(argv) == 2 and argv[0] == '--cleanup':
        end_pids(marked(os.path.abspath(argv[1])))
        return 0
    if len(argv) == 2 and argv[0] == '--watch':
        watch(argv[1])
        return 0
    sys.stderr.write('usage: python3 -m exam_lab.harness.supervisor --cleanup RUN_DIR | --watch OWNER_MARK\n')
    return 2


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

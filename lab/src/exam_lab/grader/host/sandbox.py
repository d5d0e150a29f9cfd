"""The box a submission's code runs in: bubblewrap, as a user of its own, with resource limits.

Every step that runs a student's code (``catkin_make``: CMake runs code; ``roslaunch`` and the nodes)
runs through :meth:`Box.argv`::

    sh -c 'join the box's cgroups'  prlimit ...  setpriv --reuid=U ... --no-new-privs  bwrap ...  CMD

- **A user of its own.** Each box holds a slot (an exclusive ``flock`` on
  ``/run/lock/exam-grader/box-N``, so concurrent gradings on one machine, even of two graders, never
  share one) and runs as uid ``BOX_UID_BASE + N``, a uid no account and no process uses. bubblewrap
  started by root with ``--unshare-user`` would keep root's rights over every file it can see;
  started from the box's own uid, it has exactly that uid's rights: other users' 0600 files are not
  readable, another box's processes cannot be signalled, and ``RLIMIT_NPROC`` (counted per uid)
  bounds this box's processes alone.
- **Namespaces** (bubblewrap): user, PID, IPC, UTS and cgroup namespaces of its own; the network
  namespace is the session's (only loopback, made by the runner), shared with the grader's master
  and probe, which run outside the box. When the box's first process ends, its PID namespace ends
  and the kernel kills every process in it, double-forked and ``setsid`` ones included.
- **Files**: an empty root (read-only once set up) with read-only binds of ``/usr`` (``/bin``,
  ``/lib``... are its links on Debian 12), the few ``/etc`` files a ROS process reads, the simulators'
  underlay and their sources; the student's package read-only; only the box's own work folder
  (``build/``, ``devel/``) writable. Fresh ``/proc``, ``/dev``, and private ``/tmp``, ``/var/tmp``,
  ``/dev/shm`` and HOME (size-capped tmpfs). No /root, /home, other students, grader output.
- **Reading the upload** (:meth:`Box.run` with ``mounts`` and ``network=False``): the grader's own
  readers of student bytes (``boxed/inspect``, ``boxed/intake``, the similarity check) run in the
  same box, as its uid, in a network namespace without even loopback, seeing only the upload that
  root staged byte for byte (:func:`stage_upload`, read-only), the folder they write (the workspace,
  their output) and the grader's source (read-only). Root reads back one record
  (:mod:`~exam_lab.grader.host.egress`).
- **Environment**: empty (``--clearenv``) but for the variables :func:`box_env` lets through.
- **Limits**: memory, processes and CPU by a cgroup of the box's own where the machine lets root make
  one (cgroup v1 ``memory`` + ``pids`` + ``cpu``, or v2), always ``prlimit`` (address space, processes,
  CPU time, file size, open files, no core files). The box's work folder is a tmpfs of ``WORK_BYTES``.
  CPU: at most ``cpus`` cores (a quota: the class's cores shared among the gradings side by side) at
  the default weight, so 140 busy processes of one box (each ``setsid``: an autogroup of its own) take
  that box's share, not its classmates' or the judge's.
- **The judge** (the session's masters and its probe) runs outside the box as uid ``JUDGE_UID_BASE +
  N`` of the same slot (:meth:`Box.judge_argv`), never root and never the box's uid, in cgroups of its
  own: the master the student's nodes talk to is bounded in memory (``MASTER_MEMORY_BYTES``: the
  parameters they set are its memory), and both outweigh a box for CPU (``JUDGE_SHARES``), so a box
  that burns CPU cannot delay what measures its classmates.

**Without root** (the teacher's own account, where the kernel lets an ordinary user make user
namespaces: Debian 12, Ubuntu 20.04/22.04), the box is the same bubblewrap command started as the
grading user itself, with the same namespaces, files, environment and ``prlimit`` bounds. What
differs: it runs as the grading user's uid (it still sees only what it binds: none of that user's
files), boxes are told apart by their PID namespaces and mounts rather than by uids, there is no
cgroup unless the machine delegates a writable cgroup v2 subtree to the user (tried, untested), and
the work folder has no tmpfs (each file is bounded by ``FILE_BYTES``). The session around it runs in a
user and network namespace of its own (:func:`network_namespace`), so ``RLIMIT_NPROC`` counts the
session's processes, not the rest of the user's, and a box run outside a session gets a network
namespace of its own (only loopback: not even the host's abstract sockets, X11's or D-Bus's).

:func:`check` says whether boxes can be made here at all; the runner refuses to grade when they
cannot unless the teacher accepts the risk by name.
"""
import errno
import fcntl
import os
import pwd
import shutil
import signal
import stat
import subprocess
import threading
import time

#: First uid of the boxes (isolate uses 60000+); slot N runs as BOX_UID_BASE + N.
BOX_UID_BASE = 61000
#: First uid of the judges: slot N's masters and probe run as JUDGE_UID_BASE + N.
JUDGE_UID_BASE = 62000
SLOTS = 64
LOCK_DIR = '/run/lock/exam-grader'
#: Where the box sees its workspace, and its private HOME.
BOX_WS = '/box/ws'
BOX_HOME = '/box/home'
#: Limits of one box.
MEMORY_BYTES = 2 << 30           # cgroup: the whole box
ADDRESS_SPACE_BYTES = 4 << 30    # prlimit: each process (rospy reserves 64 MB malloc arenas per thread)
PROCESSES = 512                  # threads count: a rospy node has ~15, roslaunch ~10
CPU_SECONDS = 300                # each process
FILE_BYTES = 64 << 20            # each file written, logs included
OPEN_FILES = 1024
#: CPU weights (cgroup v1 cpu.shares; v2 cpu.weight = shares * 100 / 1024): a box has the default, the
#: judge's master and probe four times it, so they keep their timing beside a box that burns its quota.
BOX_SHARES = 1024
JUDGE_SHARES = 4096
#: Period of the CPU quota (v1 cpu.cfs_period_us, v2 cpu.max), microseconds.
CPU_PERIOD_US = 100000
#: The least CPU quota of a box, in cores (a build or a node needs one at times).
MIN_BOX_CPUS = 0.5
#: The master the student's nodes talk to (roscore: rosmaster and rosout), and the probe: their memory.
MASTER_MEMORY_BYTES = 384 << 20
PROBE_MEMORY_BYTES = 512 << 20
WORK_BYTES = 512 << 20           # build/ + devel/
TMP_BYTES = 64 << 20             # each of /tmp, /var/tmp, /dev/shm, HOME
#: /etc files a ROS process reads (name resolution of localhost, the dynamic linker, alternatives).
ETC = ('alternatives', 'catkin', 'ld.so.cache', 'ld.so.conf', 'ld.so.conf.d', 'hosts', 'host.conf', 'nsswitch.conf',
       'localtime', 'ros', 'python3', 'python3.11', 'mime.types', 'ssl')
#: Variables of a box's environment, besides those a sourced workspace sets (ROS_*, paths).
PASSED = ('PATH', 'LANG', 'LC_ALL', 'PYTHONUNBUFFERED', 'PYTHONDONTWRITEBYTECODE')

#: PATH entries a box keeps (the system's, ROS's, the workspace's): none of the grading user's own.
SYSTEM_PATH = ('/usr/', '/bin', '/sbin', '/opt/ros/', BOX_WS)

_check_lock = threading.Lock()
_checked = {}


class SandboxUnavailable(RuntimeError):
    """The machine cannot make a box: the grader refuses to run student code (unless told to)."""


class UploadRefused(ValueError):
    """An upload too large or too deep to stage for its box (:func:`stage_upload`): that student's row."""


def box_env(env, home=BOX_HOME):
    """Only what ROS and the build need from ``env`` (ROS_*, the workspace's paths, PATH, locale), with
    a fresh HOME and a user name of the box: nothing else of the grading user reaches student code."""
    from exam_lab.harness.supervisor import WORKSPACE_VARS
    kept = {k: v for k, v in env.items() if k.startswith('ROS') or k in WORKSPACE_VARS or k in PASSED}
    kept['PATH'] = ':'.join(p for p in kept.get('PATH', '').split(':') if p.startswith(SYSTEM_PATH)) or \
        '/usr/bin:/bin'
    kept.update(HOME=home, USER='student', LOGNAME='student', PYTHONNOUSERSITE='1')
    kept.setdefault('LANG', 'C.UTF-8')
    return kept


def _own_cgroups():
    """``{controller: (hierarchy root, this process's path)}``; v2 as controller ``''``."""
    found = {}
    try:
        with open('/proc/self/cgroup') as f:
            for line in f:
                _, controllers, path = line.rstrip('\n').split(':', 2)
                for name in controllers.split(','):
                    if name in ('memory', 'pids', 'cpu') and os.path.isdir('/sys/fs/cgroup/%s' % name):
                        found[name] = ('/sys/fs/cgroup/%s' % name, path)
                    elif controllers == '' and os.path.isfile('/sys/fs/cgroup/cgroup.controllers'):
                        found[''] = ('/sys/fs/cgroup', path)
    except OSError:
        pass
    return found


def box_cpus(jobs, cores=None):
    """The CPU quota of one box, in cores, when ``jobs`` gradings run side by side on ``cores`` (default
    this machine's): an equal part of the machine, at least MIN_BOX_CPUS."""
    cores = cores or os.cpu_count() or 1
    return max(MIN_BOX_CPUS, float(cores) / max(1, jobs))


def cgroup_limits(memory, shares, pids=None, cpus=None, v2=False):
    """``[(controller, file, value)]`` that bound a cgroup: ``memory`` bytes, CPU weight ``shares``
    (v1 units), at most ``pids`` processes and ``cpus`` cores (None: no bound). The controller is ''
    under cgroup v2 (one folder for all)."""
    quota = int(cpus * CPU_PERIOD_US) if cpus else None
    if v2:
        limits = [('', 'memory.max', memory), ('', 'cpu.weight', max(1, min(10000, shares * 100 // 1024)))]
        if quota:
            limits.append(('', 'cpu.max', '%d %d' % (quota, CPU_PERIOD_US)))
        if pids:
            limits.append(('', 'pids.max', pids))
        return limits
    limits = [('memory', 'memory.limit_in_bytes', memory), ('cpu', 'cpu.shares', shares)]
    if quota:
        limits += [('cpu', 'cpu.cfs_period_us', CPU_PERIOD_US), ('cpu', 'cpu.cfs_quota_us', quota)]
    if pids:
        limits.append(('pids', 'pids.max', pids))
    return limits


def _make_cgroups(name, memory, shares, pids=None, cpus=None):
    """Folders of new cgroups called ``name`` with the limits of :func:`cgroup_limits`; [] when the
    machine does not let us. cgroup v1 needs the ``memory`` controller (and ``pids`` when ``pids`` is
    bounded); without ``cpu`` the CPU is not bounded. cgroup v2 is untested (needs the controllers
    enabled in the parent's cgroup.subtree_control)."""
    own = _own_cgroups()
    made = {}
    try:
        if 'memory' in own and ('pids' in own or not pids):
            limits = [l for l in cgroup_limits(memory, shares, pids, cpus) if l[0] in own]
        elif '' in own:
            limits = cgroup_limits(memory, shares, pids, cpus, v2=True)
        else:
            return []
        for controller, limit_file, value in limits:
            if controller not in made:
                root, path = own[controller]
                made[controller] = os.path.join(root, path.lstrip('/'), name)
                _fresh_folder(made[controller])
            with open(os.path.join(made[controller], limit_file), 'w') as f:
                f.write(str(value))
        return list(made.values())
    except OSError:
        _remove_cgroups(list(made.values()))
        return []


def memory_use(folders):
    """What the memory cgroup among ``folders`` saw: ``{"limit", "peak" (bytes, None where the kernel
    does not say), "oom_kills"}``; None without one. v1: memory.max_usage_in_bytes and oom_control;
    v2: memory.peak and memory.events."""
    for folder in folders:
        v1 = os.path.join(folder, 'memory.limit_in_bytes')
        v2 = os.path.join(folder, 'memory.max')
        if not os.path.isfile(v1) and not os.path.isfile(v2):
            continue
        names = ('memory.limit_in_bytes', 'memory.max_usage_in_bytes', 'memory.oom_control') \
            if os.path.isfile(v1) else ('memory.max', 'memory.peak', 'memory.events')
        values = []
        for name in names:
            try:
                with open(os.path.join(folder, name)) as f:
                    values.append(f.read())
            except OSError:
                values.append('')
        events = dict(line.split() for line in values[2].splitlines() if len(line.split()) == 2)
        limit, peak = values[0].strip(), values[1].strip()
        return {'limit': int(limit) if limit.isdigit() else None, 'peak': int(peak) if peak.isdigit() else None,
                'oom_kills': int(events.get('oom_kill', '0'))}
    return None


def reset_memory_peak(folders):
    """Start the peak of the memory cgroups among ``folders`` anew (v1; v2 kernels before 6.12 cannot)."""
    for folder in folders:
        for name in ('memory.max_usage_in_bytes', 'memory.peak'):
            try:
                with open(os.path.join(folder, name), 'w') as f:
                    f.write('0')
            except OSError:
                pass


def _join(folders):
    """The command-line prefix that puts the command in the cgroups ``folders`` (then execs it)."""
    if not folders:
        return []
    return ['sh', '-c', 'for g in "$@"; do case "$g" in --) shift; break;; esac; '
            'echo $$ > "$g/cgroup.procs" || exit 125; shift; done; exec "$@"', 'sh'] + list(folders) + ['--']


def _as_user(uid):
    """The command-line prefix that drops root for ``uid`` (its own group, none else, no capabilities)."""
    return ['setpriv', '--reuid=%d' % uid, '--regid=%d' % uid, '--clear-groups', '--no-new-privs',
            '--inh-caps=-all', '--']


def _fresh_folder(folder):
    """mkdir, after removing an empty one a crashed grader left (its slot's lock was released)."""
    try:
        os.mkdir(folder)
    except FileExistsError:
        os.rmdir(folder)
        os.mkdir(folder)


def _remove_cgroups(folders):
    for folder in reversed(folders):
        try:
            os.rmdir(folder)
        except OSError:
            pass


def _uid_in_use(uid):
    try:
        pwd.getpwuid(uid)
        return True
    except KeyError:
        return bool(pids_of_uid(uid))


def pids_of_uid(uid):
    """Living processes whose real or effective uid is ``uid`` (zombies left out: they are dead)."""
    found = []
    for entry in os.listdir('/proc'):
        if not entry.isdigit():
            continue
        try:
            with open('/proc/%s/status' % entry) as f:
                status = dict(line.split(':', 1) for line in f if ':' in line)
        except (OSError, ValueError):
            continue
        uids = status.get('Uid', '').split()
        if status.get('State', '').strip().startswith('Z') or len(uids) < 2:
            continue
        if str(uid) in uids[:2]:
            found.append(int(entry))
    return found


def _end_uid(uid):
    """Kill whatever still runs as ``uid``; returns how many there were."""
    left = pids_of_uid(uid)
    for _ in range(3 if left else 0):
        for pid in pids_of_uid(uid):
            try:
                os.kill(pid, signal.SIGKILL)
            except OSError:
                pass
        deadline = time.monotonic() + 5.0
        while time.monotonic() < deadline and pids_of_uid(uid):
            time.sleep(0.05)
        if not pids_of_uid(uid):
            break
    return len(left)


def _tmpfs(path, size, uid):
    """Mount a tmpfs of ``size`` bytes owned by ``uid`` on ``path``; False where root cannot mount."""
    done = subprocess.run(['mount', '-t', 'tmpfs', '-o', 'size=%d,mode=0700,uid=%d,gid=%d,nosuid,nodev'
                           % (size, uid, uid), 'exam-box', path],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=30)
    return done.returncode == 0


class Box(object):
    """One submission's box: a uid of its own, its work folder ``<work>/box``, its cgroups.

    :param work: the submission's work folder (root's); the box gets ``<work>/box`` (build/ and devel/
        of its workspace) and sees ``<work>/ws/src`` read-only.
    :param binds: host folders the box sees read-only at the same path (the underlay, the simulators'
        sources).
    :param bwrap: False for the unsandboxed mode the teacher asked for by name: same user and limits,
        no namespaces.
    :param cpus: the box's CPU quota in cores (:func:`box_cpus`); None: its weight only.

    Opened by a grader that is not root, a box with ``bwrap`` is *rootless* (the module's docstring):
    no slot, the grading user's uid (``owner``), and the network namespace it was opened in
    (``netns``), to tell whether a command line is made inside a session's namespace or not.
    """

    def __init__(self, work, binds=(), bwrap=True, cpus=None):
        self.work = work
        self.binds = [os.path.realpath(b) for b in binds]
        self.bwrap = bwrap
        self.cpus = cpus
        self.slot = None
        self._lock = None
        self.cgroups = []
        #: The judge's cgroups: {"master": [folders], "probe": [folders]}.
        self.judge_cgroups = {}
        self.mounted = False
        self.folder = os.path.join(work, 'box')
        self.notes = []
        self.rootless, self.owner, self.netns = False, None, None

    def describe(self):
        """What the session needs to make this box's command lines (JSON): see :meth:`attached`."""
        return {'work': self.work, 'binds': self.binds, 'bwrap': self.bwrap, 'slot': self.slot,
                'cgroups': self.cgroups, 'judge_cgroups': self.judge_cgroups, 'cpus': self.cpus,
                'rootless': self.rootless, 'owner': self.owner, 'netns': self.netns}

    @classmethod
    def attached(cls, described):
        """The box :meth:`describe` described, opened by another process (the runner holds it)."""
        box = cls(described['work'], described['binds'], described['bwrap'], described.get('cpus'))
        box.slot, box.cgroups = described['slot'], described['cgroups']
        box.judge_cgroups = described.get('judge_cgroups', {})
        box.rootless, box.owner, box.netns = described['rootless'], described['owner'], described['netns']
        return box

    @property
    def home(self):
        """The box's HOME as its processes see it."""
        return BOX_HOME if self.bwrap else os.path.join(self.folder, 'home')

    @property
    def uid(self):
        return self.owner if self.rootless else BOX_UID_BASE + self.slot

    @property
    def judge_uid(self):
        """The uid of this slot's judge (masters, probe); None unsandboxed and not root."""
        return JUDGE_UID_BASE + self.slot if self.slot is not None else None

    @property
    def workspace(self):
        """The student's workspace as the box's processes see it."""
        return BOX_WS if self.bwrap else os.path.join(self.folder, 'ws')

    def open(self):
        if os.geteuid() != 0 and self.bwrap:
            return self._open_rootless()
        if os.geteuid() != 0:  # unsandboxed and not root: the grading user's own rights, limits only
            os.makedirs(os.path.join(self.folder, 'ws', 'build'))
            os.makedirs(os.path.join(self.folder, 'ws', 'devel'))
            shutil.copytree(os.path.join(self.work, 'ws', 'src'), os.path.join(self.folder, 'ws', 'src'),
                            symlinks=True)
            return self
        os.makedirs(LOCK_DIR, mode=0o700, exist_ok=True)
        for slot in range(SLOTS):
            lock = open(os.path.join(LOCK_DIR, 'box-%d' % slot), 'w')
            try:
                fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                lock.close()
                continue
            if _uid_in_use(BOX_UID_BASE + slot) or _uid_in_use(JUDGE_UID_BASE + slot):
                lock.close()
                continue
            self.slot, self._lock = slot, lock
            break
        else:
            raise SandboxUnavailable('no free box among %d (uids %d-%d taken)'
                                     % (SLOTS, BOX_UID_BASE, BOX_UID_BASE + SLOTS - 1))
        os.makedirs(self.folder)
        self.mounted = _tmpfs(self.folder, WORK_BYTES, self.uid)
        if not self.mounted:
            os.chown(self.folder, self.uid, self.uid)
            os.chmod(self.folder, 0o700)
            self.notes.append('the box\'s work folder has no size limit (no tmpfs): files are limited '
                              'to %d MB each' % (FILE_BYTES >> 20))
        # The workspace: src is a mount point for the read-only package (or, unsandboxed, a copy).
        for sub in ('ws', 'ws/src', 'ws/build', 'ws/devel'):
            os.mkdir(os.path.join(self.folder, sub))
        src = os.path.join(self.work, 'ws', 'src')
        if not self.bwrap:
            os.rmdir(os.path.join(self.folder, 'ws', 'src'))
            shutil.copytree(src, os.path.join(self.folder, 'ws', 'src'), symlinks=True)
        for dirpath, dirnames, filenames in os.walk(self.folder):
            for name in [dirpath] + [os.path.join(dirpath, n) for n in dirnames + filenames]:
                os.lchown(name, self.uid, self.uid)
        self.cgroups = _make_cgroups('exam-box-%d' % self.slot, MEMORY_BYTES, BOX_SHARES, PROCESSES, self.cpus)
        if not self.cgroups:
            self.notes.append('no cgroup could be made: memory limited per process (%d GB of address '
                              'space), processes per uid (%d), CPU not bounded' % (ADDRESS_SPACE_BYTES >> 30, PROCESSES))
        self.judge_cgroups = {
            'master': _make_cgroups('exam-master-%d' % self.slot, MASTER_MEMORY_BYTES, JUDGE_SHARES),
            'probe': _make_cgroups('exam-judge-%d' % self.slot, PROBE_MEMORY_BYTES, JUDGE_SHARES)}
        if not self.judge_cgroups['master']:
            self.notes.append('no cgroup could be made for the judge: the master the student\'s nodes talk '
                              'to is not bounded in memory')
        return self

    def _open_rootless(self):
        """The box of a grader that is not root: its folder (the grading user's, 0700), no uid of its
        own, a cgroup only where a cgroup v2 subtree is delegated to the user."""
        self.rootless, self.owner = True, os.geteuid()
        self.netns = os.readlink('/proc/self/ns/net')
        os.makedirs(self.folder, mode=0o700)
        for sub in ('ws', 'ws/src', 'ws/build', 'ws/devel'):
            os.mkdir(os.path.join(self.folder, sub))
        self.notes.append('without root, the box\'s work folder is a plain folder, not a tmpfs of %d MB: '
                          'each file is limited to %d MB, the folder is not' % (WORK_BYTES >> 20, FILE_BYTES >> 20))
        self.cgroups = _make_cgroups('exam-box-%d-%s' % (self.owner, os.path.basename(self.work)), MEMORY_BYTES,
                                     BOX_SHARES, PROCESSES, self.cpus)
        if not self.cgroups:
            self.notes.append('without root, no cgroup (none delegated to this user): memory limited per process '
                              '(%d GB of address space), processes to %d in the session\'s user namespace'
                              % (ADDRESS_SPACE_BYTES >> 30, PROCESSES))
        return self

    def __enter__(self):
        return self.open()

    def __exit__(self, *exc):
        self.close()
        return False

    def argv(self, command, env, cwd=None, mounts=None, network=True):
        """The command line that runs ``command`` in the box with ``env`` (filtered by :func:`box_env`)
        and ``cwd`` (a path as the box sees it; default its workspace).

        :param mounts: ``[(host path, path in the box, writable)]`` instead of the workspace (the
            inspection's upload, workspace and output); unsandboxed, commands get host paths instead.
        :param network: False: a network namespace of the box's own, without even loopback.
        """
        env = box_env(env, self.home)
        cwd = cwd or self.workspace
        limits = ['prlimit', '--as=%d' % ADDRESS_SPACE_BYTES, '--nproc=%d' % PROCESSES,
                  '--cpu=%d' % CPU_SECONDS, '--fsize=%d' % FILE_BYTES, '--nofile=%d' % OPEN_FILES,
                  '--core=0', '--']
        user = _as_user(self.uid) if self.slot is not None else []
        join = _join(self.cgroups)
        if not self.bwrap:
            os.makedirs(env['HOME'], exist_ok=True)
            if self.slot is not None:
                os.chown(env['HOME'], self.uid, self.uid)
            return join + limits + user + ['env', '-i', '-C', cwd] + \
                ['%s=%s' % item for item in sorted(env.items())] + list(command)
        # bwrap itself (the box's pid 1, whose /proc/1/environ the box can read) starts with nothing.
        box = ['env', '-i', 'bwrap', '--unshare-user', '--unshare-pid', '--unshare-ipc', '--unshare-uts',
               '--unshare-cgroup-try', '--hostname', 'exam-box', '--die-with-parent', '--new-session',
               '--clearenv', '--ro-bind', '/usr', '/usr']
        if self.rootless and os.readlink('/proc/self/ns/net') == self.netns:
            box.append('--unshare-net')  # outside a session: the grading user's network is not the box's
        for link in ('bin', 'sbin', 'lib', 'lib32', 'lib64', 'libx32'):
            if os.path.islink('/' + link):
                box += ['--symlink', os.readlink('/' + link), '/' + link]
            elif os.path.isdir('/' + link):
                box += ['--ro-bind', '/' + link, '/' + link]
        for name in ETC:
            if os.path.exists('/etc/' + name):
                box += ['--ro-bind', '/etc/' + name, '/etc/' + name]
        if os.path.isdir('/opt/ros'):
            box += ['--ro-bind', '/opt/ros', '/opt/ros']
        box += ['--proc', '/proc', '--dev', '/dev']
        for path in ('/tmp', '/var/tmp', '/dev/shm', BOX_HOME):
            box += ['--size', str(TMP_BYTES), '--tmpfs', path]
        for path in self.binds:  # after the private /tmp: an underlay may live in the host's /tmp
            box += ['--ro-bind', path, path]
        if mounts is None:
            mounts = [(os.path.join(self.folder, 'ws'), BOX_WS, True),
                      (os.path.join(self.work, 'ws', 'src'), BOX_WS + '/src', False)]
        for host, inside, writable in mounts:
            box += ['--bind' if writable else '--ro-bind', host, inside]
        if not network and '--unshare-net' not in box:
            box.append('--unshare-net')
        box += ['--remount-ro', '/', '--chdir', cwd]
        for name, value in sorted(env.items()):
            box += ['--setenv', name, value]
        return join + limits + user + box + ['--'] + list(command)

    def judge_argv(self, command, part):
        """The command line that runs the judge's ``command`` (``part``: "master" or "probe") outside
        the box, as this slot's judge uid in the judge's cgroups (as the grading user unsandboxed
        without root). Its environment is the caller's: the judge's own, never the box's."""
        if self.slot is None:
            return list(command)
        return _join(self.judge_cgroups.get(part, [])) + _as_user(self.judge_uid) + list(command)

    def run(self, command, env, log, timeout, cwd=None, mounts=None, network=True):
        """Run ``command`` in the box (:meth:`argv`) and wait at most ``timeout`` s of wall clock, its
        output (stdout and stderr) in the file ``log`` (root's, outside the box); then end whatever of
        the box's uid is left. Returns ``(exit status, None)``, or ``(None, why)`` when it was killed
        at the deadline."""
        argv = self.argv(command, env, cwd, mounts, network)
        with open(log, 'wb') as out:
            child = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
                                     start_new_session=True)
            try:
                status, why = child.wait(timeout=timeout), None
            except subprocess.TimeoutExpired:
                status, why = None, 'did not finish within %.0f s' % timeout
            finally:
                try:
                    os.killpg(child.pid, signal.SIGKILL)  # the unsandboxed mode's children, in its session
                except OSError:
                    pass
                child.wait()
        self.end()
        return status, why

    def leftovers(self):
        """Pids of the box's uid still alive (there should be none once its command ended). A rootless
        box has no uid of its own to look for: what it started died with its PID namespace."""
        return pids_of_uid(self.uid) if self.slot is not None else []

    def end(self):
        """Kill whatever still runs as the box's uid; returns how many there were (0 expected)."""
        return _end_uid(self.uid) if self.slot is not None else 0

    def close(self):
        if self.slot is None:
            _remove_cgroups(self.cgroups)
            shutil.rmtree(self.folder, ignore_errors=True)
            return
        self.end()
        _end_uid(self.judge_uid)  # the session ends its judge's processes; this is for a crashed one
        _remove_cgroups(self.cgroups)
        for folders in self.judge_cgroups.values():
            _remove_cgroups(folders)
        if self.mounted:
            subprocess.run(['umount', '-l', self.folder], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                           timeout=30)
        shutil.rmtree(self.folder, ignore_errors=True)
        self._lock.close()
        self.slot = None


def check():
    """None when boxes can be made here; else why not. Tried once per process (a real box runs
    ``true``), under a lock so that concurrent gradings wait for the answer rather than guess it."""
    with _check_lock:
        if 'why' not in _checked:
            _checked['why'] = _try_a_box()
        return _checked['why']


def network_namespace(argv):
    """``argv`` run in a network namespace of its own with only loopback, up. As root ``unshare --net``;
    otherwise bubblewrap makes it, with a user namespace of its own that keeps the grading user's uid
    and shows every file as it is (the master, the probe and the box's steps run inside)."""
    if os.geteuid() == 0:
        return ['unshare', '--net', '--', 'sh', '-c', 'ip link set lo up && exec "$@"', 'sh'] + list(argv)
    return ['bwrap', '--unshare-user', '--unshare-net', '--dev-bind', '/', '/', '--'] + list(argv)


#: Why a rootless box may fail, for the teacher.
USERNS_HINT = ('without root, the kernel must let ordinary users make user namespaces: user.max_user_namespaces '
               'above 0, kernel.unprivileged_userns_clone=1 where it exists (Debian 10, 11), and on Ubuntu '
               '24.04 an AppArmor profile that allows bwrap')


def _try_a_box():
    rootless = os.geteuid() != 0
    tools = ('bwrap', 'prlimit') if rootless else ('bwrap', 'setpriv', 'prlimit', 'unshare', 'ip')
    missing = [tool for tool in tools if shutil.which(tool) is None]
    if missing:
        return 'missing %s (Debian: apt-get install bubblewrap util-linux iproute2)' % ', '.join(missing)
    import tempfile
    work = tempfile.mkdtemp(prefix='exam-box-check-')
    try:
        os.chmod(work, 0o711)
        os.makedirs(os.path.join(work, 'ws', 'src'))
        with Box(work) as box:
            argv = box.argv(['sh', '-c', 'test "$(id -u)" != 0 && test ! -e /root'], {})
            # Rootless, as the session makes it: a box in a user and network namespace of its own.
            done = subprocess.run(network_namespace(argv) if rootless else argv,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=30)
        if done.returncode != 0:
            return 'bubblewrap could not make a box (exit %d): %s%s' % (
                done.returncode, done.stdout.decode('utf-8', 'replace').strip()[-500:],
                '; %s' % USERNS_HINT if rootless else '')
        return None
    except (OSError, subprocess.SubprocessError, SandboxUnavailable) as err:
        return 'a box could not be made: %s' % err
    finally:
        shutil.rmtree(work, ignore_errors=True)


#: Most bytes and entries of one upload staged for a box (unpack's own budget applies inside).
UPLOAD_BYTES = 256 << 20
UPLOAD_FILES = 20000
UPLOAD_DEPTH = 32


def stage_upload(source, target, max_bytes=UPLOAD_BYTES, max_files=UPLOAD_FILES):
    """Copy the upload ``source`` (a file or a folder) to ``target`` for a box to read, byte for byte and
    without reading anything of it: regular files (opened with O_NOFOLLOW; executable ones stay so:
    whether a script was, is a fact of the grade), folders and links (as
    links, never followed); FIFOs, devices and sockets are left out. Everything is root's and
    world-readable, nothing writable by a box. An upload over ``max_bytes``, ``max_files`` or
    :data:`UPLOAD_DEPTH` folders deep raises :class:`UploadRefused`."""
    budget = {'bytes': max_bytes, 'files': max_files}

    def take(size):
        budget['files'] -= 1
        budget['bytes'] -= size
        if budget['files'] < 0 or budget['bytes'] < 0:
            raise UploadRefused('the upload is larger than the grader takes (%d MB, %d files)'
                                % (max_bytes >> 20, max_files))

    def copy_file(src, dest):
        fd = os.open(src, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                return
            take(info.st_size)
            with os.fdopen(os.dup(fd), 'rb') as f, open(dest, 'xb') as g:
                os.chmod(dest, 0o755 if info.st_mode & 0o111 else 0o644)  # a script keeps its x bit
                shutil.copyfileobj(f, g)
        finally:
            os.close(fd)

    def copy(src, dest, depth=0):
        if depth > UPLOAD_DEPTH:
            raise UploadRefused('the upload has folders more than %d deep' % UPLOAD_DEPTH)
        info = os.lstat(src)
        if stat.S_ISLNK(info.st_mode):
            take(0)
            os.symlink(os.readlink(src), dest)
        elif stat.S_ISDIR(info.st_mode):
            take(0)
            os.mkdir(dest, 0o755)
            os.chmod(dest, 0o755)
            for name in sorted(os.listdir(src)):
                copy(os.path.join(src, name), os.path.join(dest, name), depth + 1)
        elif stat.S_ISREG(info.st_mode):
            copy_file(src, dest)

    copy(source.rstrip('/') or '/', target)


#: What of a log reaches the results: its first and last LOG_PART bytes.
LOG_PART = 256 << 10
#: Most bytes of a file other than a log (JSON) copied to the results.
FILE_CAP = 4 << 20


def read_capped(path, part=LOG_PART):
    """A file's text, its middle cut when longer than ``2 * part`` bytes (saying so); None when
    ``path`` is not a regular file (a link, FIFO or device is never followed or opened for reading:
    opened with O_NOFOLLOW | O_NONBLOCK and checked with fstat)."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
    except OSError as err:
        if err.errno in (errno.ELOOP, errno.ENXIO, errno.ENOENT, errno.EACCES):
            return None
        raise
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            return None
        with os.fdopen(os.dup(fd), 'rb') as f:
            if info.st_size <= 2 * part:
                data = f.read(2 * part)
            else:
                head = f.read(part)
                f.seek(info.st_size - part)
                cut = info.st_size - 2 * part
                data = head + ('\n[... %d bytes cut by the grader: this log keeps its first and last %d KB '
                               'of %d bytes ...]\n' % (cut, part >> 10, info.st_size)).encode() + f.read(part)
        return data.decode('utf-8', 'replace')
    finally:
        os.close(fd)


def copy_results(source, target, suffixes=('.log', '.json', '.md'), part=LOG_PART):
    """Copy the regular files of ``source`` (not its sub-folders) ending in ``suffixes`` to ``target``,
    each capped by :func:`read_capped`; a link, FIFO or device is skipped. Returns the names skipped."""
    os.makedirs(target, exist_ok=True)
    skipped = []
    for name in sorted(os.listdir(source)):
        if not name.endswith(suffixes) or '\n' in name:
            continue
        text = read_capped(os.path.join(source, name), part if name.endswith('.log') else FILE_CAP)
        if text is None:
            skipped.append(name)
            continue
        with open(os.path.join(target, name), 'w') as f:
            f.write(text)
    return skipped

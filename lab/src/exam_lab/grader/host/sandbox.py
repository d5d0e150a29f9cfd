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
- **Limits**: memory and processes by a cgroup of the box's own where the machine lets root make one
  (cgroup v1 ``memory`` + ``pids``, or v2), always ``prlimit`` (address space, processes, CPU time,
  file size, open files, no core files). The box's work folder is a tmpfs of ``WORK_BYTES``.

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
                    if name in ('memory', 'pids') and os.path.isdir('/sys/fs/cgroup/%s' % name):
                        found[name] = ('/sys/fs/cgroup/%s' % name, path)
                    elif controllers == '' and os.path.isfile('/sys/fs/cgroup/cgroup.controllers'):
                        found[''] = ('/sys/fs/cgroup', path)
    except OSError:
        pass
    return found


def _make_cgroups(name):
    """Folders of new cgroups for one box with their limits set; [] when the machine does not let us."""
    own = _own_cgroups()
    made = []
    try:
        if 'memory' in own and 'pids' in own:
            for controller, limit_file, value in (('memory', 'memory.limit_in_bytes', MEMORY_BYTES),
                                                  ('pids', 'pids.max', PROCESSES)):
                root, path = own[controller]
                folder = os.path.join(root, path.lstrip('/'), name)
                _fresh_folder(folder)
                made.append(folder)
                with open(os.path.join(folder, limit_file), 'w') as f:
                    f.write(str(value))
        elif '' in own:
            root, path = own['']
            folder = os.path.join(root, path.lstrip('/'), name)
            _fresh_folder(folder)
            made.append(folder)
            for limit_file, value in (('memory.max', MEMORY_BYTES), ('pids.max', PROCESSES)):
                with open(os.path.join(folder, limit_file), 'w') as f:
                    f.write(str(value))
        return made
    except OSError:
        _remove_cgroups(made)
        return []


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
    """

    def __init__(self, work, binds=(), bwrap=True):
        self.work = work
        self.binds = [os.path.realpath(b) for b in binds]
        self.bwrap = bwrap
        self.slot = None
        self._lock = None
        self.cgroups = []
        self.mounted = False
        self.folder = os.path.join(work, 'box')
        self.notes = []

    def describe(self):
        """What the session needs to make this box's command lines (JSON): see :meth:`attached`."""
        return {'work': self.work, 'binds': self.binds, 'bwrap': self.bwrap, 'slot': self.slot,
                'cgroups': self.cgroups}

    @classmethod
    def attached(cls, described):
        """The box :meth:`describe` described, opened by another process (the runner holds it)."""
        box = cls(described['work'], described['binds'], described['bwrap'])
        box.slot, box.cgroups = described['slot'], described['cgroups']
        return box

    @property
    def home(self):
        """The box's HOME as its processes see it."""
        return BOX_HOME if self.bwrap else os.path.join(self.folder, 'home')

    @property
    def uid(self):
        return BOX_UID_BASE + self.slot

    @property
    def workspace(self):
        """The student's workspace as the box's processes see it."""
        return BOX_WS if self.bwrap else os.path.join(self.folder, 'ws')

    def open(self):
        if os.geteuid() != 0:  # unsandboxed and not root: the grading user's own rights, limits only
            if self.bwrap:
                raise SandboxUnavailable('a box needs root (a user of its own per submission)')
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
            if _uid_in_use(BOX_UID_BASE + slot):
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
        self.cgroups = _make_cgroups('exam-box-%d' % self.slot)
        if not self.cgroups:
            self.notes.append('no cgroup could be made: memory limited per process (%d GB of address '
                              'space), processes per uid (%d)' % (ADDRESS_SPACE_BYTES >> 30, PROCESSES))
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
        user = ['setpriv', '--reuid=%d' % self.uid, '--regid=%d' % self.uid, '--clear-groups',
                '--no-new-privs', '--inh-caps=-all', '--'] if self.slot is not None else []
        join = []
        if self.cgroups:
            join = ['sh', '-c', 'for g in "$@"; do case "$g" in --) shift; break;; esac; '
                    'echo $$ > "$g/cgroup.procs" || exit 125; shift; done; exec "$@"', 'sh'] + \
                self.cgroups + ['--']
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
        if not network:
            box.append('--unshare-net')
        box += ['--remount-ro', '/', '--chdir', cwd]
        for name, value in sorted(env.items()):
            box += ['--setenv', name, value]
        return join + limits + user + box + ['--'] + list(command)

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
        """Pids of the box's uid still alive (there should be none once its command ended)."""
        return pids_of_uid(self.uid) if self.slot is not None else []

    def end(self):
        """Kill whatever still runs as the box's uid; returns how many there were (0 expected)."""
        left = self.leftovers()
        for _ in range(3 if left else 0):
            for pid in left:
                try:
                    os.kill(pid, signal.SIGKILL)
                except OSError:
                    pass
            deadline = time.monotonic() + 5.0
            while time.monotonic() < deadline and self.leftovers():
                time.sleep(0.05)
            if not self.leftovers():
                break
        return len(left)

    def close(self):
        if self.slot is None:
            shutil.rmtree(self.folder, ignore_errors=True)
            return
        self.end()
        _remove_cgroups(self.cgroups)
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


def _try_a_box():
    if os.geteuid() != 0:
        return 'the grader is not root: it needs root to give each submission a user of its own'
    missing = [tool for tool in ('bwrap', 'setpriv', 'prlimit', 'unshare', 'ip') if shutil.which(tool) is None]
    if missing:
        return 'missing %s (Debian: apt-get install bubblewrap util-linux iproute2)' % ', '.join(missing)
    import tempfile
    work = tempfile.mkdtemp(prefix='exam-box-check-')
    try:
        os.chmod(work, 0o711)
        os.makedirs(os.path.join(work, 'ws', 'src'))
        with Box(work) as box:
            done = subprocess.run(box.argv(['sh', '-c', 'test "$(id -u)" != 0 && test ! -e /root'], {}),
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=30)
        if done.returncode != 0:
            return 'bubblewrap could not make a box (exit %d): %s' % (
                done.returncode, done.stdout.decode('utf-8', 'replace').strip()[-500:])
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

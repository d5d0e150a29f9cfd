"""The box a submission's code runs in: bubblewrap, as a user of its own, with resource limits.

Every step that runs a student's code (``catkin_make``: CMake runs code; ``roslaunch`` and the nodes)
runs through :meth:`Box.argv`::

    sh -c 'join the box's cgroups'  prlimit ...  setpriv --reuid=U ... --no-new-privs  bwrap ...  CMD

- **A user of its own.** Each box holds a slot (:mod:`~exam_lab.grader.host.uids`: an exclusive
  ``flock`` on ``/run/lock/exam-grader/box-N``, so concurrent gradings on one machine, even of two
  graders, never share one) and runs as uid ``BOX_UID_BASE + N``, a uid no account and no process
  uses. bubblewrap started by root with ``--unshare-user`` would keep root's rights over every file it
  can see; started from the box's own uid, it has exactly that uid's rights: other users' 0600 files
  are not readable, another box's processes cannot be signalled, and ``RLIMIT_NPROC`` (counted per
  uid) bounds this box's processes alone.
- **Namespaces** (bubblewrap): user, PID, IPC, UTS and cgroup namespaces of its own; the network
  namespace is the session's (only loopback, made by the runner), shared with the grader's master
  and probe, which run outside the box. When the box's first process ends, its PID namespace ends
  and the kernel kills every process in it, double-forked and ``setsid`` ones included.
- **Files** (:func:`~exam_lab.grader.host.bwrap.command`): an empty root (read-only once set up) with
  read-only binds of ``/usr`` (``/bin``, ``/lib``... are its links on Debian 12), the few ``/etc``
  files a ROS process reads, the simulators' underlay and their sources; the student's package
  read-only; only the box's own work folder (``build/``, ``devel/``:
  :func:`~exam_lab.grader.host.staging.work_folder`) writable. Fresh ``/proc``, ``/dev``, and private
  ``/tmp``, ``/var/tmp``, ``/dev/shm`` and HOME (size-capped tmpfs). No /root, /home, other students,
  grader output.
- **Reading the upload** (:meth:`Box.run` with ``mounts`` and ``network=False``): the grader's own
  readers of student bytes (``boxed/inspect``, ``boxed/intake``, the similarity check) run in the
  same box, as its uid, in a network namespace without even loopback, seeing only the upload that
  root staged byte for byte (:func:`~exam_lab.grader.host.staging.stage_upload`, read-only), the
  folder they write (the workspace, their output) and the grader's source (read-only). Root reads
  back one record (:mod:`~exam_lab.grader.contract`).
- **Environment**: empty (``--clearenv``) but for the variables
  :func:`~exam_lab.grader.score.boxenv.box_env` lets through.
- **Limits** (:mod:`~exam_lab.grader.host.limits`): memory, processes and CPU by a cgroup of the box's
  own where the machine lets root make one (:mod:`~exam_lab.grader.host.cgroups`), always ``prlimit``
  (address space, processes, CPU time, file size, open files, no core files). The box's work folder
  is a tmpfs of ``WORK_BYTES``. CPU: at most ``cpus`` cores (a quota: the class's cores shared among
  the gradings side by side) at the default weight, so 140 busy processes of one box (each
  ``setsid``: an autogroup of its own) take that box's share, not its classmates' or the judge's.
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
user and network namespace of its own (:func:`~exam_lab.grader.host.bwrap.network_namespace`), so
``RLIMIT_NPROC`` counts the session's processes, not the rest of the user's, and a box run outside a
session gets a network namespace of its own (only loopback: not even the host's abstract sockets,
X11's or D-Bus's).

:func:`check` says whether boxes can be made here at all; the grader refuses to grade when they
cannot (:func:`sandbox_refusal`) unless the teacher accepts the risk by name.
"""
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading

from exam_lab.grader.host import bwrap, cgroups, staging, uids
from exam_lab.grader.host.limits import ADDRESS_SPACE_BYTES, BOX_SHARES, FILE_BYTES, MEMORY_BYTES, PROCESSES, \
    WORK_BYTES, prlimit
from exam_lab.grader.score.boxenv import BOX_HOME, BOX_WS, box_env
from exam_lab.harness.supervisor import DIES_WITH_PARENT, OWNER, WORKSPACE_VARS, at_owner_end

_check_lock = threading.Lock()
_checked = {}
#: What :meth:`Box.open` sets, which :meth:`Box.describe` hands to the session.
_OPENED = ('slot', 'cgroups', 'judge_cgroups', 'rootless', 'owner', 'netns')


class SandboxUnavailable(RuntimeError):
    """The machine cannot make a box: the grader refuses to run student code (unless told to)."""


class Box(object):
    """One submission's box: a uid of its own, its work folder ``<work>/box``, its cgroups.

    :param work: the submission's work folder (root's); the box gets ``<work>/box`` (build/ and devel/
        of its workspace) and sees ``<work>/ws/src`` read-only.
    :param binds: host folders the box sees read-only at the same path (the underlay, the simulators').
    :param bwrap: False for the unsandboxed mode the teacher asked for by name: same user and limits.
    :param cpus: the box's CPU quota in cores (:func:`~exam_lab.grader.host.limits.box_cpus`); None: its
        weight only.
    :param name: its work folder's name in ``work`` (a submission's second box, where one of its runs
        flies beside the other, is ``box-twin``).

    Opened by a grader that is not root, a box with ``bwrap`` is *rootless* (the module's docstring): no
    slot, the grading user's uid (``owner``), and the network namespace it was opened in (``netns``).
    """

    def __init__(self, work, binds=(), bwrap=True, cpus=None, name='box'):
        self.work, self.binds, self.bwrap, self.cpus = work, [os.path.realpath(b) for b in binds], bwrap, cpus
        self.slot, self._lock, self.cgroups, self.mounted = None, None, [], False
        #: The judge's cgroups: {"master": [folders], "probe": [folders]}.
        self.judge_cgroups = {}
        self.name = name
        self.folder = os.path.join(work, name)
        self.notes = []
        self.rootless, self.owner, self.netns = False, None, None

    def describe(self):
        """What the session needs to make this box's command lines (a BoxPlace's JSON): see :meth:`attached`."""
        return {name: getattr(self, name) for name in ('work', 'bwrap', 'cpus', 'binds', 'name') + _OPENED}

    @classmethod
    def attached(cls, place):
        """The box :meth:`describe` described (a BoxPlace), opened by another process (the runner holds it)."""
        box = cls(place.work, place.binds, place.bwrap, place.cpus, place.name or 'box')
        box.slot, box.cgroups, box.rootless, box.owner, box.netns = place.slot, list(place.cgroups), place.rootless, \
            place.owner, place.netns
        box.judge_cgroups = {part: list(folders) for part, folders in place.judge_cgroups.items()}
        return box

    @property
    def home(self):
        """The box's HOME as its processes see it."""
        return BOX_HOME if self.bwrap else os.path.join(self.folder, 'home')

    @property
    def uid(self):
        return self.owner if self.rootless else uids.BOX_UID_BASE + self.slot

    @property
    def judge_uid(self):
        """The uid of this slot's judge (masters, probe); None unsandboxed and not root."""
        return uids.JUDGE_UID_BASE + self.slot if self.slot is not None else None

    @property
    def workspace(self):
        """The student's workspace as the box's processes see it."""
        return BOX_WS if self.bwrap else os.path.join(self.folder, 'ws')

    def open(self):
        """Take a slot (as root) and make the work folder and the cgroups; without root, unsandboxed,
        only the work folder (the grading user's own rights, limits only)."""
        root = os.geteuid() == 0
        if root:
            taken = uids.take_slot()
            if taken is None:
                raise SandboxUnavailable('no free box among %d (uids %d-%d taken)'
                                         % (uids.SLOTS, uids.BOX_UID_BASE, uids.BOX_UID_BASE + uids.SLOTS - 1))
            self.slot, self._lock = taken
            # Emptied again once the grading has ended, however it ended (the supervisor's "Lifetime").
            at_owner_end([sys.executable, '-m', 'exam_lab.grader.host.uids', '--end-slot', str(self.slot)])
        elif self.bwrap:
            self.rootless, self.owner, self.netns = True, os.geteuid(), os.readlink('/proc/self/ns/net')
        self.mounted = staging.work_folder(self.folder, os.path.join(self.work, 'ws', 'src'), not self.bwrap,
                                           self.uid if root else None, WORK_BYTES)  # unsandboxed: a copy, a HOME
        if not root and not self.bwrap:
            return self
        name = 'exam-box-%d' % self.slot if root else 'exam-box-%d-%s%s' % (
            self.owner, os.path.basename(self.work), '' if self.name == 'box' else '-' + self.name)
        self.cgroups = cgroups.make_cgroups(name, MEMORY_BYTES, BOX_SHARES, PROCESSES, self.cpus)
        if root:
            self.judge_cgroups = cgroups.judge_cgroups(self.slot)
        self.notes += _open_notes(root, self.mounted, self.cgroups, self.judge_cgroups)
        return self

    def __enter__(self):
        return self.open()

    def __exit__(self, *exc):
        self.close()
        return False

    def argv(self, command, env, cwd=None, mounts=None, network=True):
        """The command line that runs ``command`` in the box with ``env`` (filtered by
        :func:`~exam_lab.grader.score.boxenv.box_env`) and ``cwd`` (a path as the box sees it; default
        its workspace).

        :param mounts: ``[(host path, path in the box, writable)]`` instead of the workspace (the
            inspection's upload, workspace and output); unsandboxed, commands get host paths instead.
        :param network: False: a network namespace of the box's own, without even loopback.
        """
        env = box_env(env, WORKSPACE_VARS, self.home)
        cwd = cwd or self.workspace
        prefix = cgroups.join(self.cgroups) + prlimit() + (uids.as_user(self.uid) if self.slot is not None else [])
        if not self.bwrap:  # its HOME is a folder of its work folder (made by open); no bubblewrap to end it:
            if OWNER in os.environ:  # its owner's watch does (harness.supervisor's "Lifetime")
                env[OWNER] = os.environ[OWNER]
            return prefix + ['env', '-i', '-C', cwd] + ['%s=%s' % item for item in sorted(env.items())] + list(command)
        if mounts is None:
            mounts = [(os.path.join(self.folder, 'ws'), BOX_WS, True),
                      (os.path.join(self.work, 'ws', 'src'), BOX_WS + '/src', False)]
        # Rootless outside a session: the grading user's network is not the box's.
        own_network = not network or (self.rootless and os.readlink('/proc/self/ns/net') == self.netns)
        return prefix + bwrap.command(self.binds, mounts, cwd, env, own_network) + list(command)

    def judge_argv(self, command, part):
        """The command line that runs the judge's ``command`` (``part``: "master" or "probe") outside
        the box, as this slot's judge uid in the judge's cgroups (as the grading user unsandboxed
        without root). Its environment is the caller's: the judge's own, never the box's."""
        if self.slot is None:
            return list(command)
        return cgroups.join(self.judge_cgroups.get(part, [])) + uids.as_user(self.judge_uid) + list(command)

    def run(self, command, env, log, timeout, cwd=None, mounts=None, network=True):
        """Run ``command`` in the box (:meth:`argv`) and wait at most ``timeout`` s of wall clock, its
        output (stdout and stderr) in the file ``log`` (root's, outside the box); then end whatever of
        the box's uid is left. Returns ``(exit status, None)``, or ``(None, why)`` when it was killed
        at the deadline."""
        status, why = _run_logged(self.argv(command, env, cwd, mounts, network), log, timeout)
        self.end()
        return status, why

    def leftovers(self):
        """Pids of the box's uid still alive (there should be none once its command ended). A rootless
        box has no uid of its own to look for: what it started died with its PID namespace."""
        return uids.pids_of_uid(self.uid) if self.slot is not None else []

    def end(self):
        """Kill whatever still runs as the box's uid; returns how many there were (0 expected)."""
        return uids.end_uid(self.uid) if self.slot is not None else 0

    def close(self):
        if self.slot is not None:
            self.end()
            uids.end_uid(self.judge_uid)  # the session ends its judge's processes; this is for a crashed one
        for folders in [self.cgroups] + list(self.judge_cgroups.values()):
            cgroups.remove_cgroups(folders)
        staging.remove_work_folder(self.folder, self.mounted)
        if self._lock is not None:
            self._lock.close()
        self.slot = None


def _run_logged(argv, log, timeout):
    """Run ``argv`` in a session of its own, its output in the file ``log``, for at most ``timeout`` s;
    ``(exit status, None)`` or ``(None, why)``. Whatever is left of its session is killed."""
    with open(log, 'wb') as out:
        child = subprocess.Popen(DIES_WITH_PARENT + list(argv), stdin=subprocess.DEVNULL, stdout=out,
                                 stderr=subprocess.STDOUT, start_new_session=True)
        try:
            return child.wait(timeout=timeout), None
        except subprocess.TimeoutExpired:
            return None, 'did not finish within %.0f s' % timeout
        finally:
            try:
                os.killpg(child.pid, signal.SIGKILL)  # the unsandboxed mode's children, in its session
            except OSError:
                pass
            child.wait()


def _open_notes(root, mounted, box_cgroups, judge_cgroups):
    """What the teacher should know of a box just opened: the bounds it could not have."""
    notes = []
    if not root:
        notes.append('without root, the box\'s work folder is a plain folder, not a tmpfs of %d MB: each file is '
                     'limited to %d MB, the folder is not' % (WORK_BYTES >> 20, FILE_BYTES >> 20))
    elif not mounted:
        notes.append('the box\'s work folder has no size limit (no tmpfs): files are limited to %d MB each'
                     % (FILE_BYTES >> 20))
    if not box_cgroups:
        notes.append('no cgroup could be made: memory limited per process (%d GB of address space), processes '
                     'per uid (%d), CPU not bounded' % (ADDRESS_SPACE_BYTES >> 30, PROCESSES) if root else
                     'without root, no cgroup (none delegated to this user): memory limited per process (%d GB of '
                     'address space), processes to %d in the session\'s user namespace'
                     % (ADDRESS_SPACE_BYTES >> 30, PROCESSES))
    if root and not judge_cgroups.get('master'):
        notes.append('no cgroup could be made for the judge: the master the student\'s nodes talk to is not '
                     'bounded in memory')
    return notes


def check():
    """None when boxes can be made here; else why not. Tried once per process (a real box runs
    ``true``), under a lock so that concurrent gradings wait for the answer rather than guess it."""
    with _check_lock:
        if 'why' not in _checked:
            _checked['why'] = _try_a_box()
        return _checked['why']



def sandbox_refusal(unsandboxed=False):
    """None when student code may run here: boxes can be made, or the teacher passed the flag that
    names the risk (``unsandboxed``); otherwise the refusal, for the teacher."""
    why = check()
    if why is None or unsandboxed:
        return None
    return ('refusing to run student code without its sandbox: %s. Run the grader on a machine with '
            'bubblewrap and unprivileged user namespaces, as root or as yourself (docs/grading.md, '
            '"Isolation" and "Without root"), or pass --unsandboxed-student-code-can-read-and-damage-my-files '
            'to accept that risk' % why)


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
    work = tempfile.mkdtemp(prefix='exam-box-check-')
    try:
        os.chmod(work, 0o711)
        os.makedirs(os.path.join(work, 'ws', 'src'))
        with Box(work) as box:
            argv = box.argv(['sh', '-c', 'test "$(id -u)" != 0 && test ! -e /root'], {})
            # Rootless, as the session makes it: a box in a user and network namespace of its own.
            done = subprocess.run(bwrap.network_namespace(argv) if rootless else argv,
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

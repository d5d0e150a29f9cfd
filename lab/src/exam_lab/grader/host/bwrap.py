"""The command lines of isolation: bubblewrap's box, and the session's network namespace.

What a box sees (:func:`command`): an empty root, read-only once set up, with read-only binds of
``/usr`` (``/bin``, ``/lib``... are its links on Debian 12), the few ``/etc`` files a ROS process
reads, ``/opt/ros`` and the caller's binds (the simulators' underlay and their sources), then its
mounts (the student's package read-only, its work folder writable). Fresh ``/proc`` and ``/dev``,
private size-capped ``/tmp``, ``/var/tmp``, ``/dev/shm`` and HOME. User, PID, IPC, UTS and cgroup
namespaces of its own; the network one is the session's unless the box gets one of its own.
"""
import os
import subprocess
import threading

from exam_lab.grader.host.limits import TMP_BYTES
from exam_lab.grader.score.boxenv import BOX_HOME

#: /etc files a ROS process reads (name resolution of localhost, the dynamic linker, alternatives).
ETC = ('alternatives', 'catkin', 'ld.so.cache', 'ld.so.conf', 'ld.so.conf.d', 'hosts', 'host.conf', 'nsswitch.conf',
       'localtime', 'ros', 'python3', 'python3.11', 'mime.types', 'ssl')


def command(binds, mounts, cwd, env, own_network):
    """bubblewrap's command line, up to its ``--``, for a box that sees ``binds`` (host folders, read-only
    at the same path) and ``mounts`` (``[(host path, path in the box, writable)]``), starts in ``cwd``
    with exactly the environment ``env``, and gets a network namespace of its own (without even
    loopback) when ``own_network``."""
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
    for path in binds:  # after the private /tmp: an underlay may live in the host's /tmp
        box += ['--ro-bind', path, path]
    for host, inside, writable in mounts:
        box += ['--bind' if writable else '--ro-bind', host, inside]
    if own_network:
        box.append('--unshare-net')
    box += ['--remount-ro', '/', '--chdir', cwd]
    for name, value in sorted(env.items()):
        box += ['--setenv', name, value]
    return box + ['--']


def network_namespace(argv):
    """``argv`` run in a network namespace of its own with only loopback, up. As root ``unshare --net``;
    otherwise bubblewrap makes it, with a user namespace of its own that keeps the grading user's uid
    and shows every file as it is (the master, the probe and the box's steps run inside). ``argv`` keeps
    the parent death signal it is started with (unshare and sh exec it; bubblewrap, which runs it as its
    child, dies with its parent and takes it along: the supervisor's "Lifetime")."""
    if os.geteuid() == 0:
        return ['unshare', '--net', '--', 'sh', '-c', 'ip link set lo up && exec "$@"', 'sh'] + list(argv)
    return ['bwrap', '--unshare-user', '--unshare-net', '--die-with-parent', '--dev-bind', '/', '/', '--'] + list(argv)


_isolation = {}
_isolation_lock = threading.Lock()


def can_isolate():
    """True when this process may run a session in a network namespace of its own (as root with
    unshare, otherwise with bubblewrap where ordinary users may make user namespaces)."""
    with _isolation_lock:
        return _can_isolate()


def _can_isolate():
    if 'ok' not in _isolation:
        try:
            _isolation['ok'] = subprocess.run(network_namespace(['true']), stdout=subprocess.DEVNULL,
                                              stderr=subprocess.DEVNULL, timeout=10).returncode == 0
        except (OSError, subprocess.SubprocessError):
            _isolation['ok'] = False
    return _isolation['ok']

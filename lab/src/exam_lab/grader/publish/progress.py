"""What the grader is doing while it grades, on the terminal. No rospy here.

A session's steps are seen from the files it writes into its log folder as it goes (:data:`STEPS`):
the session itself needs no channel of its own, and a missing file only means a step not shown.
The runner reports ``unpack`` itself. On a terminal, a class run shows k of n, the students being
graded now with their step, and an estimate of the time left, on one line redrawn every second; a
single run prints each step as it starts. When stdout is not a terminal (CI, a pipe), nothing but the
lines the grader always printed.
"""
import contextlib
import os
import sys
import threading
import time

from exam_lab.grader.score import safe_text

#: (file the session writes into its log folder when the step starts, the step).
STEPS = (('build.log', 'build'), ('plan-main.json', 'main flight'), ('plan-threshold.json', 'threshold flight'))
#: Seconds one student takes before any has finished (docs/grading.md, "Speed").
PRIOR_S = 45.0
#: Seconds between two looks at the log folder, and between two redraws of the line.
POLL_S = 0.5
REDRAW_S = 1.0


def report(on_step, step):
    if on_step is not None:
        on_step(step)


@contextlib.contextmanager
def watching(log_dir, on_step):
    """Call ``on_step(step)`` once for each step of :data:`STEPS` whose file appears in ``log_dir``."""
    if on_step is None:
        yield
        return
    stop = threading.Event()

    def watch():
        seen = set()
        while True:
            # One listing a look: the session writes the files in the steps' order, so a listing that
            # holds a later step's file holds the earlier ones' too (two looks at two files could
            # see the later file without the earlier one, written between the looks).
            try:
                present = set(os.listdir(log_dir))
            except OSError:
                present = set()
            for name, step in STEPS:
                if step not in seen and name in present:
                    seen.add(step)
                    on_step(step)
            if stop.wait(POLL_S):
                return

    thread = threading.Thread(target=watch, name='progress-watch')
    thread.daemon = True
    thread.start()
    try:
        yield
    finally:
        stop.set()
        thread.join(2.0)


def estimate_left(durations, running, waiting, jobs, prior=PRIOR_S):
    """Seconds left, or None while nothing says it: each student takes the mean duration of those done
    (``prior`` before any is done), or as long as the longest running one has taken when that is
    longer (a student known to take more than the mean makes the mean wrong: the estimate grows with
    what is seen, never stuck at a floor); each running one takes what it still lacks of that (a tenth
    of it at least), and
    ``jobs`` run at a time. None before the first student is done once a running one outlasts the
    prior: the prior was wrong and no duration is known yet.

    :param durations: seconds of the students done; :param running: seconds each running one has taken.
    """
    longest = max(running) if running else 0.0
    if not durations and longest > prior:
        return None
    each = max(sum(durations) / len(durations) if durations else prior, longest)
    work = waiting * each + sum(max(each - spent, 0.1 * each) for spent in running)
    return work / max(1, min(jobs, waiting + len(running)))


def duration(seconds):
    seconds = int(round(seconds))
    return '%d min %02d s' % (seconds // 60, seconds % 60) if seconds >= 60 else '%d s' % seconds


class ClassProgress(object):
    """The class run's progress, for :func:`exam_lab.grader.class_run.grade_class` (thread-safe)."""

    def __init__(self, jobs, stream=None, live=None, clock=time.monotonic):
        self.stream = stream or sys.stdout
        self.live = self.stream.isatty() if live is None else live
        self.jobs, self.clock = jobs, clock
        self.lock = threading.Lock()
        self.total, self.done, self.running = 0, [], {}
        self.stop = threading.Event()
        self.ticker = None

    def begin(self, names):
        self.total = len(names)
        if self.live:
            self.ticker = threading.Thread(target=self._tick, name='progress-line')
            self.ticker.daemon = True
            self.ticker.start()

    def started(self, name):
        with self.lock:
            self.running[name] = [self.clock(), 'unpack']
            self._draw()

    def step(self, name, step):
        with self.lock:
            if name in self.running:
                self.running[name][1] = step
                self._draw()

    def finished(self, record):
        with self.lock:
            self.running.pop(record['student'], None)
            self.done.append(record.get('seconds', 0.0))
            self._clear()
            self.stream.write(safe_text.one_line('graded %s: %s/%s, %s (%.0f s)' % (
                record['student'], record['total'], record['max'], record.get('status', 'graded'),
                record.get('seconds', 0.0))) + '\n')
            self._draw()
            self.stream.flush()

    def say(self, line):
        """One line of news about the run (the Slurm engine's array state), above the status line."""
        with self.lock:
            self._clear()
            self.stream.write(line + '\n')
            self._draw()
            self.stream.flush()

    def close(self):
        self.stop.set()
        if self.ticker is not None:
            self.ticker.join(2.0)
        with self.lock:
            self._clear()
            self.stream.flush()

    def line(self):
        """The status line: k of n, who is being graded and at which step, the time left."""
        now = self.clock()
        waiting = self.total - len(self.done) - len(self.running)
        left = estimate_left(self.done, [now - start for start, _ in self.running.values()], waiting, self.jobs)
        now_on = ', '.join('%s (%s, %s)' % (name, step, duration(now - start))
                           for name, (start, step) in sorted(self.running.items()))
        return safe_text.one_line('[%d of %d graded] now: %s; %s' % (
            len(self.done), self.total, now_on or '-', 'about %s left' % duration(left) if left is not None else
            'time left known when the first student is done'))

    def _tick(self):
        while not self.stop.wait(REDRAW_S):
            with self.lock:
                self._draw()

    def _draw(self):
        if self.live and self.total:
            self.stream.write('\r\x1b[K' + self.line())
            self.stream.flush()

    def _clear(self):
        if self.live:
            self.stream.write('\r\x1b[K')


class StepProgress(object):
    """A single submission's steps as they start, one line each (on a terminal only)."""

    def __init__(self, stream=None, live=None, clock=time.monotonic):
        self.stream = stream or sys.stdout
        self.live = self.stream.isatty() if live is None else live
        self.clock = clock
        self.start = clock()

    def __call__(self, step):
        if self.live:
            self.stream.write('%6.1f s  %s\n' % (self.clock() - self.start, step))
            self.stream.flush()

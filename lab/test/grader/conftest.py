"""Fixtures shared by the grader's test modules: each class run here is graded once a session and
read by several modules (a grading costs about 60 s of a slot; issue 37 point 6).

The class runs the selected tests need start together as soon as the session knows its tests, in the
background (class_runs.py, hostile_run.py), as many gradings side by side as BUDGET allows, while the
tests that grade for themselves run (the Slurm and non-root modules first: the longest chains); a
fixture waits for its run. A grading mostly waits for its flight, so the budget is above the default
JOBS: the fair class and the fairness sample, whose timing judgements are the closest, are graded
inside it and hold every point (their tests are the proof; a grade that moves under load is a defect).
EXAM_TEST_GRADINGS=<n> sets the budget (1: one run at a time, as before).
"""
import json
import os
import subprocess
import sys
import threading
import time

import pytest

import class_runs
import hostile_run
from exam_lab.harness.wait import wait_until

HERE = os.path.dirname(os.path.realpath(__file__))
#: Modules run first: each grades for itself a chain of steps (a workspace built as another user, a
#: cluster, a class), waiting most of the time while the class runs above go on.
FIRST = ('test_slurm', 'test_nonroot')


def budget():
    """How many gradings the background runs hold at once: EXAM_TEST_GRADINGS, else two default JOBS."""
    from exam_lab.grader import class_run
    return max(1, int(os.environ.get('EXAM_TEST_GRADINGS') or 2 * class_run.default_jobs()))


class Runs(object):
    """The session's class runs (one thread each, waiting), each started as soon as its weight fits in
    the budget, in the listed order. The hostile class comes first, with a head start: the others (and
    the tests that grade for themselves, :func:`_hostile_head_start`) wait until its victim, graded
    beside the burner, is graded, so that the victim's timing measures the burner, not the session."""

    def __init__(self, factory, runs, limit):
        self.factory, self.limit, self.used = factory, limit, 0
        self.cond = threading.Condition()
        self.results, self.errors, self.cleanups, self.threads = {}, {}, [], []
        self.running, self.closing = set(), False
        self.order = list(runs)
        self.head_start = threading.Event()
        if 'hostile_class' not in [name for name, _ in self.order]:
            self.head_start.set()
        for name, weight in runs:
            thread = threading.Thread(target=self._run, args=(name, min(limit, weight)), name=name, daemon=True)
            self.threads.append(thread)

    def start(self):
        self.factory.getbasetemp()  # made here, once: threads making it at once would make one each
        if any(name == 'main_class' for name, _ in self.order):
            # Before any run: the similarity check's venv, made by one process (nothing locks its making).
            from exam_lab.grader.host import similarity_setup
            similarity_setup.ensure_venv()
        for thread in self.threads:
            thread.start()

    def _done(self, name):
        return name in self.results or name in self.errors

    def _run(self, name, weight):
        if name != 'hostile_class':
            self.head_start.wait(900.0)  # the head start's own bound, should it hang
        with self.cond:
            turn = [n for n, _ in self.order].index(name)
            # first fit: a run waits for the runs before it that fit no better than it does
            self._wait(lambda: self.closing or (self.used + weight <= self.limit and
                       all(self._done(n) or n in self.running or w > weight for n, w in self.order[:turn])))
            if self.closing:
                self.errors[name] = 'not started: the session ended first'
                self.cond.notify_all()
                return
            self.used += weight
            self.running.add(name)
        started = time.monotonic()
        try:
            result = self._grade(name)
            with self.cond:
                self.results[name] = result
        except BaseException as err:  # the fixture reading it fails, with why
            with self.cond:
                self.errors[name] = '%s: %s' % (type(err).__name__, err)
        finally:
            self.head_start.set()
            with self.cond:
                self.used -= weight
                self.running.discard(name)
                self.cond.notify_all()
            sys.stderr.write('class run %s: %.0f s\n' % (name, time.monotonic() - started))

    def _grade(self, name):
        root = str(self.factory.mktemp(name))
        if name == 'hostile_class':  # grade.py in a child process already; its cleanup at the session's end
            victim = os.path.join(root, 'out', hostile_run.VICTIM_NAME, 'grade.json')
            threading.Thread(target=lambda: (wait_until(lambda: os.path.isfile(victim) or self._done(name), 900.0,
                                                        period=0.5), self.head_start.set()), daemon=True).start()
            run = hostile_run.grade(root)
            self.cleanups.append(run)
            return next(run)
        with open(os.path.join(root, 'run.log'), 'w') as log:
            if self.closing:
                raise RuntimeError('not started: the session ended first')
            child = subprocess.Popen([sys.executable, os.path.join(HERE, 'class_runs.py'), name, root], cwd=HERE,
                                     stdout=log, stderr=subprocess.STDOUT)
            status = child.wait()
        if status != 0:
            with open(os.path.join(root, 'run.log'), errors='replace') as log:
                raise RuntimeError('exit %d\n%s' % (status, log.read()[-5000:]))
        with open(os.path.join(root, class_runs.RESULT)) as f:
            return json.load(f)

    def _wait(self, predicate):
        while not predicate():  # in steps: Ctrl-C reaches the main thread between them
            self.cond.wait(1.0)

    def result(self, name):
        with self.cond:
            self._wait(lambda: self._done(name))
            if name in self.errors:
                pytest.fail('the class run %s failed: %s' % (name, self.errors[name]), pytrace=False)
            return self.results[name]

    def wait_all(self):
        with self.cond:
            self._wait(lambda: all(self._done(n) for n, _ in self.order))

    def close(self):
        """Start no more runs, wait for those going (each grading ends within its budget; a class killed
        would leave its boxes running), then the hostile class's cleanup."""
        self.head_start.set()
        with self.cond:
            self.closing = True
            self.cond.notify_all()
        self.wait_all()
        for run in self.cleanups:
            run.close()


#: ``fixture name: its weight`` of the background runs, in the order they start.
def _runs():
    return [('hostile_class', 2)] + [(name, weight()) for name, (_, weight) in class_runs.RUNS.items()]


_session = {'runs': None}


def pytest_collection_modifyitems(session, config, items):
    items.sort(key=lambda item: 0 if item.module.__name__ in FIRST else 1)  # stable: the rest keeps its order


def pytest_collection_finish(session):
    if session.config.option.collectonly:
        return
    needed = set(name for item in session.items for name in getattr(item, 'fixturenames', ()))
    runs = [(name, weight) for name, weight in _runs() if name in needed and
            (name != 'hostile_class' or os.geteuid() == 0)]
    if runs:
        _session['runs'] = Runs(session.config._tmp_path_factory, runs, budget())
        _session['runs'].start()


def pytest_sessionfinish(session):
    if _session['runs'] is not None:
        _session['runs'].close()  # nothing graded after the session


@pytest.fixture(scope='session', autouse=True)
def _hostile_head_start():
    """The session's first test waits for the hostile class's head start (:class:`Runs`)."""
    if _session['runs'] is not None:
        while not _session['runs'].head_start.wait(1.0):  # in steps: Ctrl-C reaches it
            pass


def _result(name):
    if _session['runs'] is None or name not in [n for n, _ in _session['runs'].order]:
        pytest.skip('the class run %s was not started' % name)
    return _session['runs'].result(name)


@pytest.fixture(scope='session')
def all_class_runs_done():
    """Every background class run finished (a test of what the whole machine holds after grading)."""
    if _session['runs'] is not None:
        _session['runs'].wait_all()


@pytest.fixture(scope='session')
def hostile_class():
    """The one class of every hostile student and one victim (:mod:`hostile_run`), graded once."""
    if os.geteuid() != 0:
        pytest.skip('the sandbox is made by root (docs/grading.md, "Isolation")')
    return _result('hostile_class')


@pytest.fixture(scope='session')
def main_class():
    """test_grade's main class (:func:`class_runs.main_class`), its desk written as ``make grade`` writes
    it: test_grade reads its records, test_page_browser opens its pages. ``{'out', 'klass', 'records'
    (graded order), 'by_name', 'lines' (what the desk printed)}``."""
    run = dict(_result('main_class'))
    run['by_name'] = {r['student']: r for r in run['records']}
    return run


@pytest.fixture(scope='session')
def fair_class():
    """test_grade's third kind of class (:func:`class_runs.fair_class`): ``{'out', 'records'}``."""
    return _result('fair_class')


@pytest.fixture(scope='session')
def fairness_sample():
    """test_fairness's sample graded as one class (:func:`class_runs.fairness_sample`): ``{'records'}``."""
    return _result('fairness_sample')


@pytest.fixture(scope='session')
def singles():
    """Submissions graded alone on a sheet named (:data:`class_runs.SINGLES`): ``{name: record}``."""
    return _result('singles')

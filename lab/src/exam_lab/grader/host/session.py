"""One submission's session: build the student's workspace, run its node against the probe.

The runner starts this module as root, alone in a network namespace that has only loopback::

    python3 -m exam_lab.grader.host.session JOB.json

This orchestrator stays root (it starts the boxes, which drop root themselves) but parses no byte of the
student's: it reads roslaunch's output and the probe's JSON, both capped. The judge (a master per run,
the probe with its fake drone) runs as the slot's judge uid (:meth:`~exam_lab.grader.host.sandbox.Box.judge_argv`:
not root, not the box's uid), the master bounded in memory and both weighted above the box for CPU,
under a :class:`~exam_lab.harness.supervisor.Supervisor` whose log folder the student's code cannot see;
the judge's own folder (``judge_home``: ROS logs, its copy of the job, the main run's word, the probe's results) is
the judge's, mode 0700.
Every step that runs the student's code (``catkin_make``, ``roslaunch`` and the nodes) runs in the
submission's :class:`~exam_lab.grader.host.sandbox.Box`, another user in namespaces of its own that shares
only this network namespace. The box's environment starts empty: the underlay's, ROS's, a fresh HOME;
the student's own ``devel/setup.bash`` is sourced inside the box, never here, and only for the build's
products to run: roslaunch's verdict on the file as handed in comes first, before anything of the
student's has run (:func:`launch_verdict`). After each step, the box's
uid must have no process left (they die with its PID namespace); any found is killed and reported.

Job (JSON, written by :mod:`exam_lab.grader.runner`): ``workspace`` (the student's catkin workspace as
the box sees it), ``box`` (:meth:`~exam_lab.grader.host.sandbox.Box.describe`), ``underlay`` (setup.bash of
the simulators' workspace), ``log_dir``, ``namespace`` (the drone's), ``build_timeout`` /
``run_timeout`` (s), ``budget`` (s the session may take, what is left of ``student_budget``, the
student's whole grading: :class:`~exam_lab.grader.host.run.Budget`), ``judge_home`` (the judge's folder), ``runs``: the main run and, when the launch
file has a threshold the grader can change, the threshold run: each ``{"tag", "launch" (derived launch
file, as the box sees it), "plan" (the probe's, as the runner made it: the judge reads it from
this job)}`` (and, for the run flown in the submission's second
box, its ``box`` and ``judge_home``), ``side_by_side`` (the two runs at once:
:mod:`~exam_lab.grader.host.side_by_side`; otherwise one after the other, here). Writes ``<log_dir>/session.json``: ``{"build":
{...}, "runs": [{"tag", "probe" (the probe's result as read, or None), "probe_wall" (the wall times
the probe started and its result was in), "master" (its memory, its uid, whether it ended during the
run), "probe_uid", "launch": {...}}], "survivors": n, "launch_check", "budget_used" (the sentence when
the budget stopped a step, else None), "outcome"}``: a
:class:`~exam_lab.grader.score.records.SessionRecord` (checked, every text in it made safe there), and
each probe's result as ``<log_dir>/probe-<tag>.json`` (its checked record), and each step's wall and
CPU time as ``<log_dir>/timings.json`` (:mod:`~exam_lab.grader.host.timings`). Whether a run counts
(its result's times, the clock, the master) is the rubric's to say (:mod:`~exam_lab.grader.score.runs`),
from these facts, again at each rescore.
"""
import dataclasses
import os
import sys

from exam_lab.grader import contract
from exam_lab.grader.host import side_by_side as both
from exam_lab.grader.host.run import (
    MAIN_WORD, MIN_RUN_S, RUN_STOP_S, STEP_STOP_S, Budget, base_environment, capped_log, judge_environment,
    run_one, tail)
from exam_lab.grader.host.sandbox import Box
from exam_lab.grader.host import timings
from exam_lab.grader.host.timings import Stopwatch, boxes_cpu
from exam_lab.grader.score.job import JobRecord
from exam_lab.grader.score.records import Outcome, RecordError, SessionRecord
from exam_lab.grader.score.runs import judged_run, warned_in_long_excursion
from exam_lab.grader.score.safe_text import clean as clean_text
from exam_lab.harness.supervisor import Supervisor

#: roslaunch's own check of the launch file as handed in: s at most, lines of its words kept.
LAUNCH_CHECK_TIMEOUT = 30.0
LAUNCH_CHECK_LINES = 8
#: Run in the box by the system's python3: roslaunch's loader reads the file as ``roslaunch exam
#: exam.launch`` would (every include, argument, node name: ``roslaunch --nodes`` does the same) without
#: starting anything, and says what roslaunch would print as errors before launching (unknown tags and
#: attributes), which ``roslaunch --nodes`` keeps to itself.
_LAUNCH_CHECK = '''
import sys
from roslaunch.config import load_config_default
try:
    config = load_config_default([sys.argv[1]], None, verbose=False, assign_machines=False)
except Exception as err:
    print('%s: %s' % (type(err).__name__, ' '.join(str(err).split())))
    sys.exit(1)
for error in config.config_errors:
    print('WARNING: %s' % ' '.join(str(error).split())[:200])
for node in config.nodes:
    print('/' + (node.namespace + node.name).strip('/'))
'''


def launch_verdict(sup, box, base_env, *, workspace, handed_in_launch, timeout=LAUNCH_CHECK_TIMEOUT):
    """roslaunch's verdict on the student's launch file as handed in (``handed_in_launch``, in the
    ``workspace``'s src/), read by roslaunch's own loader (:data:`_LAUNCH_CHECK`) in the box before
    anything of the student's has run: the session asks for it before the build, with the underlay's
    environment and the package's folder on ROS_PACKAGE_PATH (all ``$(find exam)`` needs), never the
    student's devel/setup.bash (its environment hooks would run first and could answer for roslaunch),
    from the box's fresh HOME (a ``python3 -c`` imports first from its working folder, and the build
    can write the workspace's). ``{"file" (in the package), "status" (exit code, None when it did not
    finish), "refused" (roslaunch's words, '' when accepted), "warnings" [lines], "nodes" [names]}``;
    None without a launch file. The output comes from the box: capped, read as text."""
    relative = handed_in_launch
    if not relative:
        return None
    path = os.path.join(workspace, 'src', relative)
    packages = ':'.join(p for p in (os.path.join(workspace, 'src'), base_env.get('ROS_PACKAGE_PATH')) if p)
    env = dict(base_env, ROS_PACKAGE_PATH=packages, ROS_HOME=os.path.join(box.home, 'ros-check'))
    status, output, _ = sup.run('launch-check', box.argv(['/usr/bin/python3', '-c', _LAUNCH_CHECK, path], env,
                                                         cwd=box.home), timeout=timeout)
    lines = [l.strip()[:300] for l in clean_text(output).replace(workspace.rstrip('/') + '/src/', '')
             .splitlines() if l.strip()]
    words = [l for l in lines if not l.startswith('/')]
    return {'file': relative.split('/', 1)[-1], 'status': status,
            'refused': '' if status == 0 else ' '.join(words[-LAUNCH_CHECK_LINES:]) or
            ('roslaunch did not finish within %.0f s' % timeout if status is None
             else 'roslaunch exit %s' % status),
            'warnings': [l[len('WARNING: '):] for l in words if l.startswith('WARNING: ')][:LAUNCH_CHECK_LINES]
            if status == 0 else [],
            'nodes': [l for l in lines if l.startswith('/')][:20]}


def session(job, job_path=None, watch=None):
    """Check, build and run one submission (the module's docstring); returns the value of its
    :class:`~exam_lab.grader.score.records.SessionRecord`. With ``job.side_by_side`` (and ``job_path``,
    the job's file), the two runs fly at once (:func:`side_by_side`). ``watch``: a
    :class:`~exam_lab.grader.host.timings.Stopwatch` that times each step."""
    watch = watch or Stopwatch()
    result = {'outcome': Outcome.RAN, 'build': None, 'runs': [], 'survivors': 0}
    box = Box.attached(job.box)
    judge_env = judge_environment(job.judge_home, box)
    budget = Budget(job.budget, job.student_budget)
    with Supervisor(job.log_dir, env=judge_env) as sup:
        base_env = base_environment(job)
        # roslaunch's verdict first: nothing of the student's has run yet (no build, no environment hook).
        limit, by_budget = budget.limit(LAUNCH_CHECK_TIMEOUT, STEP_STOP_S)
        with watch.stage('launch_check'):
            result['launch_check'] = launch_verdict(sup, box, base_env, workspace=job.workspace,
                                                    handed_in_launch=job.handed_in_launch, timeout=limit)
            result['survivors'] += box.end()
        if by_budget and (result['launch_check'] or {}).get('status', 0) is None:
            result['budget_used'] = result['error'] = budget.spend(
                'roslaunch\'s check of the launch file was stopped after %.0f s' % limit)
            result['outcome'] = Outcome.CHECK_STOPPED
            return result
        limit, by_budget = budget.limit(job.build_timeout, STEP_STOP_S)
        with watch.stage('build'):
            status, _, seconds = sup.run(
                'build', box.argv(['catkin_make', '--directory', job.workspace,
                                   '-DPYTHON_EXECUTABLE=/usr/bin/python3', '-DCATKIN_ENABLE_TESTING=OFF'],
                                  dict(base_env, ROS_HOME=os.path.join(box.home, 'ros'))),
                timeout=limit)
            result['survivors'] += box.end()
        result['build'] = {'status': status, 'seconds': seconds, 'tail': tail(capped_log(sup, 'build')),
                           'timeout': limit}
        if status is None:
            result['build']['stopped'] = budget.spend('catkin_make was stopped after %.0f s, nothing was run' % seconds) \
                if by_budget else 'catkin_make did not finish within the build\'s time limit (%.0f s)' % limit
        if status != 0:
            result['budget_used'] = budget.used
            result['outcome'] = Outcome.BUILD_STOPPED if status is None else Outcome.BUILD_FAILED
            return result
        with watch.stage('runs'):
            if job.side_by_side and job_path and len(job.runs) == 2 and both.copy_build(box, job.runs):
                watch.extra['side_by_side'] = True
                both.side_by_side(sup, job, job_path, budget, result)
            else:
                one_after_the_other(sup, job, base_env, box, budget, result)
        result['budget_used'] = budget.used
    return result


def one_after_the_other(sup, job, base_env, box, budget, result):
    """The runs of ``job`` in this process, the threshold run after the main run and only when the node
    warned in it (its result counted as the rubric counts it: :func:`judged_run`), waiting for its late
    WARNING as long as the main run's took (told before it starts, as a run flown beside it is told:
    :func:`~exam_lab.grader.host.side_by_side.tell_threshold_run`); into ``result``."""
    for run in job.runs:
        run = dataclasses.replace(run, box=None, judge_home=None)  # all in ``box``, the job's judge's
        if run.tag == 'threshold':
            main = judged_run(result['runs'][0])['probe'] if result['runs'] else None
            if not warned_in_long_excursion(main):
                result['threshold_skipped'] = 'the node never warned in the main run'
                break
            both.tell_threshold_run(main, os.path.join(job.judge_home, MAIN_WORD), box.judge_uid)
        if budget.left(RUN_STOP_S) < MIN_RUN_S:
            budget.spend('the %s run was not started (%.0f s left)' % (run.tag, budget.left()))
            break
        result['runs'].append(run_one(sup, job, run, base_env, box, budget))
        result['survivors'] += result['runs'][-1]['survivors']


def main(argv):
    if len(argv) != 1:
        sys.stderr.write('usage: python3 -m exam_lab.grader.host.session JOB.json\n')
        return 2
    try:
        job = contract.read_record(argv[0], JobRecord)
    except RecordError as err:  # the grader's own bug, as below
        sys.stderr.write('the job is not one: %s\n' % err)
        return 1
    watch = Stopwatch(boxes_cpu(*[Box.attached(box) for box in [job.box] + [r.box for r in job.runs if r.box]]))
    try:
        with watch.stage('session'):
            record = SessionRecord.make(session(job, argv[0], watch))
    except RecordError as err:  # the grader's own bug: the runner says the session failed, and why
        sys.stderr.write('the session\'s record is not one: %s\n' % err)
        return 1
    for tag in ('main', 'threshold'):
        name = 'timings-%s.json' % tag
        if contract.exists(os.path.join(job.log_dir, name)):
            watch.stages.update(timings.read(job.log_dir, name).get('stages') or {})
            os.unlink(os.path.join(job.log_dir, name))
    watch.write(job.log_dir)
    contract.write_record(os.path.join(job.log_dir, SessionRecord.FILE), record)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

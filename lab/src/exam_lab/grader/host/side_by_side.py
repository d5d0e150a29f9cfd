"""The two runs of a submission side by side (:func:`side_by_side`): each a process of its own,
started by the session as root::

    python3 -m exam_lab.grader.host.side_by_side JOB.json main|threshold SECONDS

in a network namespace of its own with only loopback (:func:`~exam_lab.grader.host.bwrap.network_namespace`),
on a master of its own, its student steps in a box of its own (one of the two runs, drawn by the
runner, in the submission's second box, on a copy of the build: :func:`copy_build`), under a
supervisor of its own (:func:`run_marker`). It writes its run's record (:func:`~exam_lab.grader.host.run.run_one`)
as ``<log_dir>/run-<tag>.json`` and its timings as ``<log_dir>/timings-<tag>.json``.
"""
import json
import os
import shutil
import subprocess
import sys

from exam_lab.grader import contract
from exam_lab.grader.host import bwrap
from exam_lab.grader.host.run import (
    MAIN_WORD, STEP_STOP_S, Budget, base_environment, judge_environment, probe_record, run_one, tail)
from exam_lab.grader.host.sandbox import Box
from exam_lab.grader.host.timings import Stopwatch, boxes_cpu
from exam_lab.grader.score.job import JobRecord
from exam_lab.grader.score.records import RecordError, SessionRecord
from exam_lab.grader.score.runs import judged_run, warned_in_long_excursion, warning_latency
from exam_lab.harness.supervisor import Supervisor, end_pids, marked
from exam_lab.harness.wait import wait_until


def run_marker(log_dir, tag):
    """The marker of the processes of the run ``tag`` flown side by side (:class:`Supervisor`'s)."""
    return os.path.join(log_dir, 'run-%s' % tag)


def markers(log_dir):
    """Every marker the processes of a session logging in ``log_dir`` carry: its own and each run's
    flown side by side (what the runner ends once the session is over, whatever happened to it)."""
    return [log_dir] + [run_marker(log_dir, tag) for tag in ('main', 'threshold')]


def copy_build(box, runs):
    """Give the second box (the ``box`` of one of ``runs``) the build ``box`` made: root copies its
    ``build/`` and ``devel/`` byte for byte (``cp -a``: links as links, never followed; nothing of the
    box's uid runs any more), owned by the second box's uid; nothing of that box has run yet, so no link
    of its own can lie in the way. False when it could not be copied (the runs then fly one after the
    other, in ``box``)."""
    twins = [run.box for run in runs if run.box]
    if not twins or not box.bwrap:
        return False
    twin = Box.attached(twins[0])
    source, target = os.path.join(box.folder, 'ws'), os.path.join(twin.folder, 'ws')
    try:
        for part in ('build', 'devel'):
            shutil.rmtree(os.path.join(target, part))
        done = subprocess.run(['cp', '-a', '--', os.path.join(source, 'build'), os.path.join(source, 'devel'),
                               target], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=60)
        if done.returncode != 0:
            return False
        if twin.slot is not None:
            done = subprocess.run(['chown', '-R', '-h', '%d:%d' % (twin.uid, twin.uid), '--',
                                   os.path.join(target, 'build'), os.path.join(target, 'devel')],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=60)
        return done.returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False


def side_by_side(sup, job, job_path, budget, result):
    """The two runs at once, each a process of its own (``session JOB --run TAG``) in a network
    namespace of its own with only loopback, its master, its box (the threshold run's: a uid, a copy
    of the build, a judge of its own) and its supervisor: a node sees the same in either, and neither
    run can reach the other. Once the main run's result is in (or it ended without one), the threshold
    run is told whether the node warned and how late (:data:`~exam_lab.grader.host.run.MAIN_WORD`), so
    it waits for a late WARNING as long as the main run's took; a threshold run whose main run never
    warned (its result counted as the rubric counts it) is not kept, as when it is not flown. Which run
    flies in the copy was drawn by the runner (:func:`~exam_lab.grader.runner.plan_job`): a node that
    tells the copy (its uid, its files' times) learns nothing of its run. Into ``result``."""
    main, threshold = job.runs
    word = os.path.join(job.judge_home_of(threshold), MAIN_WORD)
    main_result = os.path.join(job.judge_home_of(main), 'probe-main.json')
    started = {}
    for run in job.runs:
        argv = [sys.executable, '-m', 'exam_lab.grader.host.side_by_side', job_path, run.tag, '%.3f' % budget.left()]
        started[run.tag] = sup.start('run-%s' % run.tag, bwrap.network_namespace(argv))
    told = []

    def done():
        if not told and (os.path.isfile(main_result) or started['main'].poll() is not None):
            probe = probe_record(main_result)[0] if os.path.isfile(main_result) else None
            tell_threshold_run(probe, word, Box.attached(job.box_of(threshold)).judge_uid)
            told.append(True)
        return all(proc.poll() is not None for proc in started.values())

    wait_until(done, budget.left() + STEP_STOP_S, period=0.1)
    sup.stop_all(list(started.values()), grace=STEP_STOP_S)
    for tag in started:
        end_pids(marked(run_marker(job.log_dir, tag)))
    runs = [read_run(job.log_dir, tag, sup) for tag in started]
    result['survivors'] += sum(run['survivors'] for run in runs)
    result['runs'] = runs[:1]
    if not warned_in_long_excursion(judged_run(runs[0])['probe']):
        result['threshold_skipped'] = 'the node never warned in the main run'
    else:
        result['runs'].append(runs[1])
    for run in runs:
        if run.get('budget'):
            budget.used = budget.used or run['budget']


def tell_threshold_run(probe, word, judge_uid):
    """Write the main run's word (:data:`~exam_lab.grader.host.run.MAIN_WORD`, the file ``word``) from
    its probe's result (None when there is none), for the threshold run's judge (``judge_uid``)."""
    said = {'warned': warned_in_long_excursion(probe), 'warn_after': warning_latency(probe)}
    with open(word + '.part', 'w') as f:
        json.dump(said, f)
    if judge_uid is not None:
        os.chown(word + '.part', judge_uid, judge_uid)
    os.rename(word + '.part', word)


def run_file(log_dir, tag):
    return os.path.join(log_dir, 'run-%s.json' % tag)


def read_run(log_dir, tag, sup):
    """The record the run ``tag`` flown side by side wrote (this session's own process wrote it);
    :raises RuntimeError: when it wrote none (its master did not start...): the session fails, as
        it does when that happens to a run flown in this process."""
    try:
        return json.loads(contract.read_text(run_file(log_dir, tag), SessionRecord.MAX_BYTES))
    except (contract.ContractError, ValueError):
        raise RuntimeError('the %s run failed: %s' % (tag, tail(sup.output('run-%s' % tag), 10)))


def run_alone(job, tag, seconds):
    """The run ``tag`` of ``job`` in this process (started by :func:`side_by_side` in a network
    namespace of its own), within ``seconds``: its record in ``<log_dir>/run-<tag>.json``, its
    timings in ``<log_dir>/timings-<tag>.json``."""
    run = job.run(tag)
    box = Box.attached(job.box_of(run))
    watch = Stopwatch(boxes_cpu(box))
    judge_home = job.judge_home_of(run)
    budget = Budget(seconds, job.student_budget)
    with watch.stage(tag):
        with Supervisor(job.log_dir, env=judge_environment(judge_home, box), marker=run_marker(job.log_dir, tag)) as sup:
            record = run_one(sup, job, run, base_environment(job), box, budget)
    contract.write_text(run_file(job.log_dir, tag), json.dumps(record))
    watch.extra['tag'] = tag
    watch.write(job.log_dir, 'timings-%s.json' % tag)


def main(argv):
    if len(argv) != 3 or argv[1] not in ('main', 'threshold'):
        sys.stderr.write('usage: python3 -m exam_lab.grader.host.side_by_side JOB.json main|threshold SECONDS\n')
        return 2
    try:
        job = contract.read_record(argv[0], JobRecord)
    except RecordError as err:  # the grader's own bug: the session says the run failed, and why
        sys.stderr.write('the job is not one: %s\n' % err)
        return 1
    run_alone(job, argv[1], float(argv[2]))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

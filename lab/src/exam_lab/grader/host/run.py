"""One run of a submission: a master, the student's launch in its box, the probe beside it; what its
output and the probe's result say (:func:`run_one`: facts, for the rubric to judge), within what is left of the student's budget
(:class:`Budget`). Root's side: it reads roslaunch's output and the probe's JSON, both capped, and
parses no byte of the student's. :mod:`~exam_lab.grader.host.session` flies the runs of a session one
after the other, :mod:`~exam_lab.grader.host.side_by_side` both at once.
"""
import json
import os
import re
import sys
import time

from exam_lab.grader.host.cgroups import memory_use, reset_memory_peak
from exam_lab.grader.contract import read_capped, read_record, write_record
from exam_lab.grader.score.job import JobRecord
from exam_lab.grader.score.records import MAX_ENDED, MAX_LOG_TEXT, ProbeRecord, RecordError
from exam_lab.grader.score.schema import plain
from exam_lab.grader.score.runs import WATCHED_DEATHS
from exam_lab.grader.score.safe_text import clean as clean_text
from exam_lab.harness.supervisor import ros_env, workspace_env
from exam_lab.harness.wait import wait_until

#: roslaunch's words for a node that ended: "[exam-1] process has died [pid 12, exit code 1, ...]";
#: a required node's death is announced as "REQUIRED process [exam-1] has died!" first.
_ENDED = re.compile(r'(?:\[([^\]\s]+)\] )?process has (died|finished cleanly)(?: \[pid \d+, (exit code -?\d+))?')
_REQUIRED = re.compile(r'REQUIRED process \[([^\]]+)\] has died')
#: Lines of the roslaunch log that say a node could not even be started.
_NOT_STARTED = re.compile(r'^(ERROR: cannot launch node.*|RLException:.*|.*Invalid roslaunch XML.*)$', re.M)
#: roslaunch's own chatter, left out of what the teacher reads.
_CHATTER = re.compile(r'^(\.\.\. |Checking log|Press Ctrl-C|Done checking|started roslaunch|SUMMARY|=+|PARAMETERS|NODES'
                      r'| \* /|  /|    \S+ \(|auto-starting|setting /run_id|process\[|ROS_MASTER_URI|\[\S+\] killing'
                      r'|shutting down|done$|log file:|Initiating shutdown|all processes on machine|$)')
#: Lines kept of a log for the teacher (its last MAX_LOG_TEXT characters at most: one line may be long).
TAIL_LINES = 25


def tail(text, lines=TAIL_LINES):
    return '\n'.join(text.rstrip().splitlines()[-lines:])[-MAX_LOG_TEXT:]


def clean(output):
    """roslaunch's output without control characters (its colours and titles, a node's escape
    sequences) and without its own chatter: what the nodes printed, and roslaunch's words about them."""
    kept = []
    for line in clean_text(output).splitlines():
        if not _CHATTER.match(line.strip('=')) or 'process has' in line:
            kept.append(line.strip('=') if line.startswith('=') else line)
    return '\n'.join(kept)


def launch_outcome(output, workspace=None):
    """What roslaunch's output says about the student's nodes: ended ones and start failures.
    Paths inside ``workspace`` are shown relative to its src/ (``exam/scripts/...``)."""
    if workspace:
        output = output.replace(workspace.rstrip('/') + '/src/', '').replace(workspace.rstrip('/'), '<ws>')
    text = clean_text(output)
    ended, required = [], None
    for line in text.splitlines():
        match = _REQUIRED.search(line)
        if match:
            required = match.group(1)
        match = _ENDED.search(line)
        if match:
            ended.append({'node': match.group(1) or required or '?', 'how': match.group(2),
                          'detail': match.group(3) or ''})
    # A node respawned in a loop is reported ended as often: its first ends say it, room left for the
    # judge's own (the rubric counts them with these: score/runs.py).
    return {'ended': ended[:MAX_ENDED - WATCHED_DEATHS], 'not_started': [line[:500] for line in _NOT_STARTED.findall(text)[:50]],
            'tail': tail(clean(output))}


#: What the session tells the threshold run of its main run, in the threshold run's judge folder
#: (:class:`~exam_lab.grader.judge.probe.MainWord`): whether the node warned, how late.
MAIN_WORD = 'main-word.json'
#: The mark the session leaves there once the student's roslaunch has exited (a launch file it refuses
#: at once): the probe then waits no longer for a node that cannot come.
LAUNCH_ENDED = 'launch-ended-%s'


def capped_log(sup, name):
    """What a process of the box printed, its middle cut beyond twice LOG_PART (:func:`read_capped`):
    the orchestrator never reads more of what the student wrote."""
    return read_capped(sup.log(name)) or ''


def uid_of(pid):
    """The real uid of the living process ``pid``, or None."""
    try:
        with open('/proc/%d/status' % pid) as f:
            return int(next(line for line in f if line.startswith('Uid:')).split()[1])
    except (OSError, StopIteration, ValueError, IndexError):
        return None


#: Seconds of the budget a run keeps for its end (roslaunch's, the probe's and the master's grace
#: periods), a build or a check for its own (the kill at its limit, the box's end).
RUN_STOP_S = 30.0
STEP_STOP_S = 5.0
#: The least seconds a run is started with (the master's start, the node's registration).
MIN_RUN_S = 30.0


def budget_sentence(total, what):
    """The teacher's sentence for a grading that used up its budget of ``total`` s in ``what``."""
    return ('its grading used up its budget of %.0f s (the most one student\'s grading may take, inspection, '
            'build and runs together): %s' % (total, what))


class Budget(object):
    """What is left of the student's grading budget: ``seconds`` from the session's start (the runner's
    share of ``total``, the student's whole budget). Each step's limit is its own or what is left,
    whichever is less (:meth:`limit`); the first step the budget stopped or left out is :attr:`used`,
    the sentence the teacher reads."""

    def __init__(self, seconds, total, clock=time.monotonic):
        self.clock, self.total = clock, total
        self.deadline = clock() + seconds
        self.used = None

    def left(self, keep=0.0):
        """Seconds left once ``keep`` s are kept back for stopping the step."""
        return max(0.0, self.deadline - keep - self.clock())

    def limit(self, cap, keep):
        """``(limit, by_budget)``: the time limit of a step whose own limit is ``cap`` s."""
        left = self.left(keep)
        return (left, True) if left < cap else (cap, False)

    def spend(self, what):
        """Note that the budget ended ``what`` (the first such step is kept); returns the sentence."""
        sentence = budget_sentence(self.total, what)
        self.used = self.used or sentence
        return sentence


def run_one(sup, job, run, base_env, box, budget):
    """Start a master, the student's launch (in the box) and the probe; return the run's record: what
    happened (the probe's result as read, when it ran, whether its master ended), which the rubric
    judges (:func:`~exam_lab.grader.score.runs.judged_run`), never the session. The probe is waited
    for at most the run's limit or what is left of the ``budget``. The judge's folder is the run's own
    (``run.judge_home``) when it has one, else the job's; the threshold run's judge reads the main
    run's word there (:data:`MAIN_WORD`), once the session wrote it."""
    tag = run.tag
    log_dir, judge_dir = sup.log_dir, job.judge_home_of(run)
    reset_memory_peak(box.judge_cgroups.get('master', []))
    killed_before = (memory_use(box.judge_cgroups.get('master', [])) or {}).get('oom_kills', 0)
    master = sup.start_master(name='master-%s' % tag, wrap=box.judge_argv([], 'master'),
                              timeout=max(1.0, min(30.0, budget.left(RUN_STOP_S))))
    record = {'tag': tag, 'probe': None, 'master': {'uid': uid_of(master.proc.pid)}}
    launch_env = ros_env(base_env, master.uri, os.path.join(box.home, 'ros-%s' % tag), ip='127.0.0.1')
    launch = sup.start('launch-%s' % tag, box.argv(
        ['bash', '-c', 'source "$1/devel/setup.bash" && exec roslaunch --screen "$2"', 'bash',
         job.workspace, run.launch], launch_env))
    # The job as the session read it, for the judge to take its run's plan from, as it was made; the
    # plan in the log folder marks the flight's start for the progress and says what was flown.
    job_path = os.path.join(judge_dir, JobRecord.FILE)
    write_record(job_path, job)
    with open(os.path.join(log_dir, 'plan-%s.json' % tag), 'w') as f:
        json.dump(plain(run.plan), f, indent=1, sort_keys=True)
    result_path, ended = os.path.join(judge_dir, 'probe-%s.json' % tag), os.path.join(judge_dir, LAUNCH_ENDED % tag)
    word = [os.path.join(judge_dir, MAIN_WORD)] if tag == 'threshold' else []
    probe_env = ros_env(master.env, master.uri, os.path.join(judge_dir, 'ros-probe-%s' % tag), ip='127.0.0.1')
    probe_env['ROS_NAMESPACE'] = job.namespace or '/'
    started, started_wall = time.monotonic(), time.time()
    probe = sup.start('probe-%s' % tag, box.judge_argv(
        [sys.executable, '-m', 'exam_lab.grader.judge.probe', job_path, tag, result_path, ended] + word, 'probe'),
        probe_env)
    # The probe writes its result, then keeps the drone up: the student's node is stopped first, so
    # nothing it does when its drone goes away (a failed service call, a crash) is counted.
    limit, by_budget = budget.limit(job.run_timeout, RUN_STOP_S)

    def over():
        """The probe's result, or its end or its master's; roslaunch's exit told to the probe, which then
        waits no longer for a node that cannot come."""
        if launch.poll() is not None and not os.path.lexists(ended):
            open(ended, 'w').close()
        return os.path.isfile(result_path) or probe.poll() is not None or master.proc.poll() is not None
    wait_until(over, limit, period=0.1)
    record['seconds'] = time.monotonic() - started
    if by_budget and not os.path.isfile(result_path) and probe.poll() is None:
        record['budget'] = budget.spend('the %s run was stopped after %.0f s' % (tag, record['seconds']))
    record['probe_uid'] = uid_of(probe.pid)  # lingering: its uid is the one it measured as
    record['launch_running'] = launch.poll() is None
    master_died = master.proc.poll() is not None
    # Read before stopping: what the nodes print when the grader stops them is not their doing.
    record['launch'] = launch_outcome(capped_log(sup, 'launch-%s' % tag), job.workspace)
    sup.stop(launch)
    record['survivors'] = box.end()
    if os.path.lexists(result_path):
        record['probe'], why = probe_record(result_path)
        if why:
            record['probe_error'] = why
    record['probe_wall'] = [started_wall, time.time()]  # what the rubric judges its times by (score/runs.py)
    if record['probe'] is not None:
        with open(os.path.join(log_dir, 'probe-%s.json' % tag), 'w') as f:
            json.dump(record['probe'], f, indent=1, sort_keys=True)
    elif 'probe_error' not in record and record.get('budget'):
        record['probe_error'] = record['budget']
    elif 'probe_error' not in record:
        record['probe_error'] = ('no result within the run\'s time limit (%.0f s); ' % job.run_timeout
                                 if probe.poll() is None else
                                 'exit %s; ' % probe.poll()) + tail(sup.output('probe-%s' % tag), 15)
    record['probe_status'] = sup.stop(probe, grace=5.0)
    sup.stop(master.proc)
    record['master']['memory'] = memory_use(box.judge_cgroups.get('master', []))
    if record['master']['memory']:  # this run's kills: the slot's master cgroup serves every run
        record['master']['memory']['oom_kills'] -= killed_before
    record['master']['died'] = master_died
    return record


def probe_record(path):
    """``(value, None)``: the probe's result in ``path`` as a checked
    :class:`~exam_lab.grader.score.records.ProbeRecord`'s value (its text clean); ``(None, why)`` when
    it is not one (too large, not JSON, a key or value the probe never writes): the run's crash, said
    so, never data."""
    try:
        return read_record(path, ProbeRecord, ProbeRecord.MAX_BYTES).value, None
    except RecordError as err:
        return None, 'the probe\'s result was refused (a crash of the run): %s' % err


def judge_environment(judge_dir, box):
    """The judge's environment: the grader's, with a HOME and ROS folders of its own the box cannot
    see, in ``judge_dir``, made the judge's own (0700, its uid's), where it writes as its uid."""
    if box.judge_uid is not None:
        os.chown(judge_dir, box.judge_uid, box.judge_uid)
    os.chmod(judge_dir, 0o700)
    return dict(os.environ, ROS_IP='127.0.0.1', HOME=judge_dir, PYTHONNOUSERSITE='1',
                ROS_LOG_DIR=os.path.join(judge_dir, 'ros_log'), ROS_HOME=os.path.join(judge_dir, 'ros_home'))


def base_environment(job):
    """The box's environment before the student's setup is sourced: the underlay's."""
    return workspace_env(job.underlay, {'PATH': os.environ.get('PATH', '/usr/bin:/bin'), 'LANG': 'C.UTF-8'})

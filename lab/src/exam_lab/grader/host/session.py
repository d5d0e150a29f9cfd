"""One submission's session: build the student's workspace, run its node against the probe.

The runner starts this module as root, alone in a network namespace that has only loopback::

    python3 -m exam_lab.grader.host.session JOB.json

This orchestrator stays root (it starts the boxes, which drop root themselves) but parses no byte of the
student's: it reads roslaunch's output and the probe's JSON, both capped. The judge (a master per run,
the probe with its fake drone) runs as the slot's judge uid (:meth:`~exam_lab.grader.host.sandbox.Box.judge_argv`:
not root, not the box's uid), the master bounded in memory and both weighted above the box for CPU,
under a :class:`~exam_lab.harness.supervisor.Supervisor` whose log folder the student's code cannot see;
the judge's own folder (``judge_home``: ROS logs, plans, the probe's results) is the judge's, mode 0700.
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
student's whole grading: :class:`Budget`), ``judge_home`` (the judge's folder), ``runs``: the main run and, when the launch
file has a threshold the grader can change, the threshold run: each ``{"tag", "launch" (derived launch
file, as the box sees it), "plan" (for the probe)}``. Writes ``<log_dir>/session.json``: ``{"build":
{...}, "runs": [{"tag", "probe" (the probe's result or None), "probe_refused" (why a result was
refused), "master" (its memory, its uid), "probe_uid", "launch": {...}}], "survivors": n, "launch_check",
"budget_used" (the sentence when the budget stopped a step, else None), "outcome"}``: a
:class:`~exam_lab.grader.score.records.SessionRecord` (checked, every text in it made safe there), and
each probe's result as ``<log_dir>/probe-<tag>.json`` (its checked record; a result refused for its
times or the master is kept in the run as ``refused_probe``).
"""
import json
import os
import re
import sys
import time

from exam_lab.grader.host.cgroups import memory_use, reset_memory_peak
from exam_lab.grader.contract import read_capped, read_record
from exam_lab.grader.host.sandbox import Box
from exam_lab.grader.score.records import (
    MAX_ENDED, MAX_LOG_TEXT, JobRecord, Outcome, PlanRecord, ProbeRecord, RecordError, SessionRecord)
from exam_lab.grader.score.safe_text import clean as clean_text
from exam_lab.grader.score.sheets import request_meaning
from exam_lab.harness.supervisor import Supervisor, ros_env, workspace_env
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
    # A node respawned in a loop is reported ended as often: its first MAX_ENDED ends say it.
    return {'ended': ended[:MAX_ENDED - WATCHED_DEATHS], 'not_started': [line[:500] for line in _NOT_STARTED.findall(text)[:50]],
            'tail': tail(clean(output))}


#: The most deaths of one run the judge's watch reports.
WATCHED_DEATHS = 20


def watched_deaths(probe):
    """The deaths the probe's :class:`~exam_lab.grader.judge.graph.NodeWatch` saw (a node started again
    or gone during the run) in its record (a :class:`~exam_lab.grader.score.records.ProbeRecord`'s
    value: checked, its text clean), as entries of :func:`launch_outcome`'s ``ended``: they cost what a
    death in roslaunch's words costs, and they are the judge's own, whatever roslaunch's log kept."""
    return [{'node': d['node'][:100], 'how': 'died', 'detail': 'seen by the judge: %s' % d['detail'][:200]}
            for d in probe['node_watch']['deaths'][:WATCHED_DEATHS]]


def warned_in_long_excursion(probe):
    """True when the main run saw a WARNING call while the value was above the threshold for long."""
    schedule = (probe or {}).get('schedule') or {}
    if 'long_up' not in schedule:
        return False
    return any(request_meaning(status) == 'WARNING' and schedule['long_up'] <= t <= schedule['long_down']
               for t, status in probe.get('calls', []))


def clock_problem(clock):
    """Why a run whose probe saw ``clock`` (its ``ClockWatch``) is not the judge's to measure, or None:
    someone set ``/use_sim_time`` or published ``/clock`` (the node under test counting on a clock of
    its own making; the probe times on the wall clock regardless)."""
    if not isinstance(clock, dict):
        return 'the probe did not say whether /clock was published'
    said = []
    if any(clock.get('use_sim_time') or []):
        said.append('/use_sim_time was set on the master')
    if clock.get('messages') or clock.get('publishers'):
        said.append('/clock was published (%s messages%s)' % (
            clock.get('messages', 0),
            ' by %s' % ', '.join(map(str, clock['publishers'])) if clock.get('publishers') else ''))
    if said:
        return '%s: the grader times the node on the wall clock only; grade it by hand' % ' and '.join(said)
    return None


def probe_problem(result, started, finished, *, kind, delay):
    """Why the probe's ``result`` cannot be this run's measurement, or None: it has times, nobody set
    the time (:func:`clock_problem`), every time it records (wall clock) must lie between the probe's
    start and the result's arrival, and the flight must have lasted its schedule (in a ``kind``
    'main' run, the long excursion at least the rule's ``delay``)."""
    schedule = result.get('schedule') or {}
    times = [t for t in [result.get('t0')] + list(schedule.values()) if isinstance(t, (int, float))]
    if not times:
        return 'the probe\'s result has no times'
    problem = clock_problem(result.get('clock'))
    if problem:
        return problem
    if min(times) < started - 1.0 or max(times) > finished + 1.0:
        return 'the probe\'s times (%.1f to %.1f) are not within its run (%.1f to %.1f)' % (
            min(times), max(times), started, finished)
    if kind == 'main' and 'long_up' in schedule and 'long_down' in schedule \
            and schedule['long_down'] - schedule['long_up'] < delay:
        return 'the long excursion lasted %.1f s, less than the %.1f s delay' % (
            schedule['long_down'] - schedule['long_up'], delay)
    return None


def warning_latency(probe):
    """Seconds from the long excursion's start to the main run's first WARNING in it, or None."""
    schedule = (probe or {}).get('schedule') or {}
    times = [t for t, status in (probe or {}).get('calls', []) if request_meaning(status) == 'WARNING'
             and schedule.get('long_up', float('inf')) <= t <= schedule.get('long_down', 0.0)]
    return min(times) - schedule['long_up'] if times else None


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


def master_problem(master, died):
    """Why a run whose master ended early (``died``) or hit its memory bound (``master``: the cgroup's
    :func:`~exam_lab.grader.host.cgroups.memory_use`) is not one to score, or None."""
    memory = master.get('memory') or {}
    if memory.get('oom_kills'):
        return ('the master the node talks to went over its memory bound of %d MB (%d process(es) killed): '
                'the node\'s parameters or messages filled it' % ((memory.get('limit') or 0) >> 20, memory['oom_kills']))
    if died:
        return 'the master the node talks to ended during the run'
    return None


def run_one(sup, job, run, base_env, box, budget):
    """Start a master, the student's launch (in the box) and the probe; return the run's record. The
    probe is waited for at most the run's limit or what is left of the ``budget``."""
    tag = run['tag']
    log_dir, judge_dir = sup.log_dir, job.judge_home
    reset_memory_peak(box.judge_cgroups.get('master', []))
    killed_before = (memory_use(box.judge_cgroups.get('master', [])) or {}).get('oom_kills', 0)
    master = sup.start_master(name='master-%s' % tag, wrap=box.judge_argv([], 'master'),
                              timeout=max(1.0, min(30.0, budget.left(RUN_STOP_S))))
    record = {'tag': tag, 'probe': None, 'master': {'uid': uid_of(master.proc.pid)}}
    launch_env = ros_env(base_env, master.uri, os.path.join(box.home, 'ros-%s' % tag), ip='127.0.0.1')
    launch = sup.start('launch-%s' % tag, box.argv(
        ['bash', '-c', 'source "$1/devel/setup.bash" && exec roslaunch --screen "$2"', 'bash',
         job.workspace, run['launch']], launch_env))
    plan_path = os.path.join(judge_dir, 'plan-%s.json' % tag)
    result_path = os.path.join(judge_dir, 'probe-%s.json' % tag)
    plan = PlanRecord.make(run['plan'])
    for path in (plan_path, os.path.join(log_dir, 'plan-%s.json' % tag)):  # the judge's, and the progress's
        with open(path, 'w') as f:
            f.write(plan.to_json())
    probe_env = ros_env(master.env, master.uri, os.path.join(judge_dir, 'ros-probe-%s' % tag), ip='127.0.0.1')
    probe_env['ROS_NAMESPACE'] = job.namespace or '/'
    started, started_wall = time.monotonic(), time.time()
    probe = sup.start('probe-%s' % tag, box.judge_argv(
        [sys.executable, '-m', 'exam_lab.grader.judge.probe', plan_path, result_path], 'probe'), probe_env)
    # The probe writes its result, then keeps the drone up: the student's node is stopped first, so
    # nothing it does when its drone goes away (a failed service call, a crash) is counted.
    limit, by_budget = budget.limit(job.run_timeout, RUN_STOP_S)
    wait_until(lambda: os.path.isfile(result_path) or probe.poll() is not None or master.proc.poll() is not None,
               limit, period=0.1)
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
    if record['probe'] is not None:
        record['launch']['ended'].extend(watched_deaths(record['probe']))  # whether or not the run is refused
        with open(os.path.join(log_dir, 'probe-%s.json' % tag), 'w') as f:
            json.dump(record['probe'], f, indent=1, sort_keys=True)
        problem = probe_problem(record['probe'], started_wall, time.time(), kind=plan.kind, delay=plan.delay)
        if problem:
            refuse(record, problem)
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
    problem = master_problem(record['master'], master_died)
    if problem:
        refuse(record, problem)
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


def refuse(record, problem):
    """A run's result that is not its measurement (``problem``: why): the rubric sees no probe; the
    result stays in the record as ``refused_probe`` (the teacher's flight plot draws it)."""
    if record['probe'] is not None:
        record['refused_probe'] = record['probe']
    record['probe'], record['probe_refused'] = None, problem
    record['probe_error'] = 'result refused: %s' % problem


def session(job):
    """Check, build and run one submission (the module's docstring); returns the value of its
    :class:`~exam_lab.grader.score.records.SessionRecord`."""
    result = {'outcome': Outcome.RAN, 'build': None, 'runs': [], 'survivors': 0}
    box = Box.attached(job.box)
    # The judge keeps the grader's environment, with a HOME and ROS folders of its own the box cannot
    # see; its folder is its own (0700), where it writes as its uid.
    judge_dir = job.judge_home
    if box.judge_uid is not None:
        os.chown(judge_dir, box.judge_uid, box.judge_uid)
    os.chmod(judge_dir, 0o700)
    judge_env = dict(os.environ, ROS_IP='127.0.0.1', HOME=judge_dir, PYTHONNOUSERSITE='1',
                     ROS_LOG_DIR=os.path.join(judge_dir, 'ros_log'), ROS_HOME=os.path.join(judge_dir, 'ros_home'))
    budget = Budget(job.budget, job.student_budget)
    with Supervisor(job.log_dir, env=judge_env) as sup:
        base_env = workspace_env(job.underlay, {'PATH': os.environ.get('PATH', '/usr/bin:/bin'),
                                                   'LANG': 'C.UTF-8'})
        # roslaunch's verdict first: nothing of the student's has run yet (no build, no environment hook).
        limit, by_budget = budget.limit(LAUNCH_CHECK_TIMEOUT, STEP_STOP_S)
        result['launch_check'] = launch_verdict(sup, box, base_env, workspace=job.workspace,
                                                handed_in_launch=job.handed_in_launch, timeout=limit)
        result['survivors'] += box.end()
        if by_budget and (result['launch_check'] or {}).get('status', 0) is None:
            result['budget_used'] = result['error'] = budget.spend(
                'roslaunch\'s check of the launch file was stopped after %.0f s' % limit)
            result['outcome'] = Outcome.CHECK_STOPPED
            return result
        limit, by_budget = budget.limit(job.build_timeout, STEP_STOP_S)
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
        for run in job.runs:
            if run['tag'] == 'threshold':
                main = result['runs'][0]['probe'] if result['runs'] else None
                if not warned_in_long_excursion(main):
                    result['threshold_skipped'] = 'the node never warned in the main run'
                    break
                run = dict(run, plan=dict(run['plan'], warn_after=warning_latency(main)))
            if budget.left(RUN_STOP_S) < MIN_RUN_S:
                budget.spend('the %s run was not started (%.0f s left)' % (run['tag'], budget.left()))
                break
            result['runs'].append(run_one(sup, job, run, base_env, box, budget))
            result['survivors'] += result['runs'][-1]['survivors']
        result['budget_used'] = budget.used
    return result


def main(argv):
    if len(argv) != 1:
        sys.stderr.write('usage: python3 -m exam_lab.grader.host.session JOB.json\n')
        return 2
    try:
        job = JobRecord.read(argv[0])
    except RecordError as err:  # the grader's own bug, as below
        sys.stderr.write('the job is not one: %s\n' % err)
        return 1
    try:
        record = SessionRecord.make(session(job))
    except RecordError as err:  # the grader's own bug: the runner says the session failed, and why
        sys.stderr.write('the session\'s record is not one: %s\n' % err)
        return 1
    with open(os.path.join(job.log_dir, SessionRecord.FILE + '.part'), 'w') as f:
        f.write(record.to_json())
    os.rename(os.path.join(job.log_dir, SessionRecord.FILE + '.part'), os.path.join(job.log_dir, SessionRecord.FILE))
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

"""One submission's session: build the student's workspace, run its node against the probe.

Everything the student's code runs happens here, under one :class:`~exam_lab.harness.supervisor.
Supervisor` (its own log folder; every process it started, and every process that inherited its
marker, is ended on exit). The runner starts this module inside a network namespace that has only
loopback when the machine allows it::

    python3 -m exam_lab.grader.session JOB.json

Job (JSON, written by :mod:`exam_lab.grader.runner`): ``workspace`` (a catkin workspace whose src/
holds the student's package), ``underlay`` (setup.bash of the simulators' workspace), ``log_dir``,
``namespace`` (the drone's), ``build_timeout`` / ``run_timeout`` (s), ``runs``: the main run and,
when the launch file has a threshold the grader can change, the threshold run: each ``{"tag",
"launch" (derived launch file), "plan" (for the probe)}``. Writes ``<log_dir>/session.json``:
``{"build": {...}, "runs": [{"tag", "probe" (the probe's result or None), "launch": {...}}]}``.
"""
import json
import os
import re
import sys
import time

from exam_lab.harness.supervisor import Supervisor, ros_env, workspace_env
from exam_lab.harness.wait import wait_until

#: Terminal colour and title sequences roslaunch writes even into a file.
_ANSI = re.compile(r'\x1b\[[0-9;]*m|\x1b?\]2;[^\n\x07]*\x07?')
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
#: Lines kept of a log for the teacher.
TAIL_LINES = 25


def tail(text, lines=TAIL_LINES):
    return '\n'.join(text.rstrip().splitlines()[-lines:])


def clean(output):
    """roslaunch's output without colours and without its own chatter: what the nodes printed, and
    roslaunch's words about them."""
    kept = []
    for line in _ANSI.sub('', output).splitlines():
        if not _CHATTER.match(line.strip('=')) or 'process has' in line:
            kept.append(line.strip('=') if line.startswith('=') else line)
    return '\n'.join(kept)


def launch_outcome(output, workspace=None):
    """What roslaunch's output says about the student's nodes: ended ones and start failures.
    Paths inside ``workspace`` are shown relative to its src/ (``exam/scripts/...``)."""
    if workspace:
        output = output.replace(workspace.rstrip('/') + '/src/', '').replace(workspace.rstrip('/'), '<ws>')
    text = _ANSI.sub('', output)
    ended, required = [], None
    for line in text.splitlines():
        match = _REQUIRED.search(line)
        if match:
            required = match.group(1)
        match = _ENDED.search(line)
        if match:
            ended.append({'node': match.group(1) or required or '?', 'how': match.group(2),
                          'detail': match.group(3) or ''})
    return {'ended': ended, 'not_started': _NOT_STARTED.findall(text), 'tail': tail(clean(output))}


def warned_in_long_excursion(probe):
    """True when the main run saw a WARNING call while the value was above the threshold for long."""
    schedule = (probe or {}).get('schedule') or {}
    if 'long_up' not in schedule:
        return False
    return any(status == 'WARNING' and schedule['long_up'] <= t <= schedule['long_down']
               for t, status in probe.get('calls', []))


def warning_latency(probe):
    """Seconds from the long excursion's start to the main run's first WARNING in it, or None."""
    schedule = (probe or {}).get('schedule') or {}
    times = [t for t, status in (probe or {}).get('calls', []) if status == 'WARNING'
             and schedule.get('long_up', float('inf')) <= t <= schedule.get('long_down', 0.0)]
    return min(times) - schedule['long_up'] if times else None


def run_one(sup, job, run, node_env):
    """Start a master, the student's launch and the probe; return the run's record."""
    tag = run['tag']
    log_dir = sup.log_dir
    master = sup.start_master(name='master-%s' % tag)
    launch_env = ros_env(node_env, master.uri, os.path.join(log_dir, 'ros-%s' % tag), ip='127.0.0.1')
    launch = sup.start('launch-%s' % tag, ['roslaunch', '--screen', run['launch']], launch_env,
                       cwd=job['workspace'])
    plan_path = os.path.join(log_dir, 'plan-%s.json' % tag)
    result_path = os.path.join(log_dir, 'probe-%s.json' % tag)
    with open(plan_path, 'w') as f:
        json.dump(run['plan'], f, indent=1, sort_keys=True)
    probe_env = ros_env(master.env, master.uri, os.path.join(log_dir, 'ros-probe-%s' % tag), ip='127.0.0.1')
    probe_env['ROS_NAMESPACE'] = job.get('namespace', '/')
    started = time.monotonic()
    probe = sup.start('probe-%s' % tag, [sys.executable, '-m', 'exam_lab.grader.probe', plan_path, result_path],
                      probe_env)
    # The probe writes its result, then keeps the drone up: the student's node is stopped first, so
    # nothing it does when its drone goes away (a failed service call, a crash) is counted.
    wait_until(lambda: os.path.isfile(result_path) or probe.poll() is not None, job['run_timeout'], period=0.1)
    seconds = time.monotonic() - started
    record = {'tag': tag, 'probe': None, 'seconds': seconds}
    record['launch_running'] = launch.poll() is None
    # Read before stopping: what the nodes print when the grader stops them is not their doing.
    record['launch'] = launch_outcome(sup.output('launch-%s' % tag), job['workspace'])
    sup.stop(launch)
    if os.path.isfile(result_path):
        with open(result_path) as f:
            record['probe'] = json.load(f)
    else:
        record['probe_error'] = ('no result within %.0f s; ' % job['run_timeout'] if probe.poll() is None else
                                 'exit %s; ' % probe.poll()) + tail(sup.output('probe-%s' % tag), 15)
    record['probe_status'] = sup.stop(probe, grace=5.0)
    sup.stop(master.proc)
    return record


def session(job):
    result = {'build': None, 'runs': []}
    with Supervisor(job['log_dir'], env=dict(os.environ, ROS_IP='127.0.0.1')) as sup:
        build_env = workspace_env(job['underlay'], sup.env)
        status, output, seconds = sup.run(
            'build', ['catkin_make', '--directory', job['workspace'], '-DPYTHON_EXECUTABLE=/usr/bin/python3',
                      '-DCATKIN_ENABLE_TESTING=OFF'],
            timeout=job['build_timeout'], env=build_env, cwd=job['workspace'])
        result['build'] = {'status': status, 'seconds': seconds, 'tail': tail(output),
                           'timeout': job['build_timeout']}
        if status != 0:
            return result
        node_env = workspace_env(os.path.join(job['workspace'], 'devel', 'setup.bash'), sup.env)
        for run in job['runs']:
            if run['tag'] == 'threshold':
                main = result['runs'][0]['probe'] if result['runs'] else None
                if not warned_in_long_excursion(main):
                    result['threshold_skipped'] = 'the node never warned in the main run'
                    break
                run = dict(run, plan=dict(run['plan'], fit=main['calibration'].get('fit'),
                                          warn_after=warning_latency(main)))
            result['runs'].append(run_one(sup, job, run, node_env))
    return result


def main(argv):
    if len(argv) != 1:
        sys.stderr.write('usage: python3 -m exam_lab.grader.session JOB.json\n')
        return 2
    with open(argv[0]) as f:
        job = json.load(f)
    result = session(job)
    with open(os.path.join(job['log_dir'], 'session.json'), 'w') as f:
        json.dump(result, f, indent=1, sort_keys=True)
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

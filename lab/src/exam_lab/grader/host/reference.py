"""The reference outputs of the report's questions 4-9: the project's own drone run, its outputs captured.

A student's report pastes what ``rosnode list``, ``rosnode info``, ``rostopic list`` / ``type``,
``rosmsg info``, ``rostopic echo`` and ``hz`` and ``catkin_create_pkg`` printed for the drone of their
sheet. The checks of :mod:`exam_lab.grader.score.answers` compare those pastes with what the same drone
prints here, never with text typed into the grader: this module starts a master and the sheet's drone
(``mydrone`` or ``submarinedrone`` of the simulators' underlay) alone in a network namespace that has
only loopback (:func:`~exam_lab.grader.host.bwrap.network_namespace`, as the sessions run), runs each
command as a student would (:data:`COMMANDS`), and writes one
:class:`~exam_lab.grader.score.reference.ReferenceRecord`. The rates the drone is configured with are
read from its own spec (``<drone>.simulator.SPEC``), next to the rates ``rostopic hz`` measured.

It runs the project's code only, none of a student's. The record is kept next to the underlay, under
the digest of the simulators' sources (``reference-<sheet>-<digest>.json``: a class run on unchanged
drones reuses it), and a copy in OUT (``reference-<sheet>.json``), which ``make rescore`` reads again::

    python3 -m exam_lab.grader.host.reference --sheet altitude --underlay SETUP.bash --out FILE.json
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

from exam_lab.grader import contract
from exam_lab.grader.host.bwrap import can_isolate, network_namespace
from exam_lab.grader.score.reference import ReferenceRecord, reference_file
from exam_lab.grader.score.records import RecordError
from exam_lab.grader.score.sheets import SHEETS
from exam_lab.harness.supervisor import DIES_WITH_PARENT, Supervisor, end_pids, marked, ros_env, workspace_env
from exam_lab.harness.wait import wait_until

#: Seconds ``rostopic hz`` listens (the slowest sensor, 0.778 Hz, gives four periods in 6 s).
HZ_SECONDS = 6
#: Seconds one command may take at most (a safety net: every command ends by itself).
COMMAND_LIMIT = 30.0
#: Seconds the drone may take to publish its first reading.
START_TIMEOUT = 30.0
#: Seconds the whole capture may take (the namespace's process is killed past it).
CAPTURE_TIMEOUT = 180.0

#: Printed by the underlay's python3: the drone's node name and each sensor's configured rate (Hz).
_SPEC = '''
import importlib, json, sys
spec = importlib.import_module(sys.argv[1] + '.simulator').SPEC
print(json.dumps({'node': spec.node_name, 'rates': {s.topic: s.default_rate for s in spec.sensors}}))
'''


def commands(sheet, node):
    """``[(key, argv)]``: the commands of the report's questions 4-8 for the ``sheet``'s drone ``node``
    (its name, ``/mydrone``). Question 9's ``catkin_create_pkg`` runs apart, in a scratch folder."""
    first, second = ['/' + topic for topic in SHEETS[sheet].inputs]
    return [('rosnode_list', ['rosnode', 'list']),
            ('rosnode_info', ['rosnode', 'info', node]),
            ('rostopic_list', ['rostopic', 'list']),
            ('rostopic_type', ['rostopic', 'type', first]),
            ('rosmsg_info', ['rosmsg', 'info', 'std_msgs/Float32']),
            ('rostopic_echo', ['rostopic', 'echo', '-n', '3', first]),
            ('rostopic_hz', ['timeout', '-s', 'INT', str(HZ_SECONDS), 'rostopic', 'hz', first]),
            ('rostopic_hz_other', ['timeout', '-s', 'INT', str(HZ_SECONDS), 'rostopic', 'hz', second])]


def capture(sheet, underlay, scratch):
    """The record's value (:class:`~exam_lab.grader.score.reference.ReferenceRecord`) of the ``sheet``'s
    drone run on the ``underlay`` (its setup.bash), its logs and scratch folders in ``scratch``. Run in
    a network namespace of its own (:func:`main`): the master's port is then free by construction."""
    drone = SHEETS[sheet].drone_pkg
    env = workspace_env(underlay, {'PATH': os.environ.get('PATH', '/usr/bin:/bin'), 'LANG': 'C.UTF-8',
                                   'HOME': scratch})
    spec = json.loads(subprocess.run(['/usr/bin/python3', '-c', _SPEC, drone], env=env, stdout=subprocess.PIPE,
                                     check=True, timeout=60).stdout.decode())
    node = '/' + spec['node']
    first = '/' + SHEETS[sheet].inputs[0]
    outputs = {}
    with Supervisor(os.path.join(scratch, 'logs'), env=env) as sup:
        master = sup.start_master(timeout=START_TIMEOUT)
        run_env = ros_env(env, master.uri, os.path.join(scratch, 'ros'), ip='127.0.0.1')
        proc = sup.start('drone', ['rosrun', drone, SHEETS[sheet].drone_type], run_env)
        if not wait_until(lambda: bool(master.publishers(first)), START_TIMEOUT, alive=lambda: proc.poll() is None):
            raise RuntimeError('%s did not publish %s within %.0f s: %s' % (drone, first, START_TIMEOUT,
                                                                           sup.output('drone')[-2000:]))
        for key, argv in commands(sheet, node):
            status, output, _ = sup.run(key, argv, COMMAND_LIMIT, run_env, scratch)
            outputs[key] = {'line': ' '.join(argv[4:] if argv[0] == 'timeout' else argv),
                            'output': output.rstrip()[-8000:], 'status': status}
        sup.stop(proc)
        sup.stop(master.proc)
    folder = os.path.join(scratch, 'create_pkg')
    os.makedirs(folder)
    argv = ['catkin_create_pkg', 'exam', 'rospy', 'std_msgs', drone]
    done = subprocess.run(argv, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          timeout=COMMAND_LIMIT)
    outputs['catkin_create_pkg'] = {'line': ' '.join(argv), 'status': done.returncode,
                                    'output': done.stdout.decode('utf-8', 'replace').rstrip()[-8000:]}
    created = sorted(os.path.relpath(os.path.join(d, f), folder) for d, _, files in os.walk(folder) for f in files)
    return {'version': 1, 'sheet': sheet, 'drone': drone, 'node': node, 'topic': first,
            'other_topic': '/' + SHEETS[sheet].inputs[1], 'rates': spec['rates'],
            'commands': outputs, 'created': created}


def ensure(sheet, underlay, out=None, timeout=CAPTURE_TIMEOUT):
    """The :class:`~exam_lab.grader.score.reference.ReferenceRecord` of the ``sheet``'s drone on the
    ``underlay``: the one kept beside the underlay for its sources' digest, else captured now (in a
    network namespace when one can be made, :func:`~exam_lab.grader.host.bwrap.can_isolate`); copied to
    ``out/reference-<sheet>.json`` when ``out`` is given. Raises RuntimeError when the drone cannot be
    run (the proposals then say the outputs were not checked)."""
    cache_dir = os.path.dirname(os.path.dirname(underlay))
    with open(os.path.join(cache_dir, 'sources.sha256')) as f:
        digest = f.read().strip()[:16]
    cached = os.path.join(cache_dir, 'reference-%s-%s.json' % (sheet, digest))
    try:
        record = contract.read_record(cached, ReferenceRecord)
    except RecordError:
        record = None
    if record is None:
        record = captured(sheet, underlay, timeout)
        contract.write_record(cached, record)
    if out:
        contract.write_record(os.path.join(out, reference_file(sheet)), record)
    return record


def captured(sheet, underlay, timeout=CAPTURE_TIMEOUT):
    """The :class:`~exam_lab.grader.score.reference.ReferenceRecord` of the ``sheet``'s drone captured
    now (:func:`capture` in a network namespace of its own when one can be made), read back checked."""
    scratch = tempfile.mkdtemp(prefix='exam-reference-')
    try:
        target = os.path.join(scratch, 'reference.json')
        argv = [sys.executable, '-m', 'exam_lab.grader.host.reference', '--sheet', sheet, '--underlay', underlay,
                '--out', target, '--scratch', scratch]
        try:
            done = subprocess.run(DIES_WITH_PARENT + (network_namespace(argv) if can_isolate() else argv),
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout)
        except subprocess.TimeoutExpired:
            raise RuntimeError('capturing the reference outputs of %s took more than %.0f s'
                               % (SHEETS[sheet].drone_pkg, timeout))
        if done.returncode != 0:
            raise RuntimeError('the reference outputs of %s could not be captured: %s' % (
                SHEETS[sheet].drone_pkg, done.stdout.decode('utf-8', 'replace')[-2000:]))
        return contract.read_record(target, ReferenceRecord)
    finally:
        end_pids(marked(os.path.join(scratch, 'logs')))  # a capture stopped at its limit leaves no master behind
        shutil.rmtree(scratch, ignore_errors=True)


def keep_for(out, sheets, underlay=None):
    """The reference of each of ``sheets`` kept in ``out`` (:func:`ensure`, the underlay built if
    needed); returns lines for the terminal: a drone that cannot be run is said, and its students'
    answers are then proposed "to check", never compared with text of the grader's."""
    from exam_lab.grader.host.underlay import default_underlay, ensure_underlay
    lines = []
    for sheet in sorted(set(sheets)):
        try:
            record = ensure(sheet, underlay or ensure_underlay(default_underlay()), out)
            lines.append('reference outputs of %s: %s (%s)' % (record.drone, os.path.join(out, reference_file(sheet)),
                                                              ', '.join(sorted(record.commands))))
        except (RuntimeError, OSError, subprocess.SubprocessError, RecordError) as err:
            lines.append('reference outputs of sheet %s NOT captured: %s' % (sheet, ' '.join(str(err).split())[:500]))
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--sheet', required=True, choices=sorted(SHEETS))
    parser.add_argument('--underlay', required=True, help="the simulators' setup.bash")
    parser.add_argument('--out', required=True)
    parser.add_argument('--scratch', required=True, help='a folder for the logs and question 9\'s package')
    args = parser.parse_args(argv)
    record = ReferenceRecord.make(capture(args.sheet, args.underlay, args.scratch))
    contract.write_record(args.out, record)
    return 0


if __name__ == '__main__':
    sys.exit(main())

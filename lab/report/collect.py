#!/usr/bin/env python3
"""Brings the system up and runs every command of docs/report.md; writes outputs.json and the bags.

Usage: collect.py --work DIR --run-dir DIR [--run-seconds S]

The order follows the exam sheets:

1. ``catkin_make`` in a scratch workspace as a student has it (question 1): src/ links to the drones'
   packages (and drone_sim and node_kit, which they share) and to the simple answer, docs/simple_answer/exam, with
   no workspace of ours on CMAKE_PREFIX_PATH.
2. A master; ``rosrun mydrone mydrone_node.py`` alone; questions 4 to 8, the warning service by hand,
   and question 10's first step (a node that only logs what it receives).
3. ``catkin_create_pkg`` of each sheet in a scratch folder (question 9); a launch with a bad threshold
   (question 12).
4. The full default flight: ``rosbag record`` then ``roslaunch exam exam.launch`` for one profile loop;
   meanwhile the commands of questions 10 to 14. At the same time, on a second master, the same flight
   with ``threshold:=1200 delay:=3`` (question 14), and on a third the simple answer's launch, in
   question 1's workspace; both recorded too.
5. The same for the underwater drone on a fresh master: questions 4 to 8 and 10's first step, then one
   full dive, with the simple answer's dive beside it on a master of its own.

Everything is bounded in time, and every process started is ended on the way out: the harness's
supervisor runs them all, with their consoles in ``--run-dir`` (report.sh's trap ends them by that
folder should this process die). The outputs (with PIDs and ports of this run) go to
``<work>/outputs.json``; render.py fills the report.
"""
import argparse
import glob
import json
import os
import shlex
import sys
import time

from exam_lab.harness.supervisor import Supervisor, workspace_env
from exam_lab.harness.wait import wait_until

import command_list

#: The packages of question 1's workspace, as a student has them: the drones and their exam package.
STUDENT_PACKAGES = ['node_kit', 'drone_sim', 'mydrone', 'submarinedrone', 'docs/simple_answer/exam']
#: Seconds of one recorded run: the default profiles loop in 100 s; the rest is start-up margin.
DEFAULT_RUN_SECONDS = 106.0


def log(message):
    print('report: %s' % message, flush=True)


class Run(object):
    """The report's commands on the harness's supervisor: each runs from the work folder, and its
    output is collected under its key in :attr:`results` (written to outputs.json)."""

    def __init__(self, supervisor, work_dir):
        self.supervisor = supervisor
        self.work_dir = work_dir
        #: command key -> {'line', 'output', 'status', 'seconds'} or, for a background command,
        #: {'line', 'console', 'output' once it stopped, 'started' for a launch}.
        self.results = {}

    def run_all(self, env, commands, cwd=None):
        """Run each command to completion (bounded by its limit) in ``env`` and keep its output."""
        for command in commands:
            status, output, seconds = self.supervisor.run(command.key, shlex.split(command.line),
                                                          command.limit, env, cwd or self.work_dir)
            if status is None:
                status = 'killed after %d s' % command.limit
            self.results[command.key] = {'line': command.line, 'output': output.rstrip(),
                                         'status': status, 'seconds': round(seconds, 1)}
            log('%-40s exit %s, %.1f s' % (command.line[:40], status, seconds))

    def background(self, master, command):
        """Start a background command and note its line (its console is read after it stops)."""
        self.results[command.key] = {'line': command.line, 'console': self.supervisor.log(command.key)}
        return self.supervisor.start(command.key, shlex.split(command.line), master.env, self.work_dir)

    def stop(self, procs, commands):
        """Stop background commands, in this order (Ctrl-C, as a user would), and keep their consoles."""
        for proc in procs:
            self.supervisor.stop(proc)
        for command in commands:
            self.results[command.key]['output'] = self.supervisor.output(command.key).rstrip()


def wait_for(what, condition, proc, timeout=30.0):
    """Wait until ``condition()`` is true; raise if ``proc`` exits or ``timeout`` s pass first."""
    if not wait_until(lambda: bool(condition()), timeout, alive=lambda: proc.poll() is None):
        raise RuntimeError('%s not there after %.0f s (process exit status %s)'
                           % (what, timeout, proc.poll()))


def node_alone(run, master, node_command, sensor_topic, commands):
    """Questions 3 to 8: one drone node on its own, explored with the command-line tools."""
    node = run.background(master, node_command)
    wait_for(sensor_topic + ' published', lambda: master.publishers(sensor_topic), node)
    run.run_all(master.env, commands)
    run.stop([node], [node_command])


def recorded_run(run, master, record, launch, output_topic, bag_topic):
    """Start ``rosbag record`` (subscribed before anything is published), then the launch file."""
    bag = run.background(master, record)
    wait_for('rosbag subscribed to ' + bag_topic, lambda: master.subscribers(bag_topic), bag)
    started = time.time()
    proc = run.background(master, launch)
    # Wall clock as the bag's stamps: the figures count time from this instant.
    run.results[launch.key]['started'] = started
    wait_for(output_topic + ' published', lambda: master.publishers(output_topic), proc)
    return bag, proc, started


def catkin_make(run):
    """Question 1: build a student's workspace (the drones and the simple answer) in a fresh folder.

    :returns: that workspace's environment (its devel/setup.bash sourced), to run the simple answer in.
    """
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
    workspace = os.path.join(run.supervisor.log_dir, 'catkin_ws')
    os.makedirs(os.path.join(workspace, 'src'))
    for package in STUDENT_PACKAGES:
        os.symlink(os.path.join(repo, package), os.path.join(workspace, 'src', os.path.basename(package)))
    # As in a student's first build from a shell: no workspace of ours as an underlay, and none of the
    # variables `make report` hands its children (make would print every directory it enters).
    # catkin_make takes the workspace from PWD, which a shell's cd would set.
    env = {name: value for name, value in run.supervisor.env.items()
           if name not in ('CMAKE_PREFIX_PATH', 'MAKEFLAGS', 'MFLAGS', 'MAKELEVEL')}
    env['PWD'] = workspace
    run.run_all(env, [command_list.CATKIN_MAKE], cwd=workspace)
    return workspace_env(os.path.join(workspace, 'devel', 'setup.bash'), base=run.supervisor.env)


def student_master(run, name, student_env):
    """A master whose commands run in the student's workspace (its ``exam`` is the simple answer)."""
    master = run.supervisor.start_master(name)
    master.env = dict(student_env, ROS_MASTER_URI=master.uri)
    return master


def flight(run, run_seconds, student_env):
    master = run.supervisor.start_master('flight.master')
    log('mydrone alone on %s' % master.uri)
    node_alone(run, master, command_list.MYDRONE_NODE, '/temperature', command_list.MYDRONE_ALONE)

    for create_pkg in (command_list.CREATE_PKG, command_list.CREATE_PKG_SUBMARINE):
        scratch = os.path.join(run.supervisor.log_dir, create_pkg.key)
        os.makedirs(scratch)
        run.run_all(master.env, [create_pkg], cwd=scratch)
        for name, key in (('package.xml', 'package_xml'), ('CMakeLists.txt', 'cmakelists')):
            with open(os.path.join(scratch, 'exam', name)) as f:
                run.results[create_pkg.key][key] = f.read()
    # No drone runs on this master now: the bad launch starts both nodes, and roslaunch ends it.
    run.run_all(master.env, [command_list.BAD_LAUNCH])

    custom = run.supervisor.start_master('custom.master')
    log('default flight on %s, threshold 1200 and delay 3 on %s, %.0f s'
        % (master.uri, custom.uri, run_seconds))
    bag, launch, started = recorded_run(run, master, command_list.FLIGHT_RECORD,
                                        command_list.FLIGHT_LAUNCH, '/altitude', '/alt_warn_led')
    custom_bag, custom_launch, _ = recorded_run(run, custom, command_list.CUSTOM_RECORD,
                                                command_list.CUSTOM_LAUNCH, '/altitude', '/alt_warn_led')
    simple = student_master(run, 'simple.master', student_env)
    simple_bag, simple_launch, _ = recorded_run(run, simple, command_list.SIMPLE_RECORD,
                                                command_list.SIMPLE_LAUNCH, '/altitude', '/alt_warn_led')
    run.run_all(master.env, command_list.FLIGHT_LIVE)
    run.run_all(custom.env, command_list.CUSTOM_LIVE)
    run.run_all(simple.env, command_list.SIMPLE_LIVE)
    time.sleep(max(0.0, started + run_seconds - time.time()))
    # The bags first, so they end on the running system rather than on its shutdown.
    run.stop([bag, custom_bag, simple_bag, launch, custom_launch, simple_launch],
             [command_list.FLIGHT_RECORD, command_list.FLIGHT_LAUNCH, command_list.CUSTOM_RECORD,
              command_list.CUSTOM_LAUNCH, command_list.SIMPLE_RECORD, command_list.SIMPLE_LAUNCH])
    for one in (simple, custom, master):
        run.supervisor.stop(one.proc)


def dive(run, run_seconds, student_env):
    master = run.supervisor.start_master('dive.master')
    log('submarine_drone alone on %s' % master.uri)
    node_alone(run, master, command_list.SUBMARINE_NODE, '/pressure_robot',
               command_list.SUBMARINE_ALONE)
    log('default dive on %s, %.0f s' % (master.uri, run_seconds))
    bag, launch, started = recorded_run(run, master, command_list.DIVE_RECORD,
                                        command_list.DIVE_LAUNCH, '/depth', '/depth_warn_led')
    simple = student_master(run, 'simple_dive.master', student_env)
    simple_bag, simple_launch, _ = recorded_run(run, simple, command_list.SIMPLE_DIVE_RECORD,
                                                command_list.SIMPLE_DIVE_LAUNCH, '/depth', '/depth_warn_led')
    run.run_all(master.env, command_list.DIVE_LIVE)
    time.sleep(max(0.0, started + run_seconds - time.time()))
    run.stop([bag, simple_bag, launch, simple_launch],
             [command_list.DIVE_RECORD, command_list.SIMPLE_DIVE_RECORD, command_list.DIVE_LAUNCH,
              command_list.SIMPLE_DIVE_LAUNCH])
    run.supervisor.stop(simple.proc)
    run.supervisor.stop(master.proc)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--work', required=True, help='folder for the bags and outputs.json')
    parser.add_argument('--run-dir', required=True, help='private scratch folder of this run')
    parser.add_argument('--run-seconds', type=float, default=DEFAULT_RUN_SECONDS,
                        help='length of each recorded flight and dive [s]')
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    for name in ('flight.bag', 'flight_1200.bag', 'dive.bag', 'simple.bag', 'simple_dive.bag'):
        if os.path.exists(os.path.join(args.work, name)):
            os.remove(os.path.join(args.work, name))
    with Supervisor(args.run_dir) as supervisor:
        run = Run(supervisor, args.work)
        student_env = catkin_make(run)
        flight(run, args.run_seconds, student_env)
        dive(run, args.run_seconds, student_env)
    missing = [c.key for c in command_list.ALL if c.key not in run.results]
    if missing:
        sys.exit('report: commands not run: %s' % ', '.join(missing))
    with open(os.path.join(args.work, 'outputs.json'), 'w') as f:
        json.dump(run.results, f, indent=1, sort_keys=True)
    log('outputs of %d commands in %s' % (len(run.results), os.path.join(args.work, 'outputs.json')))


if __name__ == '__main__':
    main()

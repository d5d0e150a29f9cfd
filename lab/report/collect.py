#!/usr/bin/env python3
"""Brings the system up and runs every command of docs/report.md; writes outputs.json and the bags.

Usage: collect.py --work DIR --run-dir DIR [--flight-seconds S]

The order follows the exam sheets:

1. A master; ``rosrun mydrone mydrone_node.py`` alone; questions 4 to 8 and the warning service by hand.
2. ``catkin_create_pkg`` in a scratch folder (question 9).
3. The full default flight: ``rosbag record`` then ``roslaunch exam exam.launch`` for one profile loop;
   meanwhile the commands of questions 10 to 14. At the same time, on a second master, the same flight
   with ``threshold:=1500`` (question 14a), recorded too.
4. The same for the underwater drone on a fresh master: questions 4 to 8, then one full dive.

Everything is bounded in time, and every process started is ended on the way out (see session.py).
The outputs (with PIDs and ports of this run) go to ``<work>/outputs.json``; render.py fills the report.
"""
import argparse
import json
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import commands as C  # noqa: E402  (the folder of this script is not a package)
from session import Master, Session  # noqa: E402

#: Seconds of one recorded run: the default profiles loop in 100 s; the rest is start-up margin.
DEFAULT_RUN_SECONDS = 106.0


def log(message):
    print('report: %s' % message, flush=True)


def run_all(session, master, commands, results):
    for command in commands:
        output, status, seconds = session.run(command, master.env)
        results[command.key] = {'line': command.line, 'output': output, 'status': status,
                                'seconds': round(seconds, 1)}
        log('%-40s exit %s, %.1f s' % (command.line[:40], status, seconds))


def background(session, master, command, results, name=None):
    """Start a background command and note its line (its console is read after it stops)."""
    results[command.key] = {'line': command.line, 'console': session.console(name or command.key)}
    return session.start(name or command.key, command.line, master.env)


def finish_console(results, key):
    """Copy a stopped background command's console into the results."""
    with open(results[key]['console'], 'rb') as f:
        results[key]['output'] = f.read().decode('utf-8', 'replace').rstrip()


def node_alone(session, master, node_command, sensor_topic, commands, results):
    """Questions 3 to 8: one drone node on its own, explored with the command-line tools."""
    node = background(session, master, node_command, results)
    session.wait_for(sensor_topic + ' published', lambda: master.publishers(sensor_topic), 30.0, node)
    run_all(session, master, commands, results)
    session.stop(node)
    finish_console(results, node_command.key)


def recorded_run(session, master, record, launch, output_topic, bag_topic):
    """Start ``rosbag record`` (subscribed before anything is published), then the launch file."""
    bag = background(session, master, record, session.results)
    session.wait_for('rosbag subscribed to ' + bag_topic, lambda: master.subscribers(bag_topic), 30.0, bag)
    started = time.time()
    proc = background(session, master, launch, session.results)
    # Wall clock as the bag's stamps: the figures count time from this instant.
    session.results[launch.key]['started'] = started
    session.wait_for(output_topic + ' published', lambda: master.publishers(output_topic), 30.0, proc)
    return bag, proc, started


def flight(session, run_seconds):
    results = session.results
    master = Master(session, 'flight')
    log('mydrone alone on %s' % master.uri)
    node_alone(session, master, C.MYDRONE_NODE, '/temperature', C.MYDRONE_ALONE, results)

    scratch = os.path.join(session.run_dir, 'create_pkg')
    os.makedirs(scratch)
    output, status, _ = session.run(C.CREATE_PKG, master.env, cwd=scratch)
    with open(os.path.join(scratch, 'exam', 'package.xml')) as f:
        created = f.read()
    results[C.CREATE_PKG.key] = {'line': C.CREATE_PKG.line, 'output': output, 'status': status,
                                 'package_xml': created}

    high = Master(session, 'high')
    log('default flight on %s, threshold 1500 on %s, %.0f s' % (master.uri, high.uri, run_seconds))
    bag, launch, started = recorded_run(session, master, C.FLIGHT_RECORD, C.FLIGHT_LAUNCH, '/altitude',
                                        '/alt_warn_led')
    high_bag, high_launch, _ = recorded_run(session, high, C.HIGH_RECORD, C.HIGH_LAUNCH, '/altitude',
                                            '/alt_warn_led')
    run_all(session, master, C.FLIGHT_LIVE, results)
    run_all(session, high, C.HIGH_LIVE, results)
    time.sleep(max(0.0, started + run_seconds - time.time()))
    # The bags first, so they end on the running system rather than on its shutdown.
    for proc in (bag, high_bag, launch, high_launch):
        session.stop(proc)
    for key in (C.FLIGHT_RECORD.key, C.FLIGHT_LAUNCH.key, C.HIGH_RECORD.key, C.HIGH_LAUNCH.key):
        finish_console(results, key)
    session.stop(high.proc)
    session.stop(master.proc)


def dive(session, run_seconds):
    results = session.results
    master = Master(session, 'dive')
    log('submarine_drone alone on %s' % master.uri)
    node_alone(session, master, C.SUBMARINE_NODE, '/pressure_robot', C.SUBMARINE_ALONE, results)
    log('default dive on %s, %.0f s' % (master.uri, run_seconds))
    bag, launch, started = recorded_run(session, master, C.DIVE_RECORD, C.DIVE_LAUNCH, '/depth',
                                        '/depth_warn_led')
    run_all(session, master, C.DIVE_LIVE, results)
    time.sleep(max(0.0, started + run_seconds - time.time()))
    for proc in (bag, launch):
        session.stop(proc)
    for key in (C.DIVE_RECORD.key, C.DIVE_LAUNCH.key):
        finish_console(results, key)
    session.stop(master.proc)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--work', required=True, help='folder for the bags and outputs.json')
    parser.add_argument('--run-dir', required=True, help='private scratch folder of this run')
    parser.add_argument('--run-seconds', type=float, default=DEFAULT_RUN_SECONDS,
                        help='length of each recorded flight and dive [s]')
    args = parser.parse_args()
    os.makedirs(args.work, exist_ok=True)
    for name in ('flight.bag', 'flight_1500.bag', 'dive.bag'):
        if os.path.exists(os.path.join(args.work, name)):
            os.remove(os.path.join(args.work, name))
    with Session(args.run_dir, args.work) as session:
        flight(session, args.run_seconds)
        dive(session, args.run_seconds)
    missing = [c.key for c in C.ALL if c.key not in session.results]
    if missing:
        sys.exit('report: commands not run: %s' % ', '.join(missing))
    with open(os.path.join(args.work, 'outputs.json'), 'w') as f:
        json.dump(session.results, f, indent=1, sort_keys=True)
    log('outputs of %d commands in %s' % (len(session.results), os.path.join(args.work, 'outputs.json')))


if __name__ == '__main__':
    main()

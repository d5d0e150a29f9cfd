#!/usr/bin/env python3
"""`make soak`: the default flight of mydrone with the exam node, recorded and checked offline.

    soak.py --dir DIR [--minutes 30] [--threshold 1300] [--delay 5]

On a master of its own (free port), ``rosbag record`` keeps the flight's topics in ``DIR/soak.bag``
while ``roslaunch exam exam.launch`` flies for ``--minutes`` and the exam node's memory is sampled to
``DIR/rss.csv``; then soak_check.py checks both. Every process runs under the harness's supervisor, its
console in DIR, and is ended on the way out (soak.sh's trap ends them by DIR should this one die).
"""
import argparse
import os
import sys

from exam_lab.harness.supervisor import Supervisor
from exam_lab.harness.wait import wait_until

import soak_check

TOPICS = ['/temperature', '/pressure', '/altitude', '/alt_warn_led', '/rosout', '/diagnostics']
NODE = '/exam'
#: Seconds a process gets to stop on Ctrl-C (the recorder closing a 30-minute bag) before SIGKILL.
GRACE = 20.0


def fly(supervisor, bag, rss_csv, seconds, threshold, delay):
    """Record the flight for ``seconds`` while sampling the node's memory; 0 when nothing failed."""
    master = supervisor.start_master()
    # Recording starts before the flight, so the LED's initial GREEN and the first readings are in the bag.
    record = supervisor.start('record', ['rosbag', 'record', '-O', bag] + TOPICS + ['__name:=soak_record'],
                              master.env)
    if not wait_until(lambda: len(master.subscribers('/altitude')) > 0, 30.0,
                      alive=lambda: record.poll() is None):
        print('soak: rosbag record did not subscribe, see %s' % supervisor.log('record'), file=sys.stderr)
        return 1
    launch = supervisor.start('launch', ['roslaunch', 'exam', 'exam.launch', 'threshold:=%g' % threshold,
                                         'delay:=%g' % delay], master.env)
    status = soak_check.sample(master.uri, NODE, seconds, rss_csv)
    # Stop the flight, then the recorder (Ctrl-C lets it close the bag); the master goes last, on close.
    supervisor.stop(launch, GRACE)
    supervisor.stop(record, GRACE)
    return status


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--dir', required=True, help='where the bag, memory samples and logs go')
    parser.add_argument('--minutes', type=float, default=30.0, help='length of the flight')
    parser.add_argument('--threshold', type=float, default=1300.0, help='the exam node\'s ~threshold [m]')
    parser.add_argument('--delay', type=float, default=5.0, help='the exam node\'s ~delay [s]')
    args = parser.parse_args(argv)
    bag = os.path.join(args.dir, 'soak.bag')
    rss_csv = os.path.join(args.dir, 'rss.csv')
    print('soak: %g min of the default flight, threshold %g m, delay %g s; output in %s'
          % (args.minutes, args.threshold, args.delay, args.dir), flush=True)
    with Supervisor(args.dir) as supervisor:
        status = fly(supervisor, bag, rss_csv, args.minutes * 60.0, args.threshold, args.delay)
    if status != 0:
        return status
    return soak_check.check(bag, rss_csv, args.threshold, args.delay, NODE)


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

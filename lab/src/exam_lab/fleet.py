"""Launch a fleet of N drone + exam pairs, each in its own namespace, with the roslaunch API.

roslaunch XML has no loop, so instead of N hand-written includes this module loads
`lab/launch/drone_pair.launch` N times with `ns:=drone1` ... `ns:=droneN` into one roslaunch parent:
one process supervises every node, and Ctrl-C (SIGINT) or SIGTERM stops them all. When no master is
running, roslaunch starts one, exactly as the `roslaunch` command does.

The pair's nodes keep their own ROS API (see drone_pair.launch); this module adds none.
"""
import argparse

import roslaunch
import rospkg

PAIR_LAUNCH = 'drone_pair.launch'


def namespace(index):
    """Name of the index-th pair (1-based): drone1, drone2, ..."""
    return 'drone%d' % index


def pair_arguments(count, threshold, delay, profile='', seed=None, output='log'):
    """Return the roslaunch arguments ("name:=value") of each of the `count` pairs.

    Pair i gets noise seed `seed + i - 1` so the drones of one fleet do not fly identical noise, while
    the fleet as a whole stays reproducible; seed None keeps the simulator's default for every drone.
    """
    if count < 1:
        raise ValueError('a fleet needs at least one pair, got %d' % count)
    fleet = []
    for index in range(1, count + 1):
        args = ['ns:=%s' % namespace(index), 'threshold:=%s' % threshold, 'delay:=%s' % delay,
                'profile:=%s' % profile, 'output:=%s' % output]
        if seed is not None:
            args.append('seed:=%d' % (seed + index - 1))
        fleet.append(args)
    return fleet


def parse_args(argv):
    """Parse the command line of fleet_launch.py (argv without the program name)."""
    parser = argparse.ArgumentParser(
        prog='fleet_launch.py',
        description='Launch N mydrone + exam pairs in namespaces drone1..droneN; Ctrl-C stops all.')
    parser.add_argument('count', type=int, help='number of drone + exam pairs (>= 1)')
    parser.add_argument('--threshold', type=float, default=1300.0, help='altitude threshold (m)')
    parser.add_argument('--delay', type=float, default=5.0, help='debounce delay (s)')
    parser.add_argument('--profile', default='',
                        help='mydrone profile: a built-in name or YAML waypoints "[[t, alt], ...]"')
    parser.add_argument('--seed', type=int, default=1,
                        help='noise seed of drone1; droneN gets seed + N - 1')
    parser.add_argument('--screen', action='store_true', help="print the nodes' output to the console")
    args = parser.parse_args(argv)
    if args.count < 1:
        parser.error('count must be at least 1, got %d' % args.count)
    return args


def main(argv):
    """Start the fleet and block until Ctrl-C or until every node has exited."""
    args = parse_args(argv)
    launch_file = rospkg.RosPack().get_path('exam_lab') + '/launch/' + PAIR_LAUNCH
    fleet = pair_arguments(args.count, args.threshold, args.delay, args.profile, args.seed,
                           'screen' if args.screen else 'log')
    uuid = roslaunch.rlutil.get_or_generate_uuid(None, False)
    roslaunch.configure_logging(uuid)
    parent = roslaunch.parent.ROSLaunchParent(uuid, [(launch_file, pair) for pair in fleet])
    # spin() returns on Ctrl-C/SIGTERM (roslaunch's process monitor traps them) and shutdown() in the
    # finally stops whatever is still running, so no node outlives the launcher.
    try:
        parent.start()
        parent.spin()
    finally:
        parent.shutdown()

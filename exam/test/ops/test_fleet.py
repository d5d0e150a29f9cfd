"""A fleet of 2 drone + exam pairs comes up namespaced with fleet_launch.py, and Ctrl-C stops it all.

Runs against a master of its own on a free port; every process is stopped whatever the outcome.
"""
import json
import os
import signal
import xmlrpc.client

from rosprocs import Processes, free_port, probe, ros_env, wait_until

PAIR_NODES = ('mydrone', 'exam')


def registered_nodes(master_uri):
    """Names of the nodes that publish, subscribe or serve something on the master."""
    try:
        code, _msg, state = xmlrpc.client.ServerProxy(master_uri).getSystemState('/test_fleet')
    except OSError:
        return None
    return {node for kind in state for _name, nodes in kind for node in nodes} if code == 1 else None


def pid_of(node_uri):
    return xmlrpc.client.ServerProxy(node_uri).getPid('/test_fleet')[2]


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    with open('/proc/%d/stat' % pid) as stat:  # a zombie has exited; only its parent has not reaped it
        return stat.read().rsplit(')', 1)[1].split()[0] != 'Z'


def test_two_pairs_come_up_namespaced_and_ctrl_c_stops_all(tmp_path):
    master = 'http://127.0.0.1:%d' % free_port()
    env = ros_env(master, tmp_path)
    with Processes(tmp_path) as procs:
        procs.start('roscore', ['roscore', '-p', master.rsplit(':', 1)[1]], env)
        assert wait_until(lambda: registered_nodes(master) is not None, 30.0), procs.output('roscore')
        # The "high" flight holds 1500 m: each pair must turn its own LED red after the 1 s delay.
        fleet = procs.start('fleet', ['rosrun', 'exam', 'fleet_launch.py', '2', '--delay', '1',
                                      '--profile', 'high'], env)
        names = ['/drone%d/%s' % (i, node) for i in (1, 2) for node in PAIR_NODES]
        ok, out = probe(['--timeout', '60', '--value', '/drone1/altitude', '--value', '/drone2/altitude',
                         '--led', '/drone1/alt_warn_led=RED', '--led', '/drone2/alt_warn_led=RED']
                        + ['--node=' + name for name in names], env)
        assert ok, out + procs.output('fleet')
        report = json.loads(out.splitlines()[-1])
        print('fleet probe:', out)
        # Nothing of the pairs leaked into the root namespace.
        nodes = registered_nodes(master)
        assert not {'/mydrone', '/exam'} & nodes, nodes
        pids = [pid_of(report['nodes'][name]) for name in names]

        # SIGINT to the launcher alone (a terminal's Ctrl-C would reach its whole group): the launcher
        # itself must bring every node down, within roslaunch's SIGINT-then-SIGTERM escalation.
        fleet.send_signal(signal.SIGINT)
        fleet.wait(timeout=40.0)
        assert wait_until(lambda: not any(alive(pid) for pid in pids), 20.0), \
            'nodes still running after Ctrl-C: %s' % [p for p in pids if alive(p)]
        assert wait_until(lambda: not set(names) & (registered_nodes(master) or set()), 20.0)

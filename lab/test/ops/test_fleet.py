"""A fleet of 2 drone + exam pairs comes up namespaced with fleet_launch.py, and Ctrl-C stops it all.

Runs against a master of its own on a free port; every process is stopped whatever the outcome.
"""
import json
import signal
import xmlrpc.client

from exam_lab.harness.supervisor import Supervisor, alive
from exam_lab.harness.wait import wait_until

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


def test_two_pairs_come_up_namespaced_and_ctrl_c_stops_all(tmp_path):
    with Supervisor(tmp_path) as procs:
        master = procs.start_master()
        env = master.env
        master = master.uri
        # The "high" flight holds 1500 m: each pair must turn its own LED red after the 1 s delay.
        fleet = procs.start('fleet', ['rosrun', 'exam_lab', 'fleet_launch.py', '2', '--delay', '1',
                                      '--profile', 'high'], env)
        names = ['/drone%d/%s' % (i, node) for i in (1, 2) for node in PAIR_NODES]
        status, out, _ = procs.run(
            'probe', ['rosrun', 'exam_lab', 'probe.py', '--timeout', '60', '--value', '/drone1/altitude',
                      '--value', '/drone2/altitude', '--led', '/drone1/alt_warn_led=RED',
                      '--led', '/drone2/alt_warn_led=RED'] + ['--node=' + name for name in names],
            timeout=90.0, env=env)
        assert status == 0, out + procs.output('fleet')
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

"""Two hosts over a real network: the ground station (roscore + exam) and the drone (mydrone) in two
network namespaces joined by a veth pair, as docs/operations.md describes for two machines.

Each namespace has only its loopback and its end of the veth pair, with private addresses that exist
nowhere else, so every byte between the nodes crosses that link and none leaves the namespaces. The
test runs twice: each host advertising its address with ROS_IP, then its name with ROS_HOSTNAME, which
the other host resolves through a hosts file of its own (`ip netns exec` mounts /etc/netns/NS/hosts
over /etc/hosts), as two real machines would through DNS or /etc/hosts.

Skipped, with the reason printed and recorded as skipped in the JUnit file, where network namespaces
cannot be created (not root, no CAP_SYS_ADMIN, no iproute2).
"""
import json
import os
import re
import shutil
import subprocess

import pytest

from exam_lab.harness.supervisor import Supervisor, ros_env

SUBNET = '10.213.77.%d/30'
GROUND_IP = '10.213.77.1'
DRONE_IP = '10.213.77.2'
GROUND_NAME = 'ground-station.exam-ops'
DRONE_NAME = 'drone.exam-ops'
HOSTS = '127.0.0.1 localhost\n%s %s\n%s %s\n' % (GROUND_IP, GROUND_NAME, DRONE_IP, DRONE_NAME)
PORT = 11311  # the namespaces are private: the default port is free there
PREFIX = 'exam_ops_'


def ip(*args):
    return subprocess.run(['ip'] + list(args), stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                          universal_newlines=True, timeout=30)


def delete_namespace(name):
    ip('netns', 'del', name)
    shutil.rmtree(os.path.join('/etc/netns', name), ignore_errors=True)
    try:
        os.rmdir('/etc/netns')  # only when empty: other namespaces' files stay
    except OSError:
        pass


def remove_orphans():
    """Delete namespaces left by a run of this test that was killed before its cleanup (its pid is gone)."""
    for name, pid in re.findall(r'^(%s\w+_(\d+))' % PREFIX, ip('netns', 'list').stdout, re.M):
        if not os.path.exists('/proc/%s' % pid):
            delete_namespace(name)


@pytest.fixture
def network():
    """Two namespaces joined by a veth pair; yields (ground, drone) namespace names; always removed."""
    if shutil.which('ip') is None:
        pytest.skip('two-host test skipped: iproute2 (`ip`) is not installed')
    remove_orphans()
    ground, drone = PREFIX + 'ground_%d' % os.getpid(), PREFIX + 'drone_%d' % os.getpid()
    made = ip('netns', 'add', ground)
    if made.returncode != 0:
        pytest.skip('two-host test skipped: cannot create a network namespace (needs root or '
                    'CAP_SYS_ADMIN): %s' % made.stdout.strip())
    try:
        assert ip('netns', 'add', drone).returncode == 0
        # Both ends are created inside their namespaces: the host's own network never sees them.
        steps = [
            ('link', 'add', 'veth_ground', 'netns', ground, 'type', 'veth', 'peer', 'name', 'veth_drone',
             'netns', drone),
            ('-n', ground, 'addr', 'add', SUBNET % 1, 'dev', 'veth_ground'),
            ('-n', drone, 'addr', 'add', SUBNET % 2, 'dev', 'veth_drone'),
            ('-n', ground, 'link', 'set', 'lo', 'up'),
            ('-n', drone, 'link', 'set', 'lo', 'up'),
            ('-n', ground, 'link', 'set', 'veth_ground', 'up'),
            ('-n', drone, 'link', 'set', 'veth_drone', 'up'),
        ]
        for name in (ground, drone):
            os.makedirs(os.path.join('/etc/netns', name), exist_ok=True)
            with open(os.path.join('/etc/netns', name, 'hosts'), 'w') as hosts:
                hosts.write(HOSTS)
        for index, step in enumerate(steps):
            done = ip(*step)
            if done.returncode != 0 and index == 0:
                pytest.skip('two-host test skipped: cannot create a veth pair between network '
                            'namespaces: %s' % done.stdout.strip())
            assert done.returncode == 0, 'ip %s: %s' % (' '.join(step), done.stdout)
        yield ground, drone
    finally:
        # Processes are stopped by then (the test's `with` block); deleting a namespace deletes its veth.
        delete_namespace(drone)
        delete_namespace(ground)


def host_env(base, advertise, own_ip, own_name, log_dir):
    """A host's ROS environment: the master at the ground station, and what this host advertises."""
    if advertise == 'ROS_IP':
        return ros_env(base, 'http://%s:%d' % (GROUND_IP, PORT), log_dir, ip=own_ip)
    env = ros_env(base, 'http://%s:%d' % (GROUND_NAME, PORT), log_dir)
    env['ROS_HOSTNAME'] = own_name
    return env


def probe(procs, args, env, prefix, timeout=90.0):
    """Run lab/scripts/probe.py on one host; (True when it saw everything, its output)."""
    status, out, _ = procs.run('probe', prefix + ('rosrun', 'exam_lab', 'probe.py') + tuple(args),
                               timeout=timeout, env=env)
    return status == 0, out


@pytest.mark.parametrize('advertise', ['ROS_IP', 'ROS_HOSTNAME'])
def test_drone_and_ground_station_on_two_hosts(network, tmp_path, advertise):
    ground, drone = network
    in_ground = ('ip', 'netns', 'exec', ground)
    in_drone = ('ip', 'netns', 'exec', drone)

    # The link leads nowhere else: the drone host's only route is the ground station's subnet.
    routes = subprocess.run(in_drone + ('ip', 'route'), stdout=subprocess.PIPE,
                            universal_newlines=True).stdout
    assert 'default' not in routes, routes

    with Supervisor(tmp_path) as procs:
        ground_env = host_env(procs.env, advertise, GROUND_IP, GROUND_NAME, tmp_path)
        drone_env = host_env(procs.env, advertise, DRONE_IP, DRONE_NAME, tmp_path)
        procs.start('roscore', in_ground + ('roscore', '-p', str(PORT)), ground_env)
        # rospy gives up on private parameters when the master is not up yet: wait for it first.
        ok, out = probe(procs, ['--node', '/rosout', '--timeout', '30'], ground_env, in_ground)
        assert ok, out + procs.output('roscore')
        procs.start('exam', in_ground + ('rosrun', 'exam', 'exam_node.py', '_delay:=1.0'), ground_env)
        # "high" holds 1500 m: the ground station must send WARNING across the link after 1 s.
        procs.start('mydrone', in_drone + ('rosrun', 'mydrone', 'mydrone_node.py', '_profile:=high'),
                    drone_env)
        wanted = ['--value', '/altitude', '--led', '/alt_warn_led=RED', '--node', '/exam',
                  '--node', '/mydrone', '--timeout', '90']
        ok, out = probe(procs, wanted, ground_env, in_ground, timeout=120)
        assert ok, out + procs.output('roscore') + procs.output('exam') + procs.output('mydrone')
        seen_ground = json.loads(out.splitlines()[-1])
        # The same from the drone's side: the ground station's /altitude reaches the drone host.
        ok, out = probe(procs, wanted, drone_env, in_drone, timeout=120)
        assert ok, out
        seen_drone = json.loads(out.splitlines()[-1])
        print('ground station sees:', seen_ground)
        print('drone host sees:', seen_drone)

    # Each node advertised its own host, so the traffic did cross the veth link.
    own = {'ROS_IP': (GROUND_IP, DRONE_IP), 'ROS_HOSTNAME': (GROUND_NAME, DRONE_NAME)}[advertise]
    assert '//%s:' % own[0] in seen_ground['nodes']['/exam']
    assert '//%s:' % own[1] in seen_ground['nodes']['/mydrone']
    assert seen_drone['/alt_warn_led']['last'] == 'RED'

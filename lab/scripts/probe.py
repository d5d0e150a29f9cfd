#!/usr/bin/env python3
"""Waits, with one deadline, until a running ROS system shows what a test expects; prints what it saw.

A node of its own, run as a subprocess by the pytest operations tests: their test process talks to
several masters (or none in its network namespace), while rospy can join only one per process.

Usage:
    probe.py [--timeout S] [--echo] [--value TOPIC]... [--led TOPIC=COLOUR]... [--node NAME]...

    --value TOPIC   std_msgs/Float32 TOPIC must deliver at least --count messages (default 5)
    --led T=C       std_msgs/String T must read C (e.g. /alt_warn_led=RED)
    --node NAME     NAME must be registered; its XML-RPC URI is reported
    --echo          also print every message of those topics as it arrives, one JSON object a line:
                    {"echo": topic, "t": arrival time (s since the epoch), "data": value}

Prints one JSON object last: per topic the message count, last value and receive rate [Hz]; per node
its URI. Exit status 0 when everything was seen before the deadline, 1 otherwise.
"""
import argparse
import json
import sys
import threading
import time

import rosgraph
import rospy
from std_msgs.msg import Float32, String


class Echo(object):
    """Prints messages as JSON lines, one writer at a time, until :meth:`stop` (the report comes last)."""

    def __init__(self, enabled):
        self.lock = threading.Lock()
        self.enabled = enabled

    def __call__(self, topic, stamp, data):
        with self.lock:
            if self.enabled:
                print(json.dumps({'echo': topic, 't': stamp, 'data': data}), flush=True)

    def stop(self):
        with self.lock:
            self.enabled = False


class Watch(object):
    """Messages of one topic: count, last value, first and last arrival (monotonic s)."""

    def __init__(self, topic, msg_type, echo):
        self.lock = threading.Lock()
        self.topic = topic
        self.echo = echo
        self.count = 0
        self.last = None
        self.first_at = self.last_at = None
        self.sub = rospy.Subscriber(topic, msg_type, self.on_msg)

    def on_msg(self, msg):
        now = time.monotonic()
        self.echo(self.topic, time.time(), msg.data)
        with self.lock:
            self.count += 1
            self.last = msg.data
            self.first_at = self.first_at or now
            self.last_at = now

    def report(self):
        with self.lock:
            span = (self.last_at - self.first_at) if self.count > 1 else 0.0
            return {'count': self.count, 'last': self.last,
                    'rate_hz': (self.count - 1) / span if span > 0 else None}


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--timeout', type=float, default=60.0)
    parser.add_argument('--count', type=int, default=5)
    parser.add_argument('--value', action='append', default=[])
    parser.add_argument('--led', action='append', default=[])
    parser.add_argument('--node', action='append', default=[])
    parser.add_argument('--echo', action='store_true')
    args = parser.parse_args(rospy.myargv(argv)[1:])

    rospy.init_node('probe', anonymous=True, disable_signals=True)
    echo = Echo(args.echo)
    values = {topic: Watch(topic, Float32, echo) for topic in args.value}
    leds = {}
    for spec in args.led:
        topic, colour = spec.split('=', 1)
        leds[topic] = (Watch(topic, String, echo), colour)
    master = rosgraph.Master(rospy.get_name())

    def node_uris():
        uris = {}
        for name in args.node:
            try:
                uris[name] = master.lookupNode(name)
            except rosgraph.MasterError:
                pass
        return uris

    def satisfied():
        return (all(w.report()['count'] >= args.count for w in values.values())
                and all(w.report()['last'] == colour for w, colour in leds.values())
                and len(node_uris()) == len(args.node))

    deadline = time.monotonic() + args.timeout
    while not satisfied() and time.monotonic() < deadline:
        time.sleep(0.1)
    ok = satisfied()
    echo.stop()
    report = {'ok': ok, 'nodes': node_uris()}
    report.update({topic: w.report() for topic, w in values.items()})
    report.update({topic: w.report() for topic, (w, _colour) in leds.items()})
    print(json.dumps(report, sort_keys=True))
    rospy.signal_shutdown('probe done')
    return 0 if ok else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))

"""The student's node as the probe finds it on the master: that it started, which inputs it subscribes
to and with which type (an input it asked for in another numeric type is then published in that type),
and which topic it publishes its value on. Run in the probe's rospy process
(:mod:`exam_lab.grader.judge.probe`), before anything is flown.
"""
import time

import rospy
from std_msgs import msg as std_msgs

from exam_lab.harness.fake_drone import TopicRecorder
from exam_lab.harness.wait import wait_until

#: Seconds to wait for roslaunch to come up on the master (its ``/roslaunch/uris/`` parameter): the
#: node's ``start_timeout`` counts from then, so a loaded machine's slow ``roslaunch`` start (bash, its
#: imports, the launch file read: 25 s seen at a load of 45) is never counted against the node.
LAUNCH_START_S = 60.0
#: Seconds to wait for the second input's subscription once the node is up.
SUBSCRIBE_S = 6.0
#: Seconds to wait for each subscribed input to connect or be refused: rospy connects in its own
#: threads, which a loaded machine runs late (over 3 s seen in a fresh clone's loaded test run).
SETTLE_S = 15.0
#: Seconds a publisher in the node's type first waits for its connection before it is registered anew;
#: each new try waits twice as long (a connection slower than one wait is not cut at every try).
RETYPE_S = 1.0
#: Seconds the node has to connect to the publishers re-typed for it.
ADAPT_S = 15.0
#: Seconds to wait for the output publisher once the node subscribed.
OUTPUT_S = 3.0
#: Message types the probe can read values from: every numeric std_msgs type (the sheet names none).
NUMERIC_TYPES = ('Float32', 'Float64', 'Int8', 'Int16', 'Int32', 'Int64', 'UInt8', 'UInt16', 'UInt32', 'UInt64')
VALUE_TYPES = {'std_msgs/%s' % name: getattr(std_msgs, name) for name in NUMERIC_TYPES}


class NodeFinder(object):
    """Finds the student's node, its inputs and its output for the probe, from what the master says
    (``graph``: :class:`~exam_lab.grader.judge.graph.Graph`) and what rospy refused (``refusals``:
    :class:`~exam_lab.grader.judge.graph.RefusedConnections`), while ``drone`` feeds its inputs."""

    def __init__(self, plan, graph, refusals, drone, t0, launch_ended=lambda: False):
        self.plan, self.graph, self.refusals, self.drone, self.t0 = plan, graph, refusals, drone, t0
        #: Whether the session saw roslaunch exit (a launch file it refuses at once): no node will come.
        self.launch_ended = launch_ended

    def wait_for_node(self):
        """The probe's result's ``nodes`` (none when no node came within the plan's ``start_timeout``
        of roslaunch's start, or roslaunch never came up within LAUNCH_START_S, or ended first),
        ``launch_seen_s`` (when the probe first saw roslaunch up, at the latest with the node; None if
        never) and ``node_seen_s`` (both s from the probe's start); once a node came, also
        ``subscribed`` and ``input_types``."""
        launched = []

        def nodes_or_end():
            """``(nodes,)`` once a node came or the wait is over (``([],)``), else None."""
            nodes = self.graph.student_nodes()
            now = time.time()
            if not launched and self.graph.launch_started():
                launched.append(now)
            over = self.launch_ended() or (now > launched[0] + self.plan.start_timeout if launched
                                           else now > self.t0 + LAUNCH_START_S)
            return (nodes,) if nodes or over else None
        nodes = (wait_until(nodes_or_end, LAUNCH_START_S + self.plan.start_timeout, period=0.1) or ([],))[0]
        found = {'nodes': nodes or [], 'node_seen_s': None if not nodes else time.time() - self.t0,
                 'launch_seen_s': launched[0] - self.t0 if launched else None}
        if not nodes:
            return found
        inputs = [rospy.resolve_name(t) for t in (self.drone.fixed_topic, self.drone.moving_topic)]
        # Every subscriber seen while waiting, not only those of one instant: a node that subscribes to
        # each input in turn (rospy.wait_for_message in its loop) subscribes to both (issue 45).
        seen = {t: [] for t in inputs}

        def both_seen():
            for topic in inputs:
                seen[topic] += [n for n in self.graph.subscribers(topic) if n not in seen[topic]]
            return all(seen.values())
        wait_until(both_seen, SUBSCRIBE_S, period=0.05)
        found['subscribed'] = seen
        found['input_types'] = self.input_types(dict(zip(inputs, (self.drone.fixed_topic, self.drone.moving_topic))))
        return found

    def input_types(self, inputs):
        """{input topic: {"type" the node subscribed with, "connected", "refused", "adapted"}}: a
        subscription rospy refused (another type than the drone's) shows as no connection and a refusal
        in our log. Waits up to SETTLE_S for each subscribed input to connect or be refused.

        A refused input the node asked for as another numeric std_msgs type is then published in that
        type (``adapted``: the type, once the node connected to it), as a teacher would change one word to
        see the rest work: the wrong type costs question 10 alone, not the values and the warning too.

        :param inputs: {resolved input topic: the feeder's name of it}."""
        feeder = self.drone.feeder

        def settled():
            return all(not self.graph.subscribers(t) or feeder.connections(name) > 0 or t in self.refusals.refused()
                       for t, name in inputs.items())
        wait_until(settled, SETTLE_S, period=0.1)
        refused = self.refusals.refused()
        adapted = {t: refused[t]['wanted'] for t in inputs
                   if t in refused and refused[t]['wanted'] in VALUE_TYPES and refused[t]['wanted'] != 'std_msgs/Float32'}
        # The node's subscriber may still hold the refused connection when the master tells it of the new
        # publisher (rospy then skips a publisher it thinks it is connected to): a publisher not
        # connected within its wait is registered anew, each wait twice the last, until ADAPT_S.
        deadline, wait = time.time() + ADAPT_S, RETYPE_S
        waiting = sorted(adapted)
        while waiting and time.time() < deadline:
            for topic in waiting:
                feeder.retype(inputs[topic], VALUE_TYPES[adapted[topic]])
            wait_until(lambda: all(feeder.connections(inputs[t]) > 0 for t in waiting),
                       min(wait, max(0.0, deadline - time.time())), period=0.05)
            waiting, wait = [t for t in waiting if feeder.connections(inputs[t]) == 0], 2 * wait
        out = {}
        for topic, name in sorted(inputs.items()):
            connected = feeder.connections(name) > 0
            if topic in refused:
                out[topic] = {'type': refused[topic]['wanted'], 'connected': connected,
                              'refused': 'rospy refused the connection: the node asked for %s, the drone '
                                         'publishes %s' % (refused[topic]['wanted'], refused[topic]['published']),
                              'published': refused[topic]['published'],
                              'adapted': adapted[topic] if topic in adapted and connected else None}
            elif self.graph.subscribers(topic):
                out[topic] = {'type': 'std_msgs/Float32' if connected else None, 'connected': connected,
                              'refused': None, 'adapted': None}
        return out

    def find_output(self, recorder):
        """The probe's result's ``output`` (the topic the node's value is read from: the sheet's, or
        else the likeliest numeric one it publishes) and the recorder that reads it: ``recorder`` (the
        drone's, of the sheet's topic in Float32), a new one for another topic or type, None for a type
        the probe cannot read values from."""
        expected = rospy.resolve_name(self.plan.output)
        found = wait_until(lambda: expected in self.graph.publications(), OUTPUT_S, period=0.1)
        publications = self.graph.publications()
        output = {'expected': expected, 'topic': None, 'type': None,
                  'candidates': sorted(publications)}
        if found:
            output.update(topic=expected, type=publications[expected])
        else:
            candidates = sorted(t for t, kind in publications.items() if kind in VALUE_TYPES)
            preferred = [t for t in candidates if self.plan.output[:3] in t.lower()] or candidates
            if preferred:
                output.update(topic=preferred[0], type=publications[preferred[0]])
        topic, kind = output['topic'], output['type']
        if topic is not None and (topic != expected or kind != 'std_msgs/Float32') and kind in VALUE_TYPES:
            recorder.close()
            recorder = TopicRecorder(topic, msg_type=VALUE_TYPES[kind], clock=time.time)
        elif topic is not None and kind not in VALUE_TYPES:
            recorder = None  # a type the probe cannot read values from
        return output, recorder

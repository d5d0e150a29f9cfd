"""The grader's probe: plays the drone for a student's node and measures what the rubric asks.

Run inside its own rospy process, on the master of one submission, by :mod:`exam_lab.grader.host.session`::

    python3 -m exam_lab.grader.judge.probe PLAN.json RESULT.json

The drone is the harness's :class:`~exam_lab.harness.fake_drone.Drone`, the sheet's own drone (its
topics, rates, service, answers and LED, from the drone package's SPEC; a new value goes out at the
sensor's next tick, as the real drone's reading does), driven by a script with noise-free values from
the oracle, so the same package gets the same measurements. The probe only
measures; the points are given by :mod:`exam_lab.grader.score.rubric` from the JSON it writes.

Plan (JSON): ``kind`` ("main": the whole scenario, "threshold": the check of question 14a, the same
scenario around the threshold drawn for it), ``sheet``, ``threshold`` (student units), ``margin`` (how
far beyond the threshold to fly), ``delay`` (s), ``start_timeout`` (s to wait for the node),
``late_warning`` (s a late WARNING is waited for, 0 for none); for "threshold" also ``warn_after``
(s the main run's WARNING took).

Every time is the wall clock's (``time.time()``), never rospy's ROS time: a student's node can set
``/use_sim_time`` on the master before the probe's ``init_node`` and publish ``/clock``, and rospy would
follow. The probe watches for both (a subscriber on ``/clock``, the parameter read at its start and
end: ``clock`` in its result), and the session refuses such a run.

The main scenario (times are the script's, all recorded as wall-clock times of the events):

1. wait for the student's node; note which inputs it subscribes to and what it publishes;
2. question 11: a few input pairs (one with another temperature / remote pressure), the value the node
   publishes for each after it settled;
3. calibration: from those values, the inputs that make the *node's own* value sit ``margin`` below
   and above the threshold and ``NEAR_M`` below it, checked by flying there (a wrong formula costs
   question 11 only);
4. the flight (docs/grading.md's table of legs says which wrong node each leg tells from a right one):
   rest below (``REST_S``, longer for a NORMAL the node owes), a short excursion above (``SHORT_S``),
   just below (``near``, ``GAP_S``), a long excursion (delay + ``AFTER_S``, longer for a late WARNING),
   just below (``BACK_S``), further below (``DEEP_S``, longer for a late NORMAL); every service call is
   recorded with its arrival time. Each leg's hold counts from
   the node's own first value on its side, and every leg is checked on the node's own values (``legs``):
   the rubric times each rule from them and judges nothing on a leg the node's value did not reach.
"""
import ast
import json
import logging
import math
import os
import re
import sys
import threading
import time
import xmlrpc.client

import rosgraph
import rospy
from rosgraph_msgs.msg import Clock
from std_msgs import msg as std_msgs

from exam_lab.grader.score.sheets import request_meaning
from exam_lab.harness import oracle
from exam_lab.harness.fake_drone import Drone, TopicRecorder
from exam_lab.harness.wait import wait_until

#: Seconds after an input change before the node's output is read (several 10 Hz ticks).
SETTLE_S = 0.8
#: After a change of both inputs, read one period of the slowest input plus this later.
SETTLE_SLACK_S = 0.5
#: Published values older than this after an input change are not read (the change may be half seen).
IGNORE_S = 0.3
#: Seconds to wait for the second input's subscription once the node is up.
SUBSCRIBE_S = 6.0
#: Seconds a publisher in the node's type waits for its connection before it is registered anew.
RETYPE_S = 1.0
#: Seconds to wait for the output publisher once the node subscribed.
OUTPUT_S = 3.0
#: The flight's holds, s from the node's own first value on the leg's side (docs/grading.md, legs).
#: The short excursion: with a return as late as the rubric's lag tolerance (one period of the slowest
#: input and 0.5 s: 1.79 s) the node's own value stays above 4.3 s at most, less than the WARNING
#: window's start (4.7 s), so a right node never warns there.
REST_S = 2.0
SHORT_S = 2.5
#: Just below the threshold after the short excursion: a count that is not reset there shows later.
GAP_S = 2.0
#: The long excursion lasts delay + AFTER_S: past the WARNING window's end (the delay and the larger of
#: 0.5 s and one period of the slowest input and a tick: 1.39 s at most, rubric.warning_window).
AFTER_S = 1.5
#: Just below the threshold after the long excursion: NORMAL must come here, at once.
BACK_S = 1.5
#: Further below (the rest's value): the NORMAL of a node that waits for a margin, for question 13.
DEEP_S = 1.5
#: A NORMAL the node owes (its last call was a WARNING) is waited for on the rest and on the last leg,
#: up to the delay, AFTER_S and one period of the slowest input after its own value came back below
#: (:func:`normal_wait`): a node that goes back to NORMAL only after the delay below, checking at each
#: reading, is seen doing it, so its late NORMAL costs Q14b's "at once" only, not Q13 as well, and a
#: WARNING it gave during the calibration does not hide the flight's WARNING from it.
#: The return legs fly the node's own value this far below the threshold (student units), accepted
#: up to NEAR_MAX_M below: closer than any noise band a student might wait for (mydrone's thermometer
#: alone moves the altitude by about 0.45 m).
NEAR_M = 0.1
NEAR_MAX_M = 0.2
#: The most seconds a leg waits for the node's own value to reach the side of the threshold it is
#: flown for (a node that blocks a callback for 5 s publishes a stale value meanwhile).
REACH_S = 8.0
#: After an input change, a value read is waited for until it moved, up to this many s (a stale node).
STALE_S = 6.0
#: Message types the probe can read values from: every numeric std_msgs type (the sheet names none).
NUMERIC_TYPES = ('Float32', 'Float64', 'Int8', 'Int16', 'Int32', 'Int64', 'UInt8', 'UInt16', 'UInt32', 'UInt64')
VALUE_TYPES = {'std_msgs/%s' % name: getattr(std_msgs, name) for name in NUMERIC_TYPES}
#: Topics every node has or that are never an answer.
IGNORED_TOPICS = ('/rosout', '/rosout_agg', '/diagnostics')


#: rospy's words, in the probe's own log, when a subscriber asks for another type than the drone
#: publishes (the md5sums differ): "Could not process inbound connection: topic types do not match:
#: [std_msgs/Float64] vs. [std_msgs/Float32]{'callerid': '/exam', 'topic': '/temperature', ...}".
_TYPE_REFUSAL = re.compile(r'topic types do not match: \[([^\]]*)\] vs\. \[([^\]]*)\](\{.*\})')


class RefusedConnections(logging.Handler):
    """The subscriptions the probe's publishers refused, read from rospy's own warning: which node
    asked for which topic with which type. The master lists such a node as a subscriber, yet it never
    gets a message (rospy drops the connection), so only this says what the node subscribed with."""

    def __init__(self):
        logging.Handler.__init__(self, logging.WARNING)
        self._lock_refused = threading.Lock()
        self._refused = {}

    def emit(self, record):
        try:
            match = _TYPE_REFUSAL.search(record.getMessage())
            header = ast.literal_eval(match.group(3)) if match else None
        except (ValueError, SyntaxError):
            return
        if isinstance(header, dict) and header.get('topic'):
            with self._lock_refused:
                self._refused[str(header['topic'])] = {'node': str(header.get('callerid', '?')),
                                                       'wanted': match.group(1), 'published': match.group(2)}

    def refused(self):
        """{topic: {"node", "wanted" (the subscriber's type), "published" (the drone's)}}."""
        with self._lock_refused:
            return dict(self._refused)

class ClockWatch(object):
    """Whether anyone set ``/use_sim_time`` or published ``/clock`` during the run: the parameter as
    rospy's ``init_node`` read it and as it is at the end, the ``/clock`` messages received and the
    nodes that publish it. Built right after ``init_node``."""

    def __init__(self):
        self._lock = threading.Lock()
        self._messages = 0
        self._at_start = self._use_sim_time()
        self._sub = rospy.Subscriber('/clock', Clock, self._count, queue_size=1)

    @staticmethod
    def _use_sim_time():
        try:
            return rospy.get_param('/use_sim_time', None)
        except Exception:  # the master answers; a failure is a transient of the XML-RPC call
            return None

    def _count(self, _msg):
        with self._lock:
            self._messages += 1

    def seen(self, graph):
        """``{"use_sim_time": [at start, at end], "messages", "publishers", "ros_time_is_wall"}``."""
        with self._lock:
            messages = self._messages
        return {'use_sim_time': [self._at_start, self._use_sim_time()], 'messages': messages,
                'publishers': graph.publishers('/clock'), 'ros_time_is_wall': rospy.rostime.is_wallclock()}


class Graph(object):
    """The master's view, restricted to the student's nodes (everyone but this probe and rosout)."""

    def __init__(self):
        self._master = rosgraph.Master(rospy.get_name())

    def _state(self):
        try:
            return self._master.getSystemState()
        except Exception:  # the master answers; a failure is a transient of the XML-RPC call
            return [[], [], []]

    def student_nodes(self):
        nodes = set()
        for kind in self._state():
            for _, names in kind:
                nodes.update(names)
        return sorted(n for n in nodes if n not in (rospy.get_name(), '/rosout'))

    def summary(self):
        """{node: {"publishes": [[topic, type]], "subscribes": [...], "services": [name]}}."""
        pubs, subs, srvs = self._state()
        try:
            types = dict(self._master.getTopicTypes())
        except Exception:
            types = {}
        nodes = {n: {'publishes': [], 'subscribes': [], 'services': []} for n in self.student_nodes()}
        for key, kind in (('publishes', pubs), ('subscribes', subs)):
            for topic, names in kind:
                for name in names:
                    if name in nodes:
                        nodes[name][key].append([topic, types.get(topic, '?')])
        for service, names in srvs:
            for name in names:
                if name in nodes and not service.startswith(name + '/'):
                    nodes[name]['services'].append(service)
        return nodes

    def publishers(self, topic):
        """Every node that publishes ``topic``, this probe included."""
        return sorted(dict(self._state()[0]).get(topic, []))

    def subscribers(self, topic):
        names = dict(self._state()[1]).get(topic, [])
        return sorted(n for n in names if n in self.student_nodes())


class NodeWatch(object):
    """The student's nodes as the judge sees them during a run, whatever roslaunch prints: every
    PERIOD_S, the master's list of nodes (``getSystemState``), each node's XML-RPC URI (``lookupNode``)
    and its pid (the node's own ``getPid``). A node whose pid or URI changes was started again (roslaunch's
    ``respawn``); one that leaves the master's list, or whose URI refuses connections, ended. Either is
    a death, seen here even when roslaunch's words about it are lost (the log's middle is cut for a
    chatty node). Built right after ``init_node``; :meth:`stop` before the result is written, so the
    grader's own stopping of the node is never counted.

    :param names: returns the student's node names (:meth:`Graph.student_nodes`).
    :param lookup: node name -> XML-RPC URI, None when the master does not know it.
    :param pid_of: URI -> pid; raises ConnectionRefusedError when nothing listens there any more.
    """

    #: Seconds between two looks; a node that dies and is back within one is still seen (new pid).
    PERIOD_S = 0.25

    def __init__(self, names, lookup, pid_of, clock=time.time):
        self._names, self._lookup, self._pid_of, self._clock = names, lookup, pid_of, clock
        self._lock = threading.Lock()
        self._seen = {}    # name -> (uri, pid) while running, None once it ended
        self._deaths = []
        self._stop = threading.Event()
        self._thread = None

    def start(self):
        self._thread = threading.Thread(target=self._loop, name='node-watch', daemon=True)
        self._thread.start()
        return self

    def _loop(self):
        while not self._stop.wait(self.PERIOD_S):
            try:
                self.look()
            except Exception:  # a transient of the master's XML-RPC: the next look sees it again
                pass

    def look(self):
        """One look at the master and each node; records the deaths it sees."""
        now, names = self._clock(), set(self._names())
        with self._lock:
            known = dict(self._seen)
        for name in sorted(names | set(n for n, s in known.items() if s is not None)):
            uri = self._lookup(name) if name in names else None
            now_running = None
            if uri is not None:
                try:
                    now_running = (uri, self._pid_of(uri))
                except ConnectionRefusedError:
                    now_running = None  # registered, but its process is gone (killed, no unregistering)
                except Exception:
                    continue  # slow or odd answer: not a death, looked at again next time
            before = known.get(name, 'new')
            if before == 'new':
                if now_running is not None:
                    self._record(name, now_running, None)
            elif before is None:
                if now_running is not None:  # back after an end already counted: started again
                    self._record(name, now_running, None, returned=True)
            elif now_running is None:
                self._record(name, None, 'ended during the run (pid %s)' % before[1], at=now)
            elif now_running != before:
                self._record(name, now_running, 'started again during the run (pid %s, then %s)'
                             % (before[1], now_running[1]), at=now)

    def _record(self, name, running, death, at=None, returned=False):
        with self._lock:
            self._seen[name] = running
            if death:
                self._deaths.append({'node': name, 't': at, 'detail': death})
            elif returned and self._deaths:
                for entry in reversed(self._deaths):
                    if entry['node'] == name:
                        entry['detail'] += ', then started again (pid %s)' % running[1]
                        break

    def stop(self):
        """Stop looking (one last look first); return ``{"deaths": [{"node", "t", "detail"}], "nodes"}``."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        try:
            self.look()
        except Exception:
            pass
        with self._lock:
            return {'deaths': [dict(d) for d in self._deaths], 'nodes': sorted(self._seen)}

class _BoundedTransport(xmlrpc.client.Transport):
    """XML-RPC to a student's node: every call within ``timeout`` s, at most ``max_bytes`` of answer
    (the node writes its answer)."""

    def __init__(self, timeout, max_bytes):
        super().__init__()
        self._timeout, self._max_bytes = timeout, max_bytes

    def make_connection(self, host):
        connection = super().make_connection(host)
        connection.timeout = self._timeout
        return connection

    def parse_response(self, response):
        parser, unmarshaller = self.getparser()
        read = 0
        while True:
            data = response.read(1024)
            if not data:
                break
            read += len(data)
            if read > self._max_bytes:
                raise ValueError('an answer over %d bytes' % self._max_bytes)
            parser.feed(data)
        parser.close()
        return unmarshaller.close()


#: A node's getPid: answered within this many s, in at most this many bytes.
PID_TIMEOUT_S = 2.0
PID_ANSWER_BYTES = 4096


def node_pid(uri):
    """The pid the node at ``uri`` gives (its XML-RPC ``getPid``); raises ConnectionRefusedError when
    nothing listens there any more, another error for an answer that is late, long or not a pid."""
    code, _, pid = xmlrpc.client.ServerProxy(uri, transport=_BoundedTransport(PID_TIMEOUT_S, PID_ANSWER_BYTES)) \
        .getPid(rospy.get_name())
    if code != 1 or not isinstance(pid, int):
        raise ValueError('getPid answered %r' % ([code, pid],))
    return pid


def node_uri(master, name):
    """The XML-RPC URI the master has for node ``name``, None when it has none."""
    try:
        return master.lookupNode(name)
    except rosgraph.MasterError:
        return None


def _last_value(recorder, since):
    """The last value published at least IGNORE_S after ``since`` and the number of such samples."""
    samples = recorder.samples(since + IGNORE_S)
    return (samples[-1][1] if samples else None), len(samples)


def _settled(recorder, since, before=None, settle=SETTLE_S):
    """The node's value after an input change at ``since``: read ``settle`` s later; when it is still the
    ``before`` value (or none), waited for until it moves, up to STALE_S (a node that blocks in a callback)."""
    time.sleep(max(0.0, since + settle - time.time()))
    # Also when nothing came yet: a node computes only once it has a reading of each input, and the
    # slowest comes once a period.
    wait_until(lambda: _last_value(recorder, since)[0] not in (None, before), max(0.0, STALE_S - settle),
               period=0.1)
    return _last_value(recorder, since)


def on_side(value, threshold, side):
    """True when ``value`` is on ``side`` ('above': beyond the threshold, 'below': not beyond it)."""
    if value is None or not math.isfinite(value):
        return False
    return value > threshold if side == 'above' else value <= threshold


def owes(calls, side, since):
    """Whether a node whose service calls are ``calls`` (``[(time, request)]``) still owes the call a
    leg flown on ``side`` since ``since`` waits for: above, a WARNING (none came since); below, a
    NORMAL (its last WARNING or NORMAL was a WARNING, whenever it came)."""
    if side == 'above':
        return not any(t >= since and request_meaning(s) == 'WARNING' for t, s in calls)
    statuses = [request_meaning(s) for _, s in sorted(calls)]
    statuses = [s for s in statuses if s in ('WARNING', 'NORMAL')]
    return bool(statuses) and statuses[-1] == 'WARNING'


def normal_wait(delay, rates):
    """Seconds a NORMAL the node owes is waited for after its own value came back below: the delay,
    AFTER_S and one period of the slowest input (``rates``: topic -> Hz)."""
    return delay + AFTER_S + 1.0 / min(rates.values())


#: The main flight's legs, in their order.
FLIGHT_LEGS = ('rest', 'short_up', 'short_down', 'long_up', 'long_down', 'deep_down')


def leg_check(samples, threshold, side, start, end):
    """Whether the node's own published values were on ``side`` of the threshold during a leg that
    was flown from ``start`` to ``end``: ``{"side", "reached" (time of the first value on that side,
    or None), "stays" (time of the first value from which every value of the leg is on that side, or
    None), "off_side" (values on the other side after "reached"), "first", "last" (values)}``.

    Judged only on what the node published: a leg whose values never reached the side (a stale
    reading, a node that does not react) is not one the rubric may judge anything on. The rubric times
    the delay from "stays" (the node's own value went beyond and stayed), the return from "reached".
    """
    inside = [(t, v) for t, v in samples if start <= t <= end]
    reached = next((t for t, v in inside if on_side(v, threshold, side)), None)
    off = len([1 for t, v in inside if reached is not None and t >= reached and not on_side(v, threshold, side)])
    stays = None
    for t, v in reversed(inside):
        if not on_side(v, threshold, side):
            break
        stays = t
    return {'side': side, 'reached': reached, 'stays': stays, 'off_side': off,
            'first': inside[0][1] if inside else None, 'last': inside[-1][1] if inside else None,
            'samples': len(inside)}


class Probe(object):

    def __init__(self, plan):
        self.plan = plan
        self.sheet = plan['sheet']
        self.result = {'kind': plan['kind'], 'sheet': self.sheet, 'threshold': plan['threshold'],
                       'margin': plan['margin'], 'delay': plan['delay'], 'start_timeout': plan['start_timeout']}
        self.graph = Graph()
        self.refusals = RefusedConnections()
        logging.getLogger('rosout').addHandler(self.refusals)
        self.clock = ClockWatch()
        # Handles of the watch's own: an XML-RPC connection is never shared between two threads.
        watched, lookups = Graph(), rosgraph.Master(rospy.get_name())
        self.watch = NodeWatch(watched.student_nodes, lambda name: node_uri(lookups, name), node_pid).start()
        self.drone = Drone(self.sheet, clock=time.time, on_ticks=True)
        self.result['input_rates'] = dict(self.drone.rates)
        self.recorder = self.drone.output
        self.fixed_now = None
        #: How long after the last change the node's value is read (see set_inputs).
        self.settle = SETTLE_S
        self.t0 = time.time()
        self.flown = []  # [time, oracle value] at every input change, for the flight plot's trace

    # --- helpers ------------------------------------------------------------------------------------

    def resolved(self, name):
        return rospy.resolve_name(name)

    def set_inputs(self, fixed, moving):
        """Change the inputs (the fixed one only when it changes, as a real drone's would); return the
        time of the first reading of the new values (the later input's next tick)."""
        drone = self.drone
        changed = None
        self.settle = SETTLE_S
        if fixed != self.fixed_now:
            changed = drone.feeder.set(drone.fixed_topic, fixed)
            self.fixed_now = fixed
            # A node that computes on each reading publishes a mixed pair in between (new fixed, old
            # moving); one that waits for a fresh reading of each follows up to the slowest period later.
            self.settle = max(SETTLE_S, 1.0 / min(drone.rates.values()) + SETTLE_SLACK_S)
        since = drone.feeder.set(drone.moving_topic, moving)
        since = max(since, changed or since)
        self.flown.append([since, drone.expected(fixed, moving)])
        return since

    def fly(self, x):
        """Put the drone where the oracle's value is ``x`` (reference fixed input); return the time."""
        return self.set_inputs(self.drone.fixed_value, self.drone.input_for(x))

    # --- phases -------------------------------------------------------------------------------------

    def wait_for_node(self):
        nodes = wait_until(lambda: self.graph.student_nodes() or None, self.plan['start_timeout'], period=0.1)
        self.result['nodes'] = nodes or []
        self.result['node_seen_s'] = None if not nodes else time.time() - self.t0
        if not nodes:
            return False
        inputs = [self.resolved(t) for t in (self.drone.fixed_topic, self.drone.moving_topic)]
        wait_until(lambda: all(self.graph.subscribers(t) for t in inputs), SUBSCRIBE_S, period=0.1)
        self.result['subscribed'] = {t: self.graph.subscribers(t) for t in inputs}
        self.result['input_types'] = self.input_types(
            dict(zip(inputs, (self.drone.fixed_topic, self.drone.moving_topic))))
        return True

    def input_types(self, inputs, timeout=3.0):
        """{input topic: {"type" the node subscribed with, "connected", "refused", "adapted"}}: a
        subscription rospy refused (another type than the drone's) shows as no connection and a refusal
        in our log. Waits up to ``timeout`` s for each subscribed input to connect or be refused.

        A refused input the node asked for as another numeric std_msgs type is then published in that
        type (``adapted``: the type, once the node connected to it), as a teacher would change one word to
        see the rest work: the wrong type costs question 10 alone, not the values and the warning too.

        :param inputs: {resolved input topic: the feeder's name of it}."""
        feeder = self.drone.feeder

        def settled():
            return all(not self.graph.subscribers(t) or feeder.connections(name) > 0 or t in self.refusals.refused()
                       for t, name in inputs.items())
        wait_until(settled, timeout, period=0.1)
        refused = self.refusals.refused()
        adapted = {t: refused[t]['wanted'] for t in inputs
                   if t in refused and refused[t]['wanted'] in VALUE_TYPES and refused[t]['wanted'] != 'std_msgs/Float32'}
        # The node's subscriber may still hold the refused connection when the master tells it of the new
        # publisher (rospy then skips a publisher it thinks it is connected to): a publisher not
        # connected within RETYPE_S is registered anew, until SUBSCRIBE_S.
        deadline = time.time() + SUBSCRIBE_S
        waiting = sorted(adapted)
        while waiting and time.time() < deadline:
            for topic in waiting:
                feeder.retype(inputs[topic], VALUE_TYPES[adapted[topic]])
            wait_until(lambda: all(feeder.connections(inputs[t]) > 0 for t in waiting),
                       min(RETYPE_S, max(0.0, deadline - time.time())), period=0.05)
            waiting = [t for t in waiting if feeder.connections(inputs[t]) == 0]
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

    def find_output(self):
        expected = self.resolved(self.plan['output'])
        found = wait_until(lambda: expected in self._student_publications(), OUTPUT_S, period=0.1)
        publications = self._student_publications()
        output = {'expected': expected, 'topic': None, 'type': None,
                  'candidates': sorted(publications)}
        if found:
            output.update(topic=expected, type=publications[expected])
        else:
            candidates = sorted(t for t, kind in publications.items() if kind in VALUE_TYPES)
            preferred = [t for t in candidates if self.plan['output'][:3] in t.lower()] or candidates
            if preferred:
                output.update(topic=preferred[0], type=publications[preferred[0]])
        self.result['output'] = output
        topic, kind = output['topic'], output['type']
        if topic is not None and (topic != expected or kind != 'std_msgs/Float32') and kind in VALUE_TYPES:
            self.recorder.close()
            self.recorder = TopicRecorder(topic, msg_type=VALUE_TYPES[kind], clock=time.time)
        elif topic is not None and kind not in VALUE_TYPES:
            self.recorder = None  # a type the probe cannot read values from
        return topic is not None and self.recorder is not None

    def _student_publications(self):
        publications = {}
        for info in self.graph.summary().values():
            for topic, kind in info['publishes']:
                if topic not in IGNORED_TOPICS:
                    publications[topic] = kind
        return publications

    def formula(self):
        """Question 11's check points: (fixed input, oracle value) pairs; returns the calibration points."""
        drone, threshold, margin = self.drone, self.plan['threshold'], self.plan['margin']
        other_fixed = {'altitude': -5.0, 'depth': 90000.0}[self.sheet]
        cases = [(drone.fixed_value, threshold - 2 * margin), (drone.fixed_value, threshold + 2 * margin),
                 (other_fixed, threshold)]
        points, rows = [], []
        # The value before the first change, so that a node that follows a reading later is waited for.
        before = _last_value(self.recorder, 0.0)[0]
        # The fixed input sent again at its next tick: the node's subscription may have connected after
        # its last reading (a publisher registered anew in the node's type), and it reads it once a period.
        self.fixed_now = None
        for fixed, x in cases:
            if self.sheet == 'altitude':
                moving = oracle.pressure_at(x, fixed)
            else:
                moving = oracle.pressure_robot_at(x, fixed)
            since = self.set_inputs(fixed, moving)
            value, count = _settled(self.recorder, since, before, self.settle)
            before = value
            rows.append({'inputs': {drone.fixed_topic: fixed, drone.moving_topic: moving},
                         'expected': drone.expected(fixed, moving), 'published': value, 'samples': count})
            if fixed == drone.fixed_value:
                points.append((x, value))
        self.result['formula'] = rows
        return points

    def calibrate(self, points):
        """Oracle values ``lo`` / ``hi`` where the node's own value is ``margin`` below / above the
        threshold: fits value = a*x + b through the check points, flies there, corrects with the
        fitted slope (twice at most). Falls back to the oracle's values when that fails."""
        threshold, margin = self.plan['threshold'], self.plan['margin']
        targets = {'lo': threshold - margin, 'hi': threshold + margin, 'near': threshold - NEAR_M}
        # How close to its target each value must come: the near one just below the threshold.
        close = {'lo': lambda v, t: abs(v - t) < margin / 3, 'hi': lambda v, t: abs(v - t) < margin / 3,
                 'near': lambda v, t: threshold - NEAR_MAX_M <= v <= threshold}
        calibration = {'by': 'oracle', 'reason': '', 'fit': None}
        usable = [(x, y) for x, y in points if y is not None and math.isfinite(y)]
        if self.recorder is None or len(usable) < 2:
            calibration['reason'] = 'no readable output: flying by the oracle\'s values'
        else:
            (x1, y1), (x2, y2) = usable[:2]
            a = (y2 - y1) / (x2 - x1)
            if not math.isfinite(a) or abs(a) < 1e-3:
                calibration['reason'] = ('the output hardly depends on the input (slope %.3g): flying by '
                                         'the oracle\'s values' % a)
            else:
                calibration.update(by='own', fit=[a, y1 - a * x1])
        chosen = {}
        for side, target in sorted(targets.items()):
            x = target
            if calibration['by'] == 'own':
                a, b = calibration['fit']
                x = (target - b) / a
            value = None
            for _ in range(4 if side == 'near' else 3):
                previous = _last_value(self.recorder, 0.0)[0] if self.recorder is not None else None
                since = self.fly(x)
                value = _settled(self.recorder, since, previous, self.settle)[0] if self.recorder is not None else None
                if calibration['by'] != 'own' or value is None or not math.isfinite(value) \
                        or close[side](value, target):
                    break
                x += (target - value) / calibration['fit'][0]
            chosen[side] = {'x': x, 'target': target, 'value': value}
        own_ok = all(v['value'] is not None and math.isfinite(v['value']) for v in chosen.values()) \
            and chosen['lo']['value'] <= threshold < chosen['hi']['value'] and chosen['near']['value'] <= threshold
        if calibration['by'] == 'own' and not own_ok:
            calibration.update(by='oracle', fit=None, reason=(
                'the node\'s values did not come out on both sides of the threshold (%s): flying by the '
                'oracle\'s values' % ', '.join('%s %r' % (k, v['value']) for k, v in sorted(chosen.items()))))
            chosen = {side: {'x': target, 'target': target, 'value': None} for side, target in targets.items()}
        calibration.update(chosen)
        self.result['calibration'] = calibration
        return chosen['lo']['x'], chosen['hi']['x'], chosen['near']['x']

    def leg(self, x, side, hold, late=0.0, late_from=None):
        """Fly at ``x`` for ``hold`` s counted from the node's own first value on ``side`` (the input's
        change when the output cannot be read, or when that value never comes within REACH_S); with
        ``late``, keep flying while the node still owes this side's call (:func:`owes`), up to ``late``
        s after ``late_from`` (default: that first value). Returns ``(the input's change, that first
        value's time)``."""
        since = self.fly(x)
        start = since
        if self.recorder is not None:
            threshold = self.plan['threshold']
            reached = wait_until(lambda: next((t for t, v in self.recorder.samples(since)
                                               if on_side(v, threshold, side)), None), REACH_S, period=0.05)
            start = reached if reached is not None else since
        time.sleep(max(0.0, start + hold - time.time()))
        deadline = (start if late_from is None else late_from) + late
        if late > 0 and deadline > time.time():
            wait_until(lambda: not owes(self.drone.service.calls(), side, since) or not self.graph.student_nodes(),
                       deadline - time.time(), period=0.1)
        return since, start

    def flight(self, lo, hi, near):
        delay = self.plan['delay']
        late = self.plan.get('late_warning', 0.0)
        late_normal = normal_wait(delay, self.drone.rates)
        schedule = {}
        schedule['rest'] = self.leg(lo, 'below', REST_S, late_normal)[0]
        schedule['short_up'] = self.leg(hi, 'above', SHORT_S)[0]
        schedule['short_down'] = self.leg(near, 'below', GAP_S)[0]
        schedule['long_up'] = self.leg(hi, 'above', delay + AFTER_S, late)[0]
        schedule['long_down'], back = self.leg(near, 'below', BACK_S)
        schedule['deep_down'] = self.leg(lo, 'below', DEEP_S, late_normal, late_from=back)[0]
        schedule['end'] = time.time()
        self.result['schedule'] = schedule
        self.result['legs'] = self.legs(schedule, FLIGHT_LEGS)
        if self.recorder is not None:
            samples = self.recorder.samples(schedule['rest'], schedule['end'])
            rate = {'samples': len(samples), 'hz': None, 'max_gap': None}
            if len(samples) >= 2:
                span = samples[-1][0] - samples[0][0]
                rate['hz'] = (len(samples) - 1) / span if span > 0 else None
                rate['max_gap'] = max(b[0] - a[0] for a, b in zip(samples, samples[1:]))
                values = [v for _, v in samples]
                rate['non_finite'] = len([v for v in values if not math.isfinite(v)])
            self.result['rate'] = rate

    def legs(self, schedule, names):
        """Each leg checked on the node's own values (None when the output cannot be read)."""
        if self.recorder is None:
            return None
        keys = sorted(schedule, key=schedule.get)
        out = {}
        for name in names:
            end = schedule[keys[keys.index(name) + 1]]
            side = 'above' if name.endswith('up') or name == 'step' else 'below'
            out[name] = leg_check(self.recorder.samples(schedule[name]), self.plan['threshold'], side,
                                  schedule[name], end)
        return out

    def threshold_check(self):
        """Question 14a: the node restarted with its launch file's threshold changed to a value drawn at
        grading time, flown exactly as the main run (issue 36 point 7: a node cannot tell the two runs
        apart but by the threshold its launch file gave it) around that value, whose long excursion
        stays below the launch file's threshold. A WARNING that came late in the main run
        (``warn_after``) is waited for that long, no longer: a node that ignores the new value costs
        the long excursion, not the late window."""
        warn_after = self.plan.get('warn_after')
        if warn_after is not None:
            self.plan['late_warning'] = min(self.plan.get('late_warning', 0.0),
                                            max(warn_after, self.plan['delay']) + AFTER_S)
        self.main_flight()

    def main_flight(self):
        # Inputs from the start: a node that waits for data before it subscribes to the rest still runs.
        self.fly(self.plan['threshold'] - self.plan['margin'])
        if self.wait_for_node():
            readable = self.find_output()
            points = self.formula() if readable else []
            self.flight(*self.calibrate(points))

    def run(self):
        if self.plan['kind'] == 'main':
            self.main_flight()
        else:
            self.threshold_check()
        self.result['node_watch'] = self.watch.stop()
        self.result['calls'] = [[t, s] for t, s in self.drone.service.calls()]
        self.result['answers'] = [[t, s, ok, message] for t, s, ok, message in self.drone.service.answers()]
        self.result['graph'] = self.graph.summary()
        seen = self.result.get('input_types') or {}
        for info in self.result['graph'].values():  # the master gives the publisher's type, not the subscriber's
            for entry in info['subscribes']:
                if entry[0] in seen:
                    entry[1] = '%s%s' % (seen[entry[0]]['type'] or 'type unknown: no connection',
                                         ', refused by rospy' if seen[entry[0]]['refused'] else '')
        self.result['alive_at_end'] = bool(self.graph.student_nodes())
        self.result['t0'] = self.t0
        self.result['clock'] = self.clock.seen(self.graph)
        self.result['judge_uid'] = os.getuid()
        self.result['trace'] = trace(self.recorder.samples(self.t0) if self.recorder is not None else [], self.flown)
        return self.result


#: The flight plot's trace keeps one published value per this many s (the node's 10 Hz).
TRACE_PERIOD_S = 0.09


def trace(samples, flown, period=TRACE_PERIOD_S):
    """The flight for the teacher's plot (not for scoring): ``{"published": [[t, value]] at most one
    sample per ``period`` (non-finite values as None), "oracle": [[t, value]] (the oracle's value from t
    on)}``, wall-clock times like the calls and the schedule."""
    kept, last = [], None
    for t, v in samples:
        if last is None or t - last >= period:
            kept.append([round(t, 3), round(v, 3) if math.isfinite(v) else None])
            last = t
    return {'published': kept, 'oracle': [[round(t, 3), round(x, 3)] for t, x in flown]}


#: Most seconds the probe keeps the drone up after writing its result, waiting to be stopped.
LINGER_S = 60.0


def main(argv):
    """Measure, write the result (atomically), then keep the fake drone serving until stopped
    (SIGINT) or LINGER_S: the student's node must not lose its drone before the grader stops it."""
    if len(argv) != 2:
        sys.stderr.write('usage: python3 -m exam_lab.grader.judge.probe PLAN.json RESULT.json\n')
        return 2
    with open(argv[0]) as f:
        plan = json.load(f)
    rospy.init_node('grader_probe', disable_signals=True)
    probe = Probe(plan)
    try:
        result = probe.run()
        with open(argv[1] + '.part', 'w') as f:
            json.dump(result, f, indent=1, sort_keys=True)
        os.rename(argv[1] + '.part', argv[1])
        time.sleep(LINGER_S)
    except KeyboardInterrupt:
        pass  # the session stopped us, after the student's node
    finally:
        probe.drone.close()
        rospy.signal_shutdown('probe done')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

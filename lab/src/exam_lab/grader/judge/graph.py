"""The ROS graph as the judge sees it, whatever the student's node prints: the master's view of the
student's nodes and what they publish, the subscriptions rospy refused the probe (another type than
the drone's), who set ``/use_sim_time`` or published ``/clock``, and each node's pid, watched for a
death or a restart. Run in the probe's rospy process (:mod:`exam_lab.grader.judge.probe`).
"""
import ast
import logging
import re
import threading
import time
import xmlrpc.client

import rosgraph
import rospy
from rosgraph_msgs.msg import Clock

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

    def launch_started(self):
        """Whether roslaunch is up on this master: it sets ``/roslaunch/uris/<host>__<port>`` once its
        own server runs, right before it sets the launch file's parameters and starts the nodes
        (roslaunch/launch.py, ``_launch_master``). Each run has a master of its own, so the parameter is
        this run's roslaunch's."""
        try:
            return any(name.startswith('/roslaunch/uris/') for name in self._master.getParamNames())
        except Exception:  # the master answers; a failure is a transient of the XML-RPC call
            return False

    def publishers(self, topic):
        """Every node that publishes ``topic``, this probe included."""
        return sorted(dict(self._state()[0]).get(topic, []))

    def subscribers(self, topic):
        names = dict(self._state()[1]).get(topic, [])
        return sorted(n for n in names if n in self.student_nodes())

    def publications(self):
        """{topic: type} of everything the student's nodes publish, but topics every node has."""
        publications = {}
        for info in self.summary().values():
            for topic, kind in info['publishes']:
                if topic not in IGNORED_TOPICS:
                    publications[topic] = kind
        return publications


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


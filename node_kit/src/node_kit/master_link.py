"""Keeps a rospy node registered with its master across a master restart (issue 13).

ROS 1 nodes register with the master once: rospy never registers again, so after the master is killed
and started again on the same port (a ground-station laptop that crashed) the node runs on, its
existing connections keep flowing, but nobody can find it any more: no new subscriber, no service
lookup, no ``rosnode list``, and its parameters are gone. :func:`start` runs a daemon thread that asks
the master whether it is the master the node registered with and still knows the node (one multicall
of ``getPid`` and ``lookupNode`` of its own name, with a short socket timeout: its cost does not grow
with the graph, see :mod:`node_kit.outage`), and follows :class:`node_kit.outage.MasterWatch`. It
asks over a connection it keeps open (:mod:`node_kit.master_line`): a second after start, the instant the
master's end closes that connection, once a second while the master is unreachable, and otherwise
only every ``HEARTBEAT_S`` seconds, so a master that lives is almost never asked:

- master unreachable: one warning for the whole outage; the node keeps running;
- master answers but does not know the node, or has another pid (it restarted): the node's private
  parameters are set again with the values it read at start-up (so ``rosparam get /exam/threshold`` is right
  again and a tool that reads them sees what the node runs with), then every publication, subscription
  and service is registered again, as rospy's ``RegManager.start`` does at start-up, and each
  subscription is told of the publishers the master returns (through the node's own XML-RPC
  ``publisherUpdate``, the call a master makes); one info line says what was re-registered. The
  topics are those the node's own XML-RPC API lists (``getPublications``, ``getSubscriptions``); the
  services, which that API does not list, come from rospy's registry
  (:func:`node_kit.rospy_private.served_services`).

The link's state (up; down since; re-registered when, how many times) is the node's "<node>: master"
status on /diagnostics, WARN while the master is down: a task of the node's one Updater
(:meth:`MasterLink.fill_status`), published with the node's other statuses.

Two things rospy does that a master outage (or a peer's stop) turns into tracebacks in the node's log
file, both settled here (:func:`quiet_master_outages`): rospy's rosout handler reads a parameter with
``get_param_cached`` at every log line, and an unset parameter is never cached, so each read is a
``subscribeParam`` call to the master ("Unable to report rosout" and a traceback while it is down; a
cost on the master while it is up): it is read once at start and put in rospy's cache. rosgraph's
XML-RPC server and rospy's connection threads log a traceback when a peer goes away mid-request (a
master killed while it tells the node of a publisher, a node that stops while this one connects to
it): one line instead, with the error.

:func:`open_persistent` serves the other side of a master outage: a service client whose connection
is open before it is needed calls the service without asking the master.

rospy's private names used (the services' registry, the parameter cache, a persistent proxy's
connection) are all in :mod:`node_kit.rospy_private`, each with why no public API does it. The calls
to the master are plain XML-RPC with a socket timeout, not rospy's master proxy, whose calls wait
forever. Not restored: rospy's parameter subscriptions (``get_param_cached``); nothing of ours relies
on them.

No ROS parameters, topics or services of its own.
"""
import logging
import socket
import threading
import time
import xmlrpc.client

import rosgraph
import rospy
from diagnostic_msgs.msg import DiagnosticStatus

from node_kit import rospy_private
from node_kit.master_line import MasterLine
from node_kit.outage import REREGISTER, UNREACHABLE, MasterWatch, classify

#: Seconds between two polls of the master.
POLL_PERIOD_S = 1.0
#: Seconds between two polls while the master is up and the connection to it held (see
#: :mod:`node_kit.master_line`): only a master that hangs, its connection open, waits for one; it is
#: noticed within HEARTBEAT_S + CALL_TIMEOUT_S. Each poll costs the master about 0.4 ms of CPU in a
#: fleet; measured with 100 pairs (200 nodes) on one master, its CPU was 11.2 % of a core at 1 s,
#: 5.5 % at 2 s and 3.2 % at 5 s (docs/benchmarks.md).
HEARTBEAT_S = 2.0
#: Socket timeout of every call to the master [s]: a master that hangs must not stop the polling.
CALL_TIMEOUT_S = 2.0
#: Caller id of the node's call to its own publisherUpdate (what a master would send).
MASTER_CALLER_ID = '/master'
#: Parameters rospy reads with get_param_cached at every log line (its rosout handler), with the
#: default it uses when they are unset.
CACHED_PARAMS = (('/rosout_disable_topics_generation', False),)
#: Errors that say a peer went away (refused, reset, cut before rospy's handshake): rosgraph's XML-RPC
#: server and rospy's connection threads log them with a traceback.
DROPPED = ('ConnectionResetError', 'ConnectionRefusedError', 'BrokenPipeError', 'ConnectionAbortedError',
           'ROSHandshakeException', 'TransportInitError')
#: The loggers whose tracebacks of a peer that went away become one line.
PEER_LOGGERS = ('xmlrpc', 'rospy.internal')
#: diagnostic_updater's levels of MasterWatch.status().
LEVELS = {'ok': DiagnosticStatus.OK, 'warn': DiagnosticStatus.WARN}


class _TimeoutTransport(xmlrpc.client.Transport):
    """xmlrpc transport whose connections time out (rospy's proxies wait forever)."""

    def __init__(self, timeout):
        xmlrpc.client.Transport.__init__(self)
        self._timeout = timeout

    def make_connection(self, host):
        connection = xmlrpc.client.Transport.make_connection(self, host)
        connection.timeout = self._timeout
        return connection


def _proxy(uri):
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(CALL_TIMEOUT_S))


class MasterError(Exception):
    """The master answered a call with an error code (an unknown service, a refused registration)."""


def _value(call, what):
    """The value of an XML-RPC ``(code, message, value)`` answer; MasterError unless code 1."""
    code, message, value = call
    if code != 1:
        raise MasterError('%s: %s' % (what, message))
    return value


class MasterLink(object):
    """The polling thread of one node; see the module docstring. Create it with :func:`start`."""

    def __init__(self, updater, poll_period=POLL_PERIOD_S, heartbeat=HEARTBEAT_S):
        self._master_uri = rosgraph.get_master_uri()
        self._name = rospy.get_name()
        self._node_uri = rospy.get_node_uri()
        self._namespace = rospy.resolve_name('~').rstrip('/')
        # The node has read its parameters by now: these are the values it runs with (read at the
        # first poll if the master went away meanwhile).
        self._params = _private_params()
        self._watch = MasterWatch(self._master_uri, self._name)
        self._known_pid = None  # pid of the master the node is registered with, once seen
        updater.add('master', self.fill_status)
        self._poll_period = poll_period
        self._heartbeat = heartbeat
        self._line = MasterLine(self._master_uri, CALL_TIMEOUT_S)
        # stop() writes to one end to end the thread's wait at once.
        self._wake_in, self._wake_out = socket.socketpair()
        # Held for a whole poll: stop() returns only once no poll runs, so that rospy's unregistration
        # at shutdown (which follows the on_shutdown hooks) is never undone by a re-registration.
        self._lock = threading.Lock()
        # Guards the watch between the polling thread and the diagnostics timer (the poll's lock is
        # held across calls to the master: the status must not wait for them).
        self._lock_status = threading.Lock()
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._run, name='master_link')
        self._thread.daemon = True

    def start(self):
        self._thread.start()

    def stop(self):
        self._stopped.set()
        try:
            self._wake_out.send(b'!')
        except OSError:  # the thread ended already and closed its end
            pass
        with self._lock:
            pass
        self._wake_out.close()

    def _run(self):
        try:
            delay = self._poll_period
            while True:
                # Returns early when the master's end closes the held connection: ask it at once.
                self._line.wait(delay, self._wake_in)
                with self._lock:
                    if self._stopped.is_set() or rospy_private.shutdown_begun():
                        return
                    try:
                        self._poll()
                    except Exception as err:  # this thread must outlive anything; say what went wrong
                        rospy.logerr_throttle(60.0, 'master link: unexpected %s: %s'
                                              % (type(err).__name__, err))
                # Up, on a held connection: its closing is the news, a heartbeat covers a hung master.
                delay = self._heartbeat if self._line.held() else self._poll_period
        finally:
            self._line.close()
            self._wake_in.close()

    def _poll(self):
        try:
            pid, node = self._line.multicall([('getPid', [self._name]),
                                              ('lookupNode', [self._name, self._name])])
        except Exception as err:  # refused, reset, timeout, HTTP error: no usable master
            self._tell(self._watch.observe, UNREACHABLE, time.time(), _describe(err))
            return
        pid = pid[2] if pid and pid[0] == 1 else None
        answer = classify(pid, node[2] if node and node[0] == 1 else None, self._known_pid)
        action = self._tell(self._watch.observe, answer, time.time())
        if action != REREGISTER:
            if self._known_pid is None:
                self._known_pid = pid
            if self._params is None:
                self._params = _private_params()
            return
        try:
            counts = self._reregister(_proxy(self._master_uri))
        except Exception as err:
            self._tell(self._watch.reregister_failed, time.time(), _describe(err))
        else:
            self._known_pid = pid
            self._tell(self._watch.reregistered, time.time(), *counts)

    def fill_status(self, stat):
        """Fill ``stat`` with the link's state (the Updater's "master" task)."""
        with self._lock_status:
            level, summary, values = self._watch.status(time.time())
        for key, value in values:
            stat.add(key, value)
        stat.summary(LEVELS[level], summary)
        return stat

    def _tell(self, method, *args):
        """Give the watch one observation (``method(*args)``); log and return what it decided."""
        with self._lock_status:
            action, level, message = method(*args)
        if level == 'warn':
            rospy.logwarn(message)
        elif level == 'info':
            rospy.loginfo(message)
        return action

    def _reregister(self, master):
        """Register parameters, publications, subscriptions and services again; return their counts."""
        caller, uri = self._name, self._node_uri
        params = self._params or {}
        # Parameters first: whoever finds the node through the master then finds its parameters too.
        for key, value in sorted(params.items()):
            _value(master.setParam(caller, self._namespace + '/' + key, value), 'setParam %s' % key)
        node = _proxy(uri)
        publications = _value(node.getPublications(caller), 'getPublications')
        subscriptions = _value(node.getSubscriptions(caller), 'getSubscriptions')
        served = rospy_private.served_services()
        for topic, data_type in publications:
            _value(master.registerPublisher(caller, topic, data_type, uri), 'registerPublisher %s' % topic)
        for topic, data_type in subscriptions:
            publishers = _value(master.registerSubscriber(caller, topic, data_type, uri),
                                'registerSubscriber %s' % topic)
            if publishers:
                # Connects to publishers it does not know yet; existing connections are kept.
                _value(node.publisherUpdate(MASTER_CALLER_ID, topic, publishers),
                       'publisherUpdate %s' % topic)
        for service, service_uri in served:
            _value(master.registerService(caller, service, service_uri, uri), 'registerService %s' % service)
        return len(publications), len(subscriptions), len(served), len(params)


def _private_params():
    """The node's private parameters, asked of the master itself, or None when it cannot be asked now.

    Not ``rospy.get_param('~')``: that answers from rospy's parameter cache when the cache holds any
    key of the node's namespace (one that rospy or a library read with ``get_param_cached``).
    """
    try:
        return _value(_proxy(rosgraph.get_master_uri()).getParam(rospy.get_name(),
                                                                  rospy.resolve_name('~')), 'getParam ~')
    except Exception:  # the master went away: the first poll that reaches it reads them
        return None


class _PeerGone(logging.Filter):
    """Turns the traceback of a peer that went away into one line: what was tried, and the error.

    A node that stops (or a master that is killed) while another connects to it is an ordinary event
    of a ROS graph: rospy reports it and retries or gives up, correctly; only the stack is noise. So
    is any error of a connection being set up while this node stops: rospy closes the socket under
    its own connecting thread (an AttributeError on the socket it just set to None).
    """

    def filter(self, record):
        text = record.getMessage()
        head, found, rest = text.partition('Traceback (most recent call last)')
        if found:
            last = rest.strip().splitlines()[-1]
            if last.split(':')[0].split('.')[-1] in DROPPED or rospy_private.shutdown_begun():
                record.msg, record.args = '%s%s' % (head or 'connection closed by its peer: ', last), ()
        return True


def quiet_master_outages():
    """Keep rospy from calling the master at every log line and from logging a dropped peer as a
    traceback (see the module docstring). Call right after ``init_node``, before the node logs."""
    try:
        for key, default in CACHED_PARAMS:
            rospy_private.cache_param(key, rospy.get_param(key, default))
    except Exception:  # the master went away already: rospy asks it again later, as it always did
        pass
    for name in PEER_LOGGERS:
        logging.getLogger(name).addFilter(_PeerGone())


def _describe(err):
    return '%s: %s' % (type(err).__name__, err)


def start(updater, poll_period=POLL_PERIOD_S):
    """Start watching the master for the running node (call it once the node is built, its parameters
    read); returns the :class:`MasterLink`, whose ``stop`` must run before rospy unregisters the node
    (:func:`node_kit.lifecycle.run` calls it from the node's first shutdown hook).

    :param updater: the node's diagnostic_updater.Updater: the link adds its "master" status to it.
    """
    link = MasterLink(updater, poll_period)
    link.start()
    return link


def open_persistent(name, service_class):
    """A persistent ``rospy.ServiceProxy`` to the service ``name``, its connection open already, and
    the service's URI: ``(proxy, uri)``.

    rospy opens a persistent proxy's connection at its first call, through the master; opened here
    when the service is found, it carries every later call without the master, as long as the serving
    process lives. A call on it that raises means the connection broke: close the proxy and open a
    new one.

    :raises Exception: the master is unreachable, does not know the service, or the service does not
        accept the connection.
    """
    proxy = rospy.ServiceProxy(name, service_class, persistent=True)
    uri = _value(_proxy(rosgraph.get_master_uri()).lookupService(rospy.get_name(), proxy.resolved_name),
                 'lookupService %s' % proxy.resolved_name)
    rospy_private.connect_persistent(proxy, uri)
    return proxy, uri

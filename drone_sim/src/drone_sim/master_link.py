"""Keeps a rospy node registered with its master across a master restart (issue 13).

ROS 1 nodes register with the master once: rospy never registers again, so after the master is killed
and started again on the same port (a ground-station laptop that crashed) the node runs on, its
existing connections keep flowing, but nobody can find it any more: no new subscriber, no service
lookup, no ``rosnode list``, and its parameters are gone. :func:`start` runs a daemon thread that asks
the master about once a second whether it lists every publication, subscription and service of this
node (``getSystemState``, with a short socket timeout), and follows
:class:`drone_sim.outage.MasterWatch`:

- master unreachable: one warning for the whole outage; the node keeps running;
- master answers but misses registrations of the node (it restarted): the node's private parameters
  are set again with the values it read at start-up (so ``rosparam get /exam/threshold`` is right
  again and a tool that reads them sees what the node runs with), then every publication, subscription
  and service is registered again, as ``rospy.impl.registration.RegManager.start`` does at start-up, and
  each subscription is told of the publishers the master returns (through the node's own XML-RPC
  ``publisherUpdate``, the call a master makes); one info line says what was re-registered.

:func:`open_persistent` serves the other side of a master outage: a service client whose connection
is open before it is needed calls the service without asking the master.

rospy internals used, all here (python3-rospy 1.15.15 of Debian 12; the same in ROS Noetic's 1.16):
the topic and service managers of ``rospy.impl.registration`` and their ``get_publications``,
``get_subscriptions`` and ``get_services`` (the lists RegManager.start registers); a ServiceProxy's
``protocol``, ``buff_size`` and ``transport``, and ``rospy.impl.tcpros_base.TCPROSTransport`` (what
``ServiceProxy.call`` does to open a persistent connection). Not restored: rospy's parameter
subscriptions (``get_param_cached``); nothing of ours relies on them.

No ROS parameters, topics or services of its own.
"""
import threading
import time
import xmlrpc.client

import rosgraph
import rospy
from rospy.impl import registration
from rospy.impl.tcpros_base import TCPROSTransport

from drone_sim.outage import (KNOWN, REREGISTER, UNKNOWN, UNREACHABLE, MasterWatch,
                               missing_registrations)

#: Seconds between two polls of the master.
POLL_PERIOD_S = 1.0
#: Socket timeout of every call to the master [s]: a master that hangs must not stop the polling.
CALL_TIMEOUT_S = 2.0
#: Caller id of the node's call to its own publisherUpdate (what a master would send).
MASTER_CALLER_ID = '/master'


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

    def __init__(self, poll_period=POLL_PERIOD_S):
        self._master_uri = rosgraph.get_master_uri()
        self._name = rospy.get_name()
        self._node_uri = rospy.get_node_uri()
        self._namespace = rospy.resolve_name('~').rstrip('/')
        # The node has read its parameters by now: these are the values it runs with.
        self._params = rospy.get_param('~', {})
        self._watch = MasterWatch(self._master_uri, self._name)
        self._poll_period = poll_period
        # Held for a whole poll: stop() returns only once no poll runs, so that rospy's unregistration
        # at shutdown (which follows the on_shutdown hooks) is never undone by a re-registration.
        self._lock = threading.Lock()
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._run, name='master_link')
        self._thread.daemon = True

    def start(self):
        self._thread.start()

    def stop(self):
        self._stopped.set()
        with self._lock:
            pass

    def _run(self):
        while not self._stopped.wait(self._poll_period):
            with self._lock:
                if self._stopped.is_set() or rospy.core.is_shutdown_requested():
                    return
                try:
                    self._poll()
                except Exception as err:  # this thread must outlive anything; say what went wrong
                    rospy.logerr_throttle(60.0, 'master link: unexpected %s: %s'
                                          % (type(err).__name__, err))

    def _poll(self):
        master = _proxy(self._master_uri)
        topics, services = registration.get_topic_manager(), registration.get_service_manager()
        # Taken before the master is asked: a registration made meanwhile is not counted as lost.
        ours = ([name for name, _ in topics.get_publications()],
                [name for name, _ in topics.get_subscriptions()],
                [name for name, _ in services.get_services()])
        try:
            state = _value(master.getSystemState(self._name), 'getSystemState')
        except Exception as err:  # refused, reset, timeout, HTTP error: no usable master
            self._act(self._watch.observe(UNREACHABLE, time.time(), _describe(err)))
            return
        lost = missing_registrations(state, self._name, *ours)
        action = self._act(self._watch.observe(UNKNOWN if lost else KNOWN, time.time()))
        if action == REREGISTER:
            try:
                counts = self._reregister(master)
            except Exception as err:
                self._act(self._watch.reregister_failed(time.time(), _describe(err)))
            else:
                self._act(self._watch.reregistered(time.time(), *counts))

    @staticmethod
    def _act(decision):
        action, level, message = decision
        if level == 'warn':
            rospy.logwarn(message)
        elif level == 'info':
            rospy.loginfo(message)
        return action

    def _reregister(self, master):
        """Register parameters, publications, subscriptions and services again; return their counts."""
        caller, uri = self._name, self._node_uri
        # Parameters first: whoever finds the node through the master then finds its parameters too.
        for key, value in sorted(self._params.items()):
            _value(master.setParam(caller, self._namespace + '/' + key, value), 'setParam %s' % key)
        topics, services = registration.get_topic_manager(), registration.get_service_manager()
        publications, subscriptions = topics.get_publications(), topics.get_subscriptions()
        served = services.get_services()
        for topic, data_type in publications:
            _value(master.registerPublisher(caller, topic, data_type, uri), 'registerPublisher %s' % topic)
        node = _proxy(uri)
        for topic, data_type in subscriptions:
            publishers = _value(master.registerSubscriber(caller, topic, data_type, uri),
                                'registerSubscriber %s' % topic)
            if publishers:
                # Connects to publishers it does not know yet; existing connections are kept.
                _value(node.publisherUpdate(MASTER_CALLER_ID, topic, publishers),
                       'publisherUpdate %s' % topic)
        for service, service_uri in served:
            _value(master.registerService(caller, service, service_uri, uri), 'registerService %s' % service)
        return len(publications), len(subscriptions), len(served), len(self._params)


def _describe(err):
    return '%s: %s' % (type(err).__name__, err)


def start(poll_period=POLL_PERIOD_S):
    """Start watching the master for the running node (call it once the node is built, its parameters
    read); returns the :class:`MasterLink`, stopped by rospy's shutdown before it unregisters."""
    link = MasterLink(poll_period)
    link.start()
    rospy.on_shutdown(link.stop)
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
    host, port = rospy.core.parse_rosrpc_uri(uri)
    # As ServiceProxy.call does for its first call (tcpros_service.py).
    transport = TCPROSTransport(proxy.protocol, proxy.resolved_name)
    transport.buff_size = proxy.buff_size
    try:
        transport.connect(host, port, uri)
    except Exception:
        transport.close()
        raise
    proxy.transport = transport
    return proxy, uri

"""Every use of rospy's private names in this project: one function each, and why no public API does it.

Read from python3-rospy 1.15.15 of Debian 12 (``/usr/lib/python3/dist-packages/rospy``). ROS 1's last
release is frozen, so these will not move under us; still, each function is held to the installed
rospy by a test of its own (``node_kit/test/unit/test_rospy_private.py``), which fails if the name or
the behaviour relied upon changes. Nothing else in the repository touches
``rospy.impl``, ``rospy.core`` or a private name of rospy (``lab/test/unit/test_layers.py`` checks it).

Used by :mod:`node_kit.lifecycle` (a node's stop) and :mod:`node_kit.master_link` (a master restart).
"""
import rospy
# rospy 1.15.15: the parameter cache, the registry of the services this process serves, and the client
# end of a TCPROS connection (rospy/impl/paramserver.py, registration.py, tcpros_base.py).
from rospy.impl import paramserver, registration
from rospy.impl.tcpros_base import TCPROSTransport


def shutdown_begun():
    """True from the instant rospy's shutdown begins (``signal_shutdown``), hooks included.

    rospy 1.15.15, ``rospy.core.is_shutdown_requested`` (not exported by ``rospy``): the public
    ``rospy.is_shutdown()`` turns true only after the shutdown hooks have run and every publisher is
    closed, too late to tell a stop from a failure while the node starts.
    """
    return rospy.core.is_shutdown_requested()


def raise_shutdown_flag():
    """Make ``rospy.is_shutdown()`` true now, from a shutdown hook, before rospy's pre-shutdown hooks.

    rospy 1.15.15, ``rospy.core._shutdown_flag``: ``signal_shutdown`` sets it only after its
    pre-shutdown hooks, and calling it again (the public way) returns at once while it runs. A topic
    created while the master is away retries its registration inside the topic manager's lock until
    ``is_shutdown()``; the pre-shutdown hook's ``close_all()`` waits for that lock, so without this the
    node hung until roslaunch's SIGKILL (see :func:`node_kit.lifecycle._stop`).
    """
    rospy.core._shutdown_flag = True


def cache_param(name, value):
    """Put ``name`` (resolved here) in rospy's parameter cache: ``rospy.get_param_cached`` answers it
    without asking the master.

    rospy 1.15.15, ``rospy.impl.paramserver.get_param_server_cache()``: ``get_param_cached`` caches only
    a parameter that is set on the master, and asks the master again at every read of one that is
    not (rospy's rosout handler reads ``/rosout_disable_topics_generation`` so at every log line).
    Setting the parameter on the master, the public way to get it cached, would show every user a
    parameter nobody set.
    """
    paramserver.get_param_server_cache().set(rospy.resolve_name(name), value)


def served_services():
    """``[(resolved name, rosrpc URI)]`` of every service this process serves.

    rospy 1.15.15, the service manager of ``rospy.impl.registration`` (what ``RegManager.start``
    registers at start-up). A node's public XML-RPC API lists its topics (``getPublications``,
    ``getSubscriptions``) but not its services, and the master that knew them is the one that restarted.
    """
    return registration.get_service_manager().get_services()


def connect_persistent(proxy, uri):
    """Open the connection of the persistent ``rospy.ServiceProxy`` ``proxy`` to the service at ``uri``
    (rosrpc), as its first call would: every call then goes over it, without the master.

    rospy 1.15.15, ``rospy.impl.tcpros_base.TCPROSTransport`` and the proxy's ``protocol``,
    ``buff_size`` and ``transport`` (as ``ServiceProxy.call`` does in rospy/impl/tcpros_service.py): a
    persistent proxy opens its connection at its first call only, through the master, and no public
    call opens it without calling the service, which would be one more request to the drone's LED.

    :raises Exception: the service does not accept the connection (closed again here).
    """
    host, port = rospy.parse_rosrpc_uri(uri)
    transport = TCPROSTransport(proxy.protocol, proxy.resolved_name)
    transport.buff_size = proxy.buff_size
    try:
        transport.connect(host, port, uri)
    except Exception:
        transport.close()
        raise
    proxy.transport = transport

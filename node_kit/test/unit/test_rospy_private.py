"""node_kit.rospy_private against the installed rospy: one test per private name, of the behaviour relied on.

Each test runs in a forked child (rospy's state is global to a process: a shutdown cannot be undone),
without a master, or with a stand-in that records what it was asked. A rospy that renamed or changed
one of these internals fails its test here rather than a node in flight.
"""
import os
import threading
from xmlrpc.server import SimpleXMLRPCServer

import pytest
import rospy
import rospy.impl.tcpros
from diagnostic_msgs.srv import AddDiagnostics, AddDiagnosticsResponse

from node_kit import rospy_private

#: No master listens here: a call to it is refused at once.
NO_MASTER = 'http://127.0.0.1:9/'


@pytest.fixture(autouse=True)
def no_master(monkeypatch):
    monkeypatch.setenv('ROS_MASTER_URI', NO_MASTER)


def _shutdown_seen_by_hooks():
    seen = []
    rospy.on_shutdown(lambda: seen.append(('client hook', rospy_private.shutdown_begun(),
                                           rospy.is_shutdown())))
    rospy.core.add_preshutdown_hook(lambda reason: seen.append(('pre-shutdown hook',
                                                                rospy_private.shutdown_begun(),
                                                                rospy.is_shutdown())))
    before = rospy_private.shutdown_begun()
    rospy.signal_shutdown('test')
    return before, seen


def test_shutdown_begun_is_true_in_the_hooks_while_is_shutdown_is_still_false(in_child):
    before, seen = in_child(_shutdown_seen_by_hooks)
    assert before is False
    assert seen == [('client hook', True, False), ('pre-shutdown hook', True, False)]


def _is_shutdown_in_the_pre_shutdown_hook():
    seen = []
    rospy.on_shutdown(rospy_private.raise_shutdown_flag)
    rospy.core.add_preshutdown_hook(lambda reason: seen.append(rospy.is_shutdown()))
    rospy.signal_shutdown('test')
    return seen


def test_the_flag_raised_by_a_client_hook_is_seen_by_the_pre_shutdown_hooks(in_child):
    # lifecycle._stop relies on it: the topic manager's registration retries end before close_all().
    assert in_child(_is_shutdown_in_the_pre_shutdown_hook) == [True]


def _cached_without_a_master():
    rospy_private.cache_param('/rosout_disable_topics_generation', True)
    return rospy.get_param_cached('/rosout_disable_topics_generation')


def test_a_cached_parameter_is_answered_without_asking_the_master(in_child):
    # Without the cache, get_param_cached asks the master, which refuses the connection here.
    assert in_child(_cached_without_a_master) is True


def _echo_service():
    # What init_node does for a service without a master: rospy's TCPROS server and its handlers.
    rospy.impl.tcpros.init_tcpros()
    return rospy.Service('/kit_echo', AddDiagnostics,
                         lambda request: AddDiagnosticsResponse(True, request.load_namespace))


def _services_served():
    service = _echo_service()
    return service.uri, rospy_private.served_services()


def test_served_services_lists_each_service_with_its_uri(in_child):
    uri, served = in_child(_services_served)
    assert uri.startswith('rosrpc://')
    assert [list(entry) for entry in served] == [['/kit_echo', uri]]


def _call_over_the_connection_opened_ahead(master_uri):
    os.environ['ROS_MASTER_URI'] = master_uri
    service = _echo_service()
    proxy = rospy.ServiceProxy('/kit_echo', AddDiagnostics, persistent=True)
    rospy_private.connect_persistent(proxy, service.uri)
    opened = proxy.transport
    answers = [proxy('first').message, proxy('second').message]
    same = proxy.transport is opened
    proxy.close()
    return answers, same


def test_a_persistent_proxy_calls_over_the_connection_opened_ahead_without_the_master(in_child):
    # A stand-in master that records what it is asked: rospy reads /tcp_keepalive once per process
    # when it opens its first connection, and nothing else may reach the master.
    asked = []
    server = SimpleXMLRPCServer(('127.0.0.1', 0), logRequests=False)
    server.register_function(lambda caller, key: asked.append(('getParam', key)) or [1, '', True],
                             'getParam')
    server.register_function(lambda caller, name: asked.append(('lookupService', name)) or
                             [-1, 'not asked for', ''], 'lookupService')
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        master_uri = 'http://127.0.0.1:%d/' % server.server_address[1]
        answers, same = in_child(_call_over_the_connection_opened_ahead, master_uri)
    finally:
        server.shutdown()
        server.server_close()
    assert answers == ['first', 'second']
    assert same, 'the calls did not use the connection opened ahead'
    assert asked == [('getParam', '/tcp_keepalive')]

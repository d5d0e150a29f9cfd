"""The kept-open connection to the master (node_kit.master_line), against a stand-in master.

The stand-in is Python's own XML-RPC server in a process of its own, threaded and speaking HTTP/1.1 as
rosmaster's (``rosgraph.xmlrpc``) does, so that its death is a real one: the kernel closes its
connections, which is the event the master link waits for.
"""
import http.client
import signal
import socket
import subprocess
import sys
import time

import pytest

from node_kit.master_line import KEEPALIVE_IDLE_S, KEEPALIVE_INTERVAL_S, KEEPALIVE_PROBES, MasterLine

STAND_IN = r'''
import socketserver, sys
from xmlrpc.server import SimpleXMLRPCRequestHandler, SimpleXMLRPCServer
opened = [0]
class Handler(SimpleXMLRPCRequestHandler):
    protocol_version = sys.argv[1]
    rpc_paths = tuple(sys.argv[2:]) or ('/',)
    def setup(self):
        opened[0] += 1
        SimpleXMLRPCRequestHandler.setup(self)
    def log_message(self, *args):
        pass
class Server(socketserver.ThreadingMixIn, SimpleXMLRPCServer):
    daemon_threads = True
server = Server(('127.0.0.1', 0), Handler, logRequests=False)
server.register_multicall_functions()
server.register_function(lambda caller: [1, 'pid', 4242], 'getPid')
server.register_function(lambda caller, name: [1, 'node', 'http://n:1/'] if name == '/known'
                         else [-1, 'unknown node', ''], 'lookupNode')
server.register_function(lambda: opened[0], 'connections')
def close_after_answers():  # from this answer on, the server ends every connection after its answer
    Handler.protocol_version = 'HTTP/1.0'
    return True
server.register_function(close_after_answers, 'close_after_answers')
print(server.server_address[1], flush=True)
server.serve_forever()
'''
#: A bound for waits that end on an event: far beyond any scheduling delay, short of a hung test.
EVENT_TIMEOUT = 30.0


def stand_in(protocol, path='/'):
    """A stand-in master speaking ``protocol``, serving XML-RPC at ``path`` only: (process, its URI)."""
    proc = subprocess.Popen([sys.executable, '-c', STAND_IN, protocol, path], stdout=subprocess.PIPE,
                            universal_newlines=True)
    port = proc.stdout.readline().strip()
    assert port, 'the stand-in master did not start'
    return proc, 'http://127.0.0.1:%s%s' % (port, path)


@pytest.fixture
def master():
    proc, uri = stand_in('HTTP/1.1')
    yield proc, uri
    proc.kill()
    proc.wait()


@pytest.fixture
def wake():
    ends = socket.socketpair()
    yield ends
    for end in ends:
        end.close()


def test_answers_come_in_order_and_a_fault_is_none(master):
    line = MasterLine(master[1], 5.0)
    assert line.multicall([('getPid', ['/a']), ('lookupNode', ['/a', '/known']),
                           ('lookupNode', ['/a', '/other']), ('no_such_method', [])]) == [
        [1, 'pid', 4242], [1, 'node', 'http://n:1/'], [-1, 'unknown node', ''], None]
    line.close()


def test_every_call_goes_over_one_connection_kept_open_with_keepalive(master):
    line = MasterLine(master[1], 5.0)
    for _ in range(5):
        line.multicall([('getPid', ['/a'])])
    assert line.multicall([('connections', [])]) == [1]
    assert line.held()
    sock = line._connection.sock
    assert sock.getsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE) == 1
    if hasattr(socket, 'TCP_KEEPIDLE'):
        assert sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_KEEPIDLE) == KEEPALIVE_IDLE_S
    line.close()


def test_a_living_master_leaves_the_connection_open_until_the_timeout(master, wake):
    line = MasterLine(master[1], 5.0)
    line.multicall([('getPid', ['/a'])])
    assert line.wait(0.2, wake[0]) is False
    assert line.held()
    assert line.multicall([('connections', [])]) == [1]
    line.close()


def test_the_masters_death_ends_the_wait_at_once(master, wake):
    proc, uri = master
    line = MasterLine(uri, 5.0)
    line.multicall([('getPid', ['/a'])])
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    started = time.monotonic()
    assert line.wait(EVENT_TIMEOUT, wake[0]) is True
    assert time.monotonic() - started < EVENT_TIMEOUT / 2
    assert not line.held()
    with pytest.raises(OSError):  # nobody listens on the port any more: refused
        line.multicall([('getPid', ['/a'])])


def test_a_wake_ends_the_wait(master, wake):
    line = MasterLine(master[1], 5.0)
    line.multicall([('getPid', ['/a'])])
    wake[1].send(b'!')
    started = time.monotonic()
    assert line.wait(EVENT_TIMEOUT, wake[0]) is False
    assert time.monotonic() - started < EVENT_TIMEOUT / 2
    line.close()


def test_without_a_held_connection_the_wait_is_a_plain_wait(wake):
    proc, uri = stand_in('HTTP/1.0')  # closes every connection after its answer: nothing to wait on
    try:
        line = MasterLine(uri, 5.0)
        assert line.multicall([('getPid', ['/a'])]) == [[1, 'pid', 4242]]
        assert not line.held()
        assert line.wait(0.1, wake[0]) is False
        assert line.multicall([('connections', [])]) == [2]
    finally:
        proc.kill()
        proc.wait()


def test_an_absent_master_raises_and_holds_nothing():
    probe = socket.socket()
    probe.bind(('127.0.0.1', 0))
    port = probe.getsockname()[1]
    probe.close()  # a port nobody listens on
    line = MasterLine('http://127.0.0.1:%d/' % port, 5.0)
    with pytest.raises(OSError):
        line.multicall([('getPid', ['/a'])])
    assert not line.held()


def test_the_call_goes_to_the_path_of_the_masters_uri(wake):
    proc, uri = stand_in('HTTP/1.1', '/ros/master')  # answers at that path only (404 elsewhere)
    try:
        line = MasterLine(uri, 5.0)
        assert line.multicall([('getPid', ['/a'])]) == [[1, 'pid', 4242]]
        line.close()
        with pytest.raises(http.client.HTTPException):  # the stand-in does answer 404 at another path
            MasterLine(uri.replace('/ros/master', '/elsewhere'), 5.0).multicall([('getPid', ['/a'])])
    finally:
        proc.kill()
        proc.wait()


def test_a_uri_without_a_port_means_the_http_port_80(monkeypatch):
    opened = []

    class Refused(object):
        """An HTTPConnection that records where it connects and is refused there."""
        def __init__(self, host, port, timeout):
            opened.append((host, port, timeout))
            self.sock = None

        def request(self, *args):
            raise ConnectionRefusedError('refused')

        def close(self):
            pass
    monkeypatch.setattr(http.client, 'HTTPConnection', Refused)
    with pytest.raises(ConnectionRefusedError):
        MasterLine('http://ground/', 3.0).multicall([('getPid', ['/a'])])
    with pytest.raises(ConnectionRefusedError):
        MasterLine('http://ground:11311/', 3.0).multicall([('getPid', ['/a'])])
    assert opened == [('ground', 80, 3.0), ('ground', 11311, 3.0)]


def test_a_master_that_stops_holding_the_connection_still_answers_and_is_not_held(master):
    # The connection was held (and its keepalive set), then the master closes it after an answer: the
    # answer still comes, nothing is held any more, and the next call opens a new connection.
    line = MasterLine(master[1], 5.0)
    assert line.multicall([('getPid', ['/a'])]) == [[1, 'pid', 4242]]
    assert line.held()
    assert line.multicall([('close_after_answers', [])]) == [True]
    assert not line.held()
    assert line.multicall([('connections', [])]) == [2]
    assert not line.held()
    line.close()


def test_every_keepalive_option_is_set_on_the_held_connection(master):
    line = MasterLine(master[1], 5.0)
    line.multicall([('getPid', ['/a'])])
    sock = line._connection.sock
    assert sock.getsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE) == 1
    for option, value in (('TCP_KEEPIDLE', KEEPALIVE_IDLE_S), ('TCP_KEEPINTVL', KEEPALIVE_INTERVAL_S),
                          ('TCP_KEEPCNT', KEEPALIVE_PROBES)):
        if hasattr(socket, option):
            assert sock.getsockopt(socket.IPPROTO_TCP, getattr(socket, option)) == value, option
    line.close()

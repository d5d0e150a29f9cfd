"""One kept-open connection to the ROS master: how a node learns of its master's death without asking.

A node that keeps itself registered across a master restart (:mod:`node_kit.master_link`) must notice
two things at once: the master went away, and a master answers again that does not know the node.
Asking once a second costs the master one XML-RPC request per node per second: 200 nodes of a
100-pair fleet took 22 % of its core that way (issue 19), for answers that were "nothing changed"
every time. The event to wait for is the master's death, and the kernel announces it: rosmaster's
XML-RPC server speaks HTTP/1.1 (``rosgraph.xmlrpc``, on Linux 4.16 and newer), so the connection of
a call stays open after the answer, one idle thread of the master's server waiting on it, and when
the master process ends (killed, crashed, stopped) the kernel closes the connection: the node's end
becomes readable at that instant. :meth:`MasterLine.wait` waits for exactly that.

So the node asks only when something happened: at start, when the connection closes, and (while the
master is down) once a poll period until it answers again, which is as fast as polling once a second
ever was. A heartbeat (a real call every ``HEARTBEAT_S`` of :mod:`node_kit.master_link`) covers
what leaves the connection open: a master that hangs. TCP keepalive on the connection covers a
master host that vanished from the network, in the kernels, costing the master's process nothing.

A master that closes every connection after its answer (HTTP/1.0: a Linux kernel older than 4.16)
leaves nothing to wait on: :meth:`MasterLine.held` is then false and the caller polls as before.

Only the standard library: unit-tested against a stand-in master in a process of its own.
"""
import http.client
import select
import socket
import xmlrpc.client
from urllib.parse import urlsplit

#: TCP keepalive: the first probe after this many idle seconds, then one every KEEPALIVE_INTERVAL_S;
#: after KEEPALIVE_PROBES unanswered probes the kernel breaks the connection (the host is gone).
KEEPALIVE_IDLE_S = 1
KEEPALIVE_INTERVAL_S = 1
KEEPALIVE_PROBES = 2


class MasterLine(object):
    """XML-RPC calls to the master over one kept-open HTTP/1.1 connection, and a wait for its end.

    :param uri: the master's URI (``http://host:port/``).
    :param timeout: socket timeout of a call [s]: a master that hangs fails the call.

    Not thread-safe: one thread (the master link's) uses it.
    """

    def __init__(self, uri, timeout):
        parts = urlsplit(uri)
        self._host, self._port, self._path = parts.hostname, parts.port or 80, parts.path or '/'
        self._timeout = timeout
        self._connection = None
        self._tuned = None  # the socket whose keepalive is set

    def multicall(self, calls):
        """One ``system.multicall`` request of ``calls``, a list of ``(method, params)``.

        :returns: each call's answer, in order (ROS's ``[code, message, value]``), or None for a call
            that raised a fault.
        :raises Exception: no answer (refused, reset, timeout, not HTTP 200, not XML-RPC); the
            connection is closed then, and the next call opens a new one.
        """
        body = xmlrpc.client.dumps(([{'methodName': m, 'params': list(p)} for m, p in calls],),
                                   'system.multicall')
        if self._connection is None:
            self._connection = http.client.HTTPConnection(self._host, self._port, timeout=self._timeout)
        try:
            self._connection.request('POST', self._path, body, {'Content-Type': 'text/xml'})
            response = self._connection.getresponse()
            data = response.read()
            if response.status != 200:
                raise http.client.HTTPException('HTTP %d %s' % (response.status, response.reason))
            (answers,), _ = xmlrpc.client.loads(data)
        except Exception:
            self.close()
            raise
        self._keepalive()
        return [a[0] if isinstance(a, list) and a else None for a in answers]

    def held(self):
        """Whether the connection stayed open after the last answer (the master speaks HTTP/1.1)."""
        return self._connection is not None and self._connection.sock is not None

    def wait(self, timeout, wake):
        """Wait until the master's end closes the connection, ``wake`` is readable, or ``timeout`` [s].

        :param wake: a socket another thread writes to, to end the wait early (a stop).
        :returns: True when the connection closed or broke (it is closed here then): ask the master
            now. False at the timeout or a wake, or when no connection is held (a plain wait).
        """
        sock = self._connection.sock if self.held() else None
        readable, _, _ = select.select([wake] + ([sock] if sock else []), [], [], timeout)
        if sock is None or sock not in readable:
            return False
        # The master never writes unasked: readable means end of stream or an error.
        self.close()
        return True

    def close(self):
        if self._connection is not None:
            self._connection.close()
            self._connection = None

    def _keepalive(self):
        sock = self._connection.sock
        if sock is None or sock is self._tuned:
            return
        self._tuned = sock
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)
        for option, value in (('TCP_KEEPIDLE', KEEPALIVE_IDLE_S), ('TCP_KEEPINTVL', KEEPALIVE_INTERVAL_S),
                              ('TCP_KEEPCNT', KEEPALIVE_PROBES)):
            if hasattr(socket, option):  # Linux; elsewhere the system's keepalive times apply
                sock.setsockopt(socket.IPPROTO_TCP, getattr(socket, option), value)

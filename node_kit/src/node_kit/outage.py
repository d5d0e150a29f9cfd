"""What a node does when its master goes away and comes back: the rules, without rospy.

ROS 1 nodes register with the master once, at start-up; a master that is killed and started again on
the same port knows none of them. :mod:`node_kit.master_link` asks the master when the connection it
holds to it closes, once a second while it is down, every few seconds otherwise, and feeds each
answer to :class:`MasterWatch`, which says what to do and what to log: the pure part,
unit-tested with synthetic answers and times.

An answer is one of:

- ``KNOWN``: the master answers, knows this node, and is the master the node registered with (all is
  well, or it is back after a network fault);
- ``UNKNOWN``: the master answers but was restarted: it lost everything (:func:`classify`);
- ``UNREACHABLE``: no answer (connection refused, timeout).

What a poll costs the master does not grow with the graph (issue 19): one XML-RPC multicall of
``getPid`` (the master's process id) and ``lookupNode`` of the node's own name, two dictionary
look-ups; ``getSystemState`` (the whole graph, once a second from every node) grew with the square
of the fleet. A restarted master forgets every node, so ``lookupNode`` fails; and a master that
learnt the node's name again some other way (a parameter subscription, a new publisher) without its
other registrations has another pid than the one the node registered with.

Logging rule: one line when the outage starts, one when it ends, nothing in between, so that a master
down for an hour does not flood the log.
"""

KNOWN = 'known'
UNKNOWN = 'unknown'
UNREACHABLE = 'unreachable'

#: What :meth:`MasterWatch.observe` asks the caller to do besides logging.
REREGISTER = 'reregister'


def classify(pid, node_uri, known_pid):
    """The answer of one poll, from the master's ``getPid`` and ``lookupNode(own name)`` answers.

    :param pid: the master's pid, or None when ``getPid`` failed.
    :param node_uri: the URI the master has for this node's name, or None when it does not know it.
    :param known_pid: the pid of the master the node last registered with, None before it is known.
    :returns: KNOWN or UNKNOWN (an unreachable master never gets here).
    """
    if node_uri is None or pid is None:
        return UNKNOWN
    if known_pid is not None and pid != known_pid:
        return UNKNOWN
    return KNOWN


class MasterWatch(object):
    """The master's state as one node sees it, from the answers to its polls.

    :param master_uri: for the messages.
    :param name: the node's resolved name, for the messages.

    Every method returns ``(action, level, message)``; ``action`` is None or :data:`REREGISTER`,
    ``level`` is None (log nothing), ``'info'`` or ``'warn'``.
    """

    def __init__(self, master_uri, name):
        self._uri = master_uri
        self._name = name
        self._down_since = None  # time the outage began, None while the master is up
        self._reregister_failed = False
        self._reregistered_at = None  # time of the last re-registration, None before the first
        self._reregistrations = 0
        self._counts = None  # what the last re-registration registered
        self._answered_at = None  # time of the master's last answer, None before the first

    @property
    def up(self):
        return self._down_since is None

    def observe(self, answer, now, error=''):
        """One poll's answer at time ``now`` [s]; ``error`` says why the master was unreachable."""
        if answer != UNREACHABLE:
            self._answered_at = now
        if answer == UNREACHABLE:
            if self._down_since is not None:
                return None, None, ''
            self._down_since = now
            return None, 'warn', (
                'master at %s unreachable (%s): %s keeps running; topics already connected keep '
                'flowing and the warning service keeps its connection, but no new connection, '
                'parameter or name lookup works until the master is back' % (self._uri, error,
                                                                              self._name))
        if answer == UNKNOWN:
            return REREGISTER, None, ''
        if self._down_since is None:
            return None, None, ''
        outage = now - self._down_since
        self._down_since = None
        self._reregister_failed = False
        return None, 'info', ('master at %s reachable again after %.1f s; it still knows %s: '
                              'nothing to re-register' % (self._uri, outage, self._name))

    def reregistered(self, now, publications, subscriptions, services, parameters):
        """Re-registration with a restarted master succeeded; the counts are for the message."""
        outage = None if self._down_since is None else now - self._down_since
        self._down_since = None
        self._reregister_failed = False
        self._reregistered_at = now
        self._reregistrations += 1
        self._counts = (publications, subscriptions, services, parameters)
        down = 'restarted' if outage is None else 'restarted after %.1f s down' % outage
        return None, 'info', ('master at %s %s, without %s: re-registered %d publications, '
                              '%d subscriptions, %d services and %d private parameters'
                              % (self._uri, down, self._name, publications, subscriptions, services,
                                 parameters))

    def reregister_failed(self, now, error):
        """Re-registration was cut short (the master went away again, or refused a registration)."""
        if self._down_since is None:
            self._down_since = now
        if self._reregister_failed:
            return None, None, ''
        self._reregister_failed = True
        return None, 'warn', ('could not re-register %s with the master at %s (%s): retrying every '
                              'poll' % (self._name, self._uri, error))

    def status(self, now):
        """The link to the master as /diagnostics shows it: ``(level, summary, [(key, value)])``.

        ``level`` is ``'ok'``, or ``'warn'`` while the master is unreachable or the node could not
        re-register with it. Times [s] are those given to observe() (the node passes wall time).
        """
        values = [('master', self._uri),
                  ('state', 'up' if self.up else 'down'),
                  ('down since [s]', 'up' if self.up else '%.3f' % self._down_since),
                  ('down for [s]', '0' if self.up else '%.1f' % (now - self._down_since)),
                  ('last answer at [s]',
                   'never' if self._answered_at is None else '%.3f' % self._answered_at),
                  ('re-registrations', '%d' % self._reregistrations),
                  ('last re-registration at [s]',
                   'never' if self._reregistered_at is None else '%.3f' % self._reregistered_at)]
        if self._counts is not None:
            values.append(('last re-registration', '%d publications, %d subscriptions, %d services, '
                           '%d private parameters' % self._counts))
        if not self.up:
            failing = ', re-registration failing' if self._reregister_failed else ''
            return 'warn', 'master down for %.1f s%s' % (now - self._down_since, failing), values
        if self._reregistered_at is None:
            return 'ok', 'master up, registered since the start', values
        return 'ok', 'master up, re-registered %d times, last at %.3f' % (
            self._reregistrations, self._reregistered_at), values


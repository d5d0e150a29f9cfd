"""The exam node's /diagnostics: its inputs and its warning (rqt_runtime_monitor shows them).

Two statuses, named after the node by diagnostic_updater, in the node's one Updater
(:func:`node_kit.lifecycle.updater`, which publishes them with the "<node>: master" status):

- ``<node>: inputs``: each input's measured rate [Hz], age [s] and rejected readings; WARN while an
  input is stale (older than ``~timeout``) or has never arrived.
- ``<node>: warning``: the value, the threshold, the warning state, when a pending WARNING is due, the
  LED wanted and shown, the failed service calls; ERROR while the warning service cannot be reached.

The status functions only format copies the node takes under its locks (:class:`Snapshot`, and
:meth:`exam.warning_link.WarningLink.snapshot`): they never touch the node's state themselves.

Published Topics:
    /diagnostics (diagnostic_msgs/DiagnosticArray): every ``~diagnostic_period`` seconds (default 1),
        also while the master is down (subscribers already connected keep seeing them).
"""
import collections

from diagnostic_msgs.msg import DiagnosticStatus

from exam.warning_link import LED_COLOURS
from node_kit import lifecycle

#: One input as diagnostics show it: topic, measured rate [Hz], age [s] or None, rejected readings.
InputRow = collections.namedtuple('InputRow', 'topic rate age rejected')
#: The node's state as diagnostics show it: InputRow list, latest value or None, warning state or None,
#: threshold, time [s] a pending WARNING is due or None.
Snapshot = collections.namedtuple('Snapshot', 'inputs value state threshold deadline')


def inputs_status(stat, snapshot, timeout):
    """Fill ``stat`` with each input's rate, age and rejected readings; WARN if one is stale."""
    stale = []
    for row in snapshot.inputs:
        stat.add('%s rate [Hz]' % row.topic, '%.2f' % row.rate)
        stat.add('%s age [s]' % row.topic, 'never received' if row.age is None else '%.2f' % row.age)
        stat.add('%s rejected readings' % row.topic, row.rejected)
        if row.age is None or row.age > timeout:
            stale.append(row.topic)
    if stale:
        stat.summary(DiagnosticStatus.WARN, 'stale or missing: %s' % ', '.join(stale))
    else:
        stat.summary(DiagnosticStatus.OK, 'all inputs fresh')
    return stat


def warning_status(stat, snapshot, link, mode, service):
    """Fill ``stat`` with the value, the warning state and the LED; ERROR while ``service`` fails.

    :param link: the warning link's snapshot() dict.
    :param mode: the node's :class:`exam.modes.Mode`, for the output's name and unit.
    :param service: the resolved name of the warning service.
    """
    unit, value, state, deadline = mode.unit, snapshot.value, snapshot.state, snapshot.deadline
    shown = LED_COLOURS[link['shown']]
    stat.add('%s [%s]' % (mode.output, unit), 'none yet' if value is None else '%.2f' % value)
    stat.add('threshold [%s]' % unit, '%.2f' % snapshot.threshold)
    stat.add('state', state or 'unknown (no reading yet)')
    stat.add('WARNING due at [s]', 'not pending' if deadline is None else '%.3f' % deadline)
    stat.add('LED wanted', LED_COLOURS.get(link['wanted'], 'nothing yet'))
    stat.add('LED shows', shown)
    stat.add('failed service calls', link['failures'])
    if link['failing']:
        stat.summary(DiagnosticStatus.ERROR, 'cannot reach %s: %s' % (service, link['last_error']))
    else:
        stat.summary(DiagnosticStatus.OK, 'state %s, LED %s' % (state or 'unknown', shown))
    return stat


def start(snapshot, link_snapshot, mode, service, timeout):
    """Add both statuses to the node's Updater, which node_kit publishes; return the Updater.

    :param snapshot: function() -> Snapshot, a copy of the node's state taken under its lock.
    :param link_snapshot: function() -> the warning link's snapshot() dict.
    """
    updater = lifecycle.updater()
    updater.add('inputs', lambda stat: inputs_status(stat, snapshot(), timeout))
    updater.add('warning', lambda stat: warning_status(stat, snapshot(), link_snapshot(), mode, service))
    return updater

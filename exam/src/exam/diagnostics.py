"""The exam node's /diagnostics: its inputs and its warning, once a second (rqt_runtime_monitor shows them).

Two statuses, named after the node by diagnostic_updater:

- ``<node>: inputs``: each input's measured rate [Hz], age [s] and rejected readings; WARN while an
  input is stale (older than ``~timeout``) or has never arrived.
- ``<node>: warning``: the value, the threshold, the warning state, when a pending WARNING is due, the
  LED wanted and shown, the failed service calls; ERROR while the warning service cannot be reached.

The status functions only format copies the node takes under its locks (:class:`Snapshot`, and
:meth:`exam.warning_link.WarningLink.snapshot`): they never touch the node's state themselves.

The timer never dies: diagnostic_updater reads ``~diagnostic_period`` from the master on every update,
which raises while the master is unreachable; the statuses are then published anyway (subscribers
already connected keep seeing them) and the failure is logged once per outage (:func:`publish`).

Published Topics:
    /diagnostics (diagnostic_msgs/DiagnosticArray): every second. diagnostic_updater also reads its
        own ``~diagnostic_period`` (s, default 1): a longer period publishes less often.
"""
import collections

import diagnostic_updater
import rospy
from diagnostic_msgs.msg import DiagnosticStatus

from drone_sim import lifecycle
from drone_sim.outage import OncePerOutage
from exam.warning_link import LED_COLOURS

#: Seconds between two updates of /diagnostics.
PERIOD_S = 1.0

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
    """Publish both statuses every PERIOD_S seconds from a timer of their own; return the Updater.

    :param snapshot: function() -> Snapshot, a copy of the node's state taken under its lock.
    :param link_snapshot: function() -> the warning link's snapshot() dict.
    """
    updater = diagnostic_updater.Updater()
    updater.setHardwareID(rospy.get_name())
    updater.add('inputs', lambda stat: inputs_status(stat, snapshot(), timeout))
    updater.add('warning', lambda stat: warning_status(stat, snapshot(), link_snapshot(), mode, service))
    guard = OncePerOutage('/diagnostics: reading the diagnostic_period parameter from the master',
                          'the master is unreachable; the statuses are published every %.0f s anyway '
                          '(connected subscribers keep them, a new one finds them once the master is '
                          'back)' % PERIOD_S)
    lifecycle.timer(PERIOD_S, lambda event: publish(updater, guard))
    return updater


def publish(updater, guard):
    """One update of ``updater`` that never raises: a timer thread that raises is gone for good.

    :param guard: a :class:`drone_sim.outage.OncePerOutage`: the failure is logged once per outage.
    """
    try:
        updater.update()
    except Exception as err:  # ConnectionRefusedError, timeouts... from the master
        line = guard.failed('%s: %s' % (type(err).__name__, err))
        if line is not None:
            rospy.logwarn(line)
        try:
            updater.force_update()  # publishes only: no master involved
        except Exception as err:
            rospy.logerr_throttle(60.0, '/diagnostics not published: %s: %s' % (type(err).__name__, err))
        return
    line = guard.succeeded()
    if line is not None:
        rospy.loginfo(line)

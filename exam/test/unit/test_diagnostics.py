"""The two /diagnostics statuses, filled from hand-made snapshots (no master, no node)."""
import collections

import pytest

# ROS's Python packages: present beside rospy, absent from a plain interpreter.
diagnostic_updater = pytest.importorskip('diagnostic_updater')
from diagnostic_msgs.msg import DiagnosticStatus  # noqa: E402

from exam.debounce import NORMAL, WARNING  # noqa: E402
from exam.diagnostics import InputRow, Snapshot, inputs_status, warning_status  # noqa: E402

Mode = collections.namedtuple('Mode', 'output unit')
ALTITUDE = Mode('altitude', 'm')
LINK_OK = {'wanted': WARNING, 'shown': WARNING, 'failing': False, 'failures': 0, 'last_error': ''}


def snapshot(inputs=(), value=None, state=None, deadline=None):
    return Snapshot(inputs=list(inputs), value=value, state=state, threshold=1300.0, deadline=deadline)


def values(stat):
    return {kv.key: kv.value for kv in stat.values}


def test_inputs_fresh_is_ok():
    rows = [InputRow('temperature', 0.78, 1.2, 0), InputRow('pressure', 2.0, 0.4, 3)]
    stat = inputs_status(diagnostic_updater.DiagnosticStatusWrapper(), snapshot(rows), timeout=5.0)
    assert (stat.level, stat.message) == (DiagnosticStatus.OK, 'all inputs fresh')
    assert values(stat) == {'temperature rate [Hz]': '0.78', 'temperature age [s]': '1.20',
                            'temperature rejected readings': '0', 'pressure rate [Hz]': '2.00',
                            'pressure age [s]': '0.40', 'pressure rejected readings': '3'}


def test_inputs_stale_or_missing_is_a_warning_naming_them():
    rows = [InputRow('temperature', 0.0, None, 0), InputRow('pressure', 2.0, 5.01, 0)]
    stat = inputs_status(diagnostic_updater.DiagnosticStatusWrapper(), snapshot(rows), timeout=5.0)
    assert (stat.level, stat.message) == (DiagnosticStatus.WARN, 'stale or missing: temperature, pressure')
    assert values(stat)['temperature age [s]'] == 'never received'


def test_an_input_exactly_as_old_as_the_timeout_is_still_fresh():
    # The node's own rule (inputs.is_fresh): stale only when older than ~timeout.
    rows = [InputRow('temperature', 0.78, 5.0, 0), InputRow('pressure', 2.0, 0.4, 0)]
    stat = inputs_status(diagnostic_updater.DiagnosticStatusWrapper(), snapshot(rows), timeout=5.0)
    assert stat.level == DiagnosticStatus.OK


def test_warning_before_the_first_reading():
    link = dict(LINK_OK, wanted=None, shown=NORMAL)
    stat = warning_status(diagnostic_updater.DiagnosticStatusWrapper(), snapshot(), link, ALTITUDE,
                          '/altitude_warning')
    assert (stat.level, stat.message) == (DiagnosticStatus.OK, 'state unknown, LED GREEN')
    assert values(stat) == {'altitude [m]': 'none yet', 'threshold [m]': '1300.00',
                            'state': 'unknown (no reading yet)', 'WARNING due at [s]': 'not pending',
                            'LED wanted': 'nothing yet', 'LED shows': 'GREEN', 'failed service calls': '0'}


def test_warning_pending_then_failing_service_is_an_error():
    link = dict(LINK_OK, wanted=WARNING, shown=NORMAL, failing=True, failures=2, last_error='absent')
    stat = warning_status(diagnostic_updater.DiagnosticStatusWrapper(),
                          snapshot(value=1400.0, state=NORMAL, deadline=12.5), link, ALTITUDE,
                          '/altitude_warning')
    assert (stat.level, stat.message) == (DiagnosticStatus.ERROR, 'cannot reach /altitude_warning: absent')
    assert values(stat)['WARNING due at [s]'] == '12.500'
    assert values(stat)['LED wanted'] == 'RED'
    assert values(stat)['failed service calls'] == '2'


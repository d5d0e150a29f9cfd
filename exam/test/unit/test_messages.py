"""The warning's log lines, worded per sheet: "above" for the aerial drone, "deeper than" underwater."""
import collections

from exam.debounce import NORMAL, WARNING
from exam.messages import back_within, excess_began, excess_cancelled, state_changed

Mode = collections.namedtuple('Mode', 'output unit above within')
ALTITUDE = Mode('altitude', 'm', 'above', 'at or below')
DEPTH = Mode('depth', 'm', 'deeper than', 'not deeper than')


def test_an_excess_is_logged_with_its_start_and_the_time_its_warning_is_due():
    assert excess_began(ALTITUDE, 1310.24, 1300.0, 100.5, 105.5) == (
        'altitude 1310.2 m above the threshold 1300.0 m since 100.500, WARNING due at 105.500')
    assert excess_began(DEPTH, 200.0, 150.0, 7.0, 12.0) == (
        'depth 200.0 m deeper than the threshold 150.0 m since 7.000, WARNING due at 12.000')


def test_a_cancelled_excess_says_why():
    assert excess_cancelled(ALTITUDE, 1290.0, back_within(ALTITUDE)) == (
        'altitude 1290.0 m: the pending WARNING is cancelled (back at or below it)')
    assert excess_cancelled(DEPTH, 140.0, back_within(DEPTH)) == (
        'depth 140.0 m: the pending WARNING is cancelled (back not deeper than it)')
    assert excess_cancelled(DEPTH, 160.0, 'no fresh reading of /pressure_robot') == (
        'depth 160.0 m: the pending WARNING is cancelled (no fresh reading of /pressure_robot)')


def test_state_changes_in_each_sheets_words():
    assert state_changed(ALTITUDE, WARNING, 1350.0, 1300.0, 5.0) == (
        'altitude 1350.0 m above the threshold 1300.0 m for 5.0 s: WARNING')
    assert state_changed(ALTITUDE, NORMAL, 1282.1, 1300.0, 5.0) == (
        'altitude 1282.1 m at or below the threshold 1300.0 m: NORMAL')
    assert state_changed(DEPTH, WARNING, 200.0, 150.0, 5.0) == (
        'depth 200.0 m deeper than the threshold 150.0 m for 5.0 s: WARNING')
    assert state_changed(DEPTH, NORMAL, 8.3, 150.0, 5.0) == (
        'depth 8.3 m not deeper than the threshold 150.0 m: NORMAL')


def test_the_modes_carry_the_sheets_words():
    from exam.modes import MODES
    assert (MODES['altitude'].above, MODES['altitude'].within) == ('above', 'at or below')
    assert (MODES['depth'].above, MODES['depth'].within) == ('deeper than', 'not deeper than')

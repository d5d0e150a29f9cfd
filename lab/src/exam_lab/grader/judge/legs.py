"""The flight's legs without ROS: how long each is held, whether the node still owes a call on it, how
each is checked on the node's own values, the node's value read after an input change, and the trace
kept for the teacher's plot. Pure (no rospy: every function takes the samples, the calls and the
times it judges), so the rules the rubric times from are unit-tested on synthetic time; the probe
(:mod:`exam_lab.grader.judge.pilot`) flies them.
"""
import math
import time

from exam_lab.grader.score.sheets import request_meaning
from exam_lab.harness.wait import wait_until

#: Seconds after an input change before the node's output is read (several 10 Hz ticks).
SETTLE_S = 0.8
#: Published values older than this after an input change are not read (the change may be half seen).
IGNORE_S = 0.3
#: The flight's holds, s from the node's own first value on the leg's side (docs/grading.md, legs).
#: The short excursion: with a return as late as the rubric's lag tolerance (one period of the slowest
#: input and 0.5 s: 1.79 s) the node's own value stays above 4.3 s at most, less than the WARNING
#: window's start (4.7 s), so a right node never warns there.
REST_S = 2.0
SHORT_S = 2.5
#: Just below the threshold after the short excursion: a count that is not reset there shows later.
GAP_S = 2.0
#: The long excursion lasts delay + AFTER_S: past the WARNING window's end (the delay and the larger of
#: 0.5 s and one period of the slowest input and a tick: 1.39 s at most, score.flight.warning_window).
AFTER_S = 1.5
#: Just below the threshold after the long excursion: NORMAL must come here, at once.
BACK_S = 1.5
#: Further below (the rest's value): the NORMAL of a node that waits for a margin, for question 13.
DEEP_S = 1.5
#: After an input change, a value read is waited for until it moved, up to this many s (a stale node).
STALE_S = 6.0


def last_value(recorder, since):
    """The last value published at least IGNORE_S after ``since`` and the number of such samples."""
    samples = recorder.samples(since + IGNORE_S)
    return (samples[-1][1] if samples else None), len(samples)


def settled(recorder, since, before=None, settle=SETTLE_S):
    """The node's value after an input change at ``since``: read ``settle`` s later; when it is still the
    ``before`` value (or none), waited for until it moves, up to STALE_S (a node that blocks in a callback)."""
    time.sleep(max(0.0, since + settle - time.time()))
    # Also when nothing came yet: a node computes only once it has a reading of each input, and the
    # slowest comes once a period.
    wait_until(lambda: last_value(recorder, since)[0] not in (None, before), max(0.0, STALE_S - settle),
               period=0.1)
    return last_value(recorder, since)


def on_side(value, threshold, side):
    """True when ``value`` is on ``side`` ('above': beyond the threshold, 'below': not beyond it)."""
    if value is None or not math.isfinite(value):
        return False
    return value > threshold if side == 'above' else value <= threshold


def owes(calls, side, since):
    """Whether a node whose service calls are ``calls`` (``[(time, request)]``) still owes the call a
    leg flown on ``side`` since ``since`` waits for: above, a WARNING (none came since); below, a
    NORMAL (its last WARNING or NORMAL was a WARNING, whenever it came)."""
    if side == 'above':
        return not any(t >= since and request_meaning(s) == 'WARNING' for t, s in calls)
    statuses = [request_meaning(s) for _, s in sorted(calls)]
    statuses = [s for s in statuses if s in ('WARNING', 'NORMAL')]
    return bool(statuses) and statuses[-1] == 'WARNING'


def normal_wait(delay, rates):
    """Seconds a NORMAL the node owes (its last call was a WARNING) is waited for, on the rest and on
    the last leg, after its own value came back below: the delay, AFTER_S and one period of the slowest
    input (``rates``: topic -> Hz). A node that goes back to NORMAL only after the delay below, checking
    at each reading, is seen doing it, so its late NORMAL costs Q14b's "at once" only, not Q13 as well,
    and a WARNING it gave during the calibration does not hide the flight's WARNING from it."""
    return delay + AFTER_S + 1.0 / min(rates.values())


#: The main flight's legs, in their order.
FLIGHT_LEGS = ('rest', 'short_up', 'short_down', 'long_up', 'long_down', 'deep_down')


def leg_check(samples, threshold, side, start, end):
    """Whether the node's own published values were on ``side`` of the threshold during a leg that
    was flown from ``start`` to ``end``: ``{"side", "reached" (time of the first value on that side,
    or None), "stays" (time of the first value from which every value of the leg is on that side, or
    None), "off_side" (values on the other side after "reached"), "first", "last" (values)}``.

    Judged only on what the node published: a leg whose values never reached the side (a stale
    reading, a node that does not react) is not one the rubric may judge anything on. The rubric times
    the delay from "stays" (the node's own value went beyond and stayed), the return from "reached".
    """
    inside = [(t, v) for t, v in samples if start <= t <= end]
    reached = next((t for t, v in inside if on_side(v, threshold, side)), None)
    off = len([1 for t, v in inside if reached is not None and t >= reached and not on_side(v, threshold, side)])
    stays = None
    for t, v in reversed(inside):
        if not on_side(v, threshold, side):
            break
        stays = t
    return {'side': side, 'reached': reached, 'stays': stays, 'off_side': off,
            'first': inside[0][1] if inside else None, 'last': inside[-1][1] if inside else None,
            'samples': len(inside)}


#: The flight plot's trace keeps one published value per this many s (the node's 10 Hz).
TRACE_PERIOD_S = 0.09


def trace(samples, flown, period=TRACE_PERIOD_S):
    """The flight for the teacher's plot (not for scoring): ``{"published": [[t, value]] at most one
    sample per ``period`` (non-finite values as None), "oracle": [[t, value]] (the oracle's value from t
    on)}``, wall-clock times like the calls and the schedule."""
    kept, last = [], None
    for t, v in samples:
        if last is None or t - last >= period:
            kept.append([round(t, 3), round(v, 3) if math.isfinite(v) else None])
            last = t
    return {'published': kept, 'oracle': [[round(t, 3), round(x, 3)] for t, x in flown]}

"""The flight as the rubric times it: the node's calls of the warning service, the legs the probe flew
(their schedule, whether the node's own value reached each leg's side, how late it followed its
inputs), and the windows its timing rules count in (the WARNING's :func:`warning_window`, the lag
tolerance). Pure, no rospy.

Every function takes a probe's result (:class:`~exam_lab.grader.score.records.ProbeRecord`) as it is
kept or as its view, and reads the view.
"""
from exam_lab.grader.score.measured import otherwise, probe_of
from exam_lab.grader.score.sheets import DELAY, REQUESTS, request_meaning
from exam_lab.grader.score.tolerances import (LAG_SLACK_S, OLD_SLOWEST_HZ, RATE_HZ, RATE_TOLERANCE, WARNING_EARLY_S,
                                              WARNING_LATE_S)

#: The legs of the flights, in words: docs/grading.md's names of the legs (and the plot's), with their side.
LEG_WORDS = {'rest': 'rest below', 'short_up': 'short excursion above', 'short_down': 'just below',
             'long_up': 'long excursion above', 'long_down': 'return just below', 'deep_down': 'further below',
             'start': 'start below',
             'step': 'step above the new threshold'}


def calls(probe):
    """Every call the node made: ``[(time, meaning, request, accepted)]``, ``meaning`` the status the
    request was meant as (:func:`~exam_lab.grader.score.sheets.request_meaning`; the request itself when
    it means neither), ``accepted`` the drone's answer (success). A refused request is a call all the same."""
    probe = probe_of(probe)
    answers = {(a[0], a[1]): bool(a[2]) for a in probe.answers or ()}
    out = []
    for t, request in sorted(probe.calls or ()):
        meaning = request_meaning(request)
        out.append((t, meaning or request, request, answers.get((t, request), request in REQUESTS)))
    return out


def refused_calls(probe, start=float('-inf'), end=float('inf')):
    """The calls the drone refused between ``start`` and ``end``: ``[(time, request)]``."""
    return [(t, request) for t, _, request, accepted in calls(probe) if not accepted and start <= t <= end]


def refused_words(refused):
    requests = sorted(set(r for _, r in refused))
    return '%d call(s) with %s' % (len(refused), ', '.join('"%s"' % r[:40] for r in requests[:4]))


def calls_between(probe, start, end, status=None):
    return [(t, s) for t, s, _, _ in calls(probe) if start <= t <= end and (status is None or s == status)]


def repeats(probe, since):
    made = calls(probe)
    return len([1 for previous, call in zip(made, made[1:]) if call[0] >= since and call[1] == previous[1]])


def schedule_of(probe):
    """The flight's schedule ``{leg: time}`` when it flew the main run's legs, else None (no flight, or
    a single step of a threshold run kept from before)."""
    schedule = probe_of(probe).schedule or {}
    return schedule if 'long_up' in schedule else None


def driven_by(probe):
    calibration = probe_of(probe).calibration
    if calibration and calibration.by == 'own':
        return 'driven at the node\'s own values %.1f / %.1f' % (calibration.lo.value, calibration.hi.value)
    lo, hi = (calibration.lo, calibration.hi) if calibration else (None, None)
    return 'driven at the oracle\'s values %.1f / %.1f (%s)' % (
        otherwise(lo.x if lo else None, float('nan')), otherwise(hi.x if hi else None, float('nan')),
        otherwise(calibration.reason if calibration else None, ''))


def silent(probe):
    """Whether the node published nothing the judge received, its output there all the same (a
    publisher rospy never connects, a value never published): the probe then flew each leg from the
    input's change, at the oracle's values, and every timing rule is judged from its calls against
    the judge's own value of the flight, from the readings (issue 45). A probe of before recorded no
    such flight (it held each leg for a value that never came): never silent then."""
    return bool(probe_of(probe).silent)


def _legs(probe):
    """The legs checked on the node's own values: none for a :func:`silent` output."""
    probe = probe_of(probe)
    return {} if silent(probe) else (probe.legs or {})


def unreached_legs(probe, names=None):
    """Legs of a flight whose node's own value never reached the side they were flown for."""
    legs = _legs(probe)
    return [n for n in (names or sorted(legs)) if n in legs and legs[n].reached is None]


def leg_words(probe, name):
    probe = probe_of(probe)
    leg = probe.legs[name]
    shown = 'nothing' if leg.first is None else '%.1f to %.1f' % (leg.first, leg.last)
    return ('not judged: in the %s the node\'s own value never went %s the threshold %g (it published %s), '
            'so nothing is judged on that leg' % (LEG_WORDS.get(name, name), leg.side,
                                                  otherwise(probe.threshold, float('nan')), shown))


def reached(probe, name):
    """When the node's own value reached the leg's side (the input's change when it cannot be read)."""
    probe = probe_of(probe)
    leg = _legs(probe).get(name)
    return (leg.reached if leg else None) or probe.schedule[name]


def slowest_period(probe):
    """Seconds between two readings of the slowest input the judge's drone published: the sheet's drone,
    at the rates its package's SPEC gives (``input_rates``, recorded by the probe)."""
    rates = [r for r in (probe_of(probe).input_rates or {}).values() if r and r > 0]
    return 1.0 / min(rates or [OLD_SLOWEST_HZ])


def lag_tolerance(probe):
    """Seconds the node's value may take to follow its inputs: one period of the slowest input the
    drone flew plus LAG_SLACK_S, or plus its own period when it is slow (:func:`own_period`: its rate
    is question 11's loss, not the timing items' too, issue 45)."""
    return slowest_period(probe) + max(LAG_SLACK_S, own_period(probe))


def own_period(probe):
    """A slow node's own pace: the longest gap between two values it published in the flight, s, when
    its rate is below the sheet's 10 Hz (question 11's loss); 0 otherwise (a 10 Hz node's tick is
    counted where it matters; a long gap of a 10 Hz node is a block, not its pace) or when not measured.
    A node that publishes once a second shows an input change, and checks its delay, that much later."""
    rate = probe_of(probe).rate
    hz, gap = (rate.hz, rate.max_gap) if rate else (None, None)
    if hz is None or gap is None or hz >= RATE_HZ * (1 - RATE_TOLERANCE):
        return 0.0
    return gap


def warning_window(probe):
    """``(earliest, latest)`` s after the node's own value went beyond and stayed, for a WARNING on time:
    the delay less WARNING_EARLY_S; the delay and the larger of WARNING_LATE_S, one period of the
    slowest input and one tick of the node's 10 Hz (a node that checks at each reading), and the node's
    own period (:func:`own_period`: one that publishes slowly checks as slowly, its rate question 11's
    loss alone, issue 45), or later for a slow node, :func:`paced_late`."""
    delay = otherwise(probe_of(probe).delay, DELAY)
    return delay - WARNING_EARLY_S, max(delay + max(WARNING_LATE_S, slowest_period(probe) + 1.0 / RATE_HZ,
                                                    own_period(probe)), paced_late(probe))


def paced_late(probe):
    """The latest WARNING on time of a slow node (:func:`own_period`), timed at its own ticks as the
    judge received its values: before its second value published more than a tick after the delay, s
    after its own value went beyond and stayed; 0 for a node at the sheet's rate or when not recorded.

    A node that checks its delay once a loop warns in the loop whose check first sees the delay
    elapsed: the first of its values after the delay (a tick later when its check fell a few ms short
    of it, transport and a loaded machine), its call following its value by the service's own latency.
    Its longest gap (:func:`own_period`) bounds that only for a steady pace; measured on its ticks, the
    window is the node's own, however its pace and the machine's load vary (issue 45: 0.01 s outside
    under load). A node whose delay is longer than the sheet's by more than one of its periods is
    still outside."""
    probe = probe_of(probe)
    published = probe.trace.published if probe.trace else None
    if not own_period(probe) or not published or silent(probe) or 'long_up' not in (probe.schedule or {}):
        return 0.0
    since = timed_from(probe, 'long_up', stays=True)[0]
    after = [t for t, _ in published if t > since + otherwise(probe.delay, DELAY) + 1.0 / RATE_HZ]
    return after[1] - since if len(after) > 1 else 0.0


def leg_lag(probe, name):
    """Seconds from the input's change to the node's own first value on leg ``name``'s side, or None
    (the leg was not flown, its value never reached the side, or the output cannot be read)."""
    probe = probe_of(probe)
    leg = _legs(probe).get(name)
    start = (probe.schedule or {}).get(name)
    if (leg.reached if leg else None) is None or start is None:
        return None
    return leg.reached - start


def timed_from(probe, name, stays=False):
    """``(time, words)``: where a timing rule on leg ``name`` counts from, in the node's own frame: when
    its own value went beyond and stayed (``stays``: the delay) or first came to the leg's side (the
    return). A node whose value took longer than :func:`lag_tolerance` to follow its inputs there is
    timed from the input's change instead (its lag is then its mistake, said here and in Q11), and so
    is one whose output cannot be read."""
    probe = probe_of(probe)
    start = probe.schedule[name]
    lag = leg_lag(probe, name)
    if lag is None:
        return start, 'the first reading'
    if lag > lag_tolerance(probe):
        return start, 'the first reading (the node\'s own value followed %.1f s later, more than one input ' \
                      'period: timed from the reading)' % lag
    leg = probe.legs[name]
    own = leg.stays if stays and leg.stays is not None else leg.reached
    return own, 'its own value'


def worst_lag(probe):
    """``(leg, seconds)``: the flight's leg where the node's value followed its inputs latest, and how
    late; None when nothing was measured."""
    probe = probe_of(probe)
    measured = [(name, leg_lag(probe, name)) for name in LEG_WORDS if leg_lag(probe, name) is not None
                and name in (probe.schedule or {}) and name not in ('start', 'step')]
    return max(measured, key=lambda m: m[1]) if measured else None


def lag_words(probe):
    """Question 11's evidence of how fast the node's value followed its inputs on the flight's legs,
    or '' when nothing was measured."""
    probe = probe_of(probe)
    if worst_lag(probe) is None:
        return ''
    name, worst = worst_lag(probe)
    tolerance = lag_tolerance(probe)
    if worst <= tolerance:
        return 'its value followed the inputs within %.2f s (at most %.2f s: one period of the slowest input ' \
               'and %s); the timing items are judged from its own values' % (
                   max(worst, 0.0), tolerance, 'its own period, %.2f s' % own_period(probe) if own_period(probe) > LAG_SLACK_S
                   else 'a tick')
    return 'its value followed the inputs %.1f s late in the %s, more than one period of the slowest input ' \
           '(%.2f s): the timing items are judged from the readings there' % (worst, LEG_WORDS[name], tolerance)


def up_end(probe):
    """Until when a WARNING belongs to the long excursion: the node's own value back below (or the
    input's return, if later)."""
    probe = probe_of(probe)
    return max(probe.schedule['long_down'], reached(probe, 'long_down'))


def back_end(probe):
    """Until when a NORMAL is the return's "at once": the end of the leg just below the threshold."""
    schedule = probe_of(probe).schedule
    return schedule.get('deep_down', schedule['end'])

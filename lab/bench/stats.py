"""Statistics of the benchmark: stream timing, warning latency, CPU share, crossing script, profiles.

No rospy here, so every number the report prints is computed by code the unit tests in
lab/test/unit/test_bench_stats.py drive with synthetic timestamps. All times are seconds of ROS time
as floats.
"""

import collections
import math
import random


def interval_stats(stamps):
    """Timing of a message stream from its receive stamps.

    :param stamps: receive times (s), in arrival order.
    :returns: dict with ``count``, ``rate_hz`` (messages per second over the span from first to last),
        ``sd_ms`` (sample standard deviation of the intervals), ``max_gap_ms``, and ``dev_p50_ms`` /
        ``dev_p99_ms``, percentiles of each interval's distance from the mean interval: they tell a
        steady wobble (both high) from a few scheduler hiccups (median low, p99 and sd high). The
        timing values are None when fewer than three messages make no meaningful statistics.
    """
    stats = {'count': len(stamps), 'rate_hz': None, 'sd_ms': None, 'max_gap_ms': None,
             'dev_p50_ms': None, 'dev_p99_ms': None}
    if len(stamps) < 3:
        return stats
    intervals = [b - a for a, b in zip(stamps, stamps[1:])]
    span = stamps[-1] - stamps[0]
    mean = span / len(intervals)
    variance = sum((x - mean) ** 2 for x in intervals) / (len(intervals) - 1)
    stats['rate_hz'] = len(intervals) / span if span > 0 else None
    stats['sd_ms'] = math.sqrt(variance) * 1e3
    stats['max_gap_ms'] = max(intervals) * 1e3
    deviations = [abs(x - mean) * 1e3 for x in intervals]
    stats['dev_p50_ms'] = percentile(deviations, 50)
    stats['dev_p99_ms'] = percentile(deviations, 99)
    return stats


def percentile(values, q):
    """The q-th percentile (0..100) with linear interpolation between ranks (numpy's default).

    With 20 samples, p99 lies between the two largest: it is effectively the worst case, which is what
    a latency goal over a few dozen crossings can honestly claim.
    """
    if not values:
        return None
    ordered = sorted(values)
    pos = (len(ordered) - 1) * q / 100.0
    low = int(math.floor(pos))
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (ordered[high] - ordered[low]) * (pos - low)


def summarize_ms(values_s):
    """Median, p99, min and max of a list of seconds, in milliseconds (None when empty)."""
    ms = [v * 1e3 for v in values_s]
    return {
        'n': len(ms),
        'median_ms': percentile(ms, 50),
        'p99_ms': percentile(ms, 99),
        'min_ms': min(ms) if ms else None,
        'max_ms': max(ms) if ms else None,
    }


def match_warning_calls(cycles, calls, delay):
    """Pair each scripted excursion with the service calls it caused.

    Excursion i owns the calls from its first reading above (``up``) up to the next excursion's ``up``.
    In that window a correct node makes exactly two calls: WARNING, then NORMAL.

    :param cycles: list of ``(up, down)``: publish stamps of the first reading above the threshold and
        of the first reading back at or below it.
    :param calls: list of ``(stamp, status)`` as the fake service received them.
    :param delay: the node's ``~delay`` (s).
    :returns: ``(warning_latencies, normal_latencies, anomalies)``; latencies in s (WARNING: call minus
        ``up + delay``; NORMAL: call minus ``down``); anomalies lists human-readable problems (missing
        or extra calls) so a broken node cannot pass as a fast one.
    """
    calls = sorted(calls)
    warning, normal, anomalies = [], [], []
    # Calls before the first excursion are wrong too (the node must start NORMAL without a call).
    early = [c for c in calls if cycles and c[0] < cycles[0][0]]
    anomalies.extend('call %s before the first excursion' % status for _, status in early)
    for i, (up, down) in enumerate(cycles):
        end = cycles[i + 1][0] if i + 1 < len(cycles) else math.inf
        window = [(t, s) for t, s in calls if up <= t < end]
        statuses = [s for _, s in window]
        if statuses != ['WARNING', 'NORMAL']:
            anomalies.append('excursion %d: calls %s, expected [WARNING, NORMAL]' % (i, statuses))
        first_warning = next((t for t, s in window if s == 'WARNING'), None)
        if first_warning is None:
            continue
        warning.append(first_warning - (up + delay))
        first_normal = next((t for t, s in window if s == 'NORMAL' and t >= first_warning), None)
        if first_normal is not None:
            normal.append(first_normal - down)
    return warning, normal, anomalies


def crossing_script(count, delay, hold, rng, below=1000.0, above=1600.0):
    """Altitude steps for ``count`` excursions above the threshold, each long enough to warn.

    Each excursion stays above for ``delay + hold`` and then below for ``hold``, both stretched by a
    random 0..0.2 s so crossings fall at every phase of the node's 10 Hz tick: a tick-driven node then
    shows its real spread of latencies rather than one lucky phase.

    :returns: list of ``(t, altitude_m)`` steps, starting below at t = 0; odd entries go above.
    """
    steps = [(0.0, below)]
    t = hold
    for _ in range(count):
        t += rng.uniform(0.0, 0.2)
        steps.append((t, above))
        t += delay + hold + rng.uniform(0.0, 0.2)
        steps.append((t, below))
        t += hold
    return steps


def new_rng(seed):
    """A private RNG, so the script does not depend on who else drew from the global one."""
    return random.Random(seed)


def cpu_percent(ticks, seconds, clock_ticks):
    """CPU use in percent of one core from a delta of utime+stime clock ticks over ``seconds``."""
    return 100.0 * ticks / clock_ticks / seconds if seconds > 0 else None


def within(value, target, tolerance):
    """True when ``value`` is within the relative ``tolerance`` of ``target`` (False when unknown)."""
    return value is not None and abs(value - target) <= tolerance * target


def summarize_collapsed(path, top=10):
    """Self and inclusive share of the busiest functions in a py-spy ``raw`` (collapsed) file.

    Each line is ``frame;frame;...;leaf count``; a frame reads ``function (file:line)``. Line numbers
    are dropped so one function's samples add up.
    """
    self_counts = collections.Counter()
    inclusive = collections.Counter()
    total = 0
    with open(path) as f:
        for line in f:
            stack, _, count = line.rstrip('\n').rpartition(' ')
            if not stack or not count.isdigit():
                continue
            n = int(count)
            total += n
            frames = [_function(frame) for frame in stack.split(';')]
            self_counts[frames[-1]] += n
            for name in set(frames):
                inclusive[name] += n
    if total == 0:
        return 'no samples: the node was idle for the whole window'
    names = [name for name, _ in self_counts.most_common(top)]
    return {'samples': total,
            'functions': [(name, 100.0 * self_counts[name] / total, 100.0 * inclusive[name] / total)
                          for name in names]}


def _function(frame):
    # "publish (rospy/topics.py:880)" -> "publish (rospy/topics.py)"
    name, _, where = frame.partition(' (')
    return '%s (%s)' % (name, where.rsplit(':', 1)[0]) if where else name

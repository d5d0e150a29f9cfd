#!/usr/bin/env python3
"""The measuring halves of `make soak` (soak.py runs the flight): sampling the exam node's memory while
the flight runs, and checking the recorded bag offline afterwards, which also works on its own:

    soak_check.py check --bag SOAK.bag --rss RSS.csv [--threshold 1300] [--delay 5] [--node /exam]

`check` replays nothing: it reads /altitude, /alt_warn_led and /rosout from the bag and
- applies the debounce rule of the exam sheets (question 14b) to the published /altitude values, with
  the harness's oracle (exam_lab.harness.oracle.debounce_transitions), written from the rule's text
  independently of exam.debounce;
- matches every LED change (the drone's latched alt_warn_led) and every delivered service call (the exam
  node's "LED set to ..." log line on /rosout) against the oracle's transitions, in order and in time;
- reports any transition lost (oracle without LED change) or repeated (two equal calls in a row);
- compares the exam node's resident memory at the start and the end of the run.
It prints the figures and exits non-zero on any mismatch, or when the run saw no WARNING at all.

The pure functions (matching, memory trend) take plain lists and are unit-tested in
lab/test/unit/test_soak_check.py.
"""
import argparse
import csv
import re
import statistics
import sys
import time
import xmlrpc.client

from exam_lab.harness.oracle import NORMAL, WARNING, debounce_transitions
from exam_lab.harness.wait import wait_until

LED_STATE = {'GREEN': NORMAL, 'RED': WARNING}
#: A delivered call, as the exam node logs it (exam/src/exam/node.py, the link's on_delivered).
CALL_LOG = re.compile(r'LED set to (NORMAL|WARNING)\s*$')
#: Seconds an observed change may differ from the oracle's instant: /altitude samples the computed
#: value at 10 Hz (up to 0.1 s after the reading), plus call and logging latency on a loaded machine.
TOLERANCE_S = 0.5
#: Memory growth that counts as a leak between the start and the end of the run [KiB], or 3 %.
RSS_SLACK_KIB = 2048
RSS_SLACK_RATIO = 0.03


def changes(events):
    """The events [(time, state)] at which the state differs from the previous event's."""
    result = []
    for t, state in events:
        if not result or result[-1][1] != state:
            result.append((t, state))
    return result


def repeats(events):
    """Events [(time, state)] that repeat the state of the event before them."""
    return [events[i] for i in range(1, len(events)) if events[i][1] == events[i - 1][1]]


def match(expected, observed, tolerance=TOLERANCE_S):
    """Pair expected and observed transitions in order.

    Returns (errors [s] observed - expected of the pairs, problems [str]); problems lists every
    transition lost, unexpected, of the wrong state, or further than `tolerance` from its instant.
    """
    errors, problems = [], []
    for index in range(max(len(expected), len(observed))):
        if index >= len(observed):
            problems.append('lost: %s due at %.2f s' % (expected[index][1], expected[index][0]))
            continue
        if index >= len(expected):
            problems.append('unexpected: %s at %.2f s' % (observed[index][1], observed[index][0]))
            continue
        (t_exp, s_exp), (t_obs, s_obs) = expected[index], observed[index]
        if s_exp != s_obs:
            problems.append('transition %d: %s at %.2f s, the rule wants %s at %.2f s'
                            % (index + 1, s_obs, t_obs, s_exp, t_exp))
            continue
        errors.append(t_obs - t_exp)
        if abs(t_obs - t_exp) > tolerance:
            problems.append('transition %d: %s at %.2f s, %.2f s from the rule\'s %.2f s'
                            % (index + 1, s_obs, t_obs, t_obs - t_exp, t_exp))
    return errors, problems


def rss_trend(samples):
    """(start KiB, end KiB, growth KiB, leak?) from samples [(time s, rss KiB)] in time order.

    The first fifth is start-up (imports, connections, first buffers) and left out; the start and end
    levels are medians of the first and last thirds of the rest, so one sample's noise does not decide.
    """
    steady = samples[len(samples) // 5:]
    if len(steady) < 3:
        raise ValueError('too few memory samples (%d) for a trend' % len(samples))
    third = max(1, len(steady) // 3)
    start = statistics.median(rss for _t, rss in steady[:third])
    end = statistics.median(rss for _t, rss in steady[-third:])
    growth = end - start
    return start, end, growth, growth > max(RSS_SLACK_KIB, RSS_SLACK_RATIO * start)


# --- sampling (while the flight runs) -------------------------------------------------------------

def node_pid(master_uri, node):
    """Pid of a node through the master and the node's XML-RPC API; None while it is not up."""
    try:
        code, _msg, uri = xmlrpc.client.ServerProxy(master_uri).lookupNode('/soak_check', node)
        if code != 1:
            return None
        code, _msg, pid = xmlrpc.client.ServerProxy(uri).getPid('/soak_check')
        return pid if code == 1 else None
    except OSError:
        return None


def read_rss_kib(pid):
    with open('/proc/%d/status' % pid) as status:
        for line in status:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    raise ValueError('no VmRSS for pid %d' % pid)


def sample(master_uri, node, seconds, csv_path, period=5.0):
    """Write the resident memory of ``node`` every ``period`` s for ``seconds`` s to ``csv_path``.

    Returns 0, or 1 when the node never came up (60 s) or died meanwhile.
    """
    pid = wait_until(lambda: node_pid(master_uri, node), 60.0, period=0.5)
    if pid is None:
        print('soak: %s never came up' % node, file=sys.stderr)
        return 1
    print('soak: sampling the memory of %s (pid %d) every %.0f s for %.0f s'
          % (node, pid, period, seconds), flush=True)
    start = time.monotonic()
    with open(csv_path, 'w', newline='') as out:
        writer = csv.writer(out)
        writer.writerow(['elapsed_s', 'rss_kib'])
        while True:
            elapsed = time.monotonic() - start
            try:
                writer.writerow(['%.1f' % elapsed, read_rss_kib(pid)])
            except (OSError, ValueError):
                print('soak: %s (pid %d) died after %.0f s' % (node, pid, elapsed), file=sys.stderr)
                return 1
            out.flush()
            if elapsed >= seconds:
                return 0
            time.sleep(min(period, max(0.0, seconds - elapsed)))


# --- offline check ----------------------------------------------------------------------------------

def read_bag(path, node):
    """(altitude readings, LED events, call events), each [(bag time s, value)], from the bag."""
    import rosbag
    readings, leds, calls = [], [], []
    with rosbag.Bag(path) as bag:
        for topic, msg, stamp in bag.read_messages(topics=['/altitude', '/alt_warn_led', '/rosout']):
            t = stamp.to_sec()
            if topic == '/altitude':
                readings.append((t, msg.data))
            elif topic == '/alt_warn_led':
                leds.append((t, LED_STATE.get(msg.data, msg.data)))
            elif msg.name == node:
                found = CALL_LOG.search(msg.msg)
                if found:
                    calls.append((t, found.group(1)))
    return readings, leds, calls


def check(bag, rss_csv, threshold, delay, node='/exam'):
    """Check the soak run recorded in ``bag`` and ``rss_csv``; print the figures; 0 when it passes."""
    readings, leds, calls = read_bag(bag, node)
    if not readings:
        print('soak: FAIL, no /altitude in %s' % bag)
        return 1
    # Times from the first /altitude on, so every figure and failure reads as "s into the run".
    t0 = readings[0][0]
    readings, leds, calls = ([(t - t0, value) for t, value in events] for events in (readings, leds, calls))
    duration = readings[-1][0]
    expected = debounce_transitions(readings, threshold, delay)
    # The LED starts GREEN (NORMAL) before any call: its first, latched message is no transition.
    led_changes = changes([(float('-inf'), NORMAL)] + leds)[1:]
    led_errors, led_problems = match(expected, led_changes)
    call_errors, call_problems = match(expected, calls)
    repeated = repeats(calls)
    with open(rss_csv, newline='') as src:
        rss = [(float(row['elapsed_s']), int(row['rss_kib'])) for row in csv.DictReader(src)]
    rss_start, rss_end, growth, leak = rss_trend(rss)

    def spread(errors):
        if not errors:
            return 'none'
        return 'mean %+.3f s, max |%.3f| s' % (statistics.mean(errors), max(abs(e) for e in errors))

    warnings = sum(1 for _t, state in expected if state == WARNING)
    print('soak: %.1f min recorded, %d /altitude messages (%.2f Hz), threshold %.1f m, delay %.1f s'
          % (duration / 60.0, len(readings), (len(readings) - 1) / duration if duration else 0.0,
             threshold, delay))
    print('soak: oracle %d transitions (%d WARNING); LED %d changes (timing %s); calls %d (timing %s); '
          '%d repeated calls' % (len(expected), warnings, len(led_changes), spread(led_errors),
                                 len(calls), spread(call_errors), len(repeated)))
    print('soak: exam RSS %d KiB -> %d KiB (%+d KiB) over %d samples, %s'
          % (rss_start, rss_end, growth, len(rss), 'GROWING' if leak else 'flat'))
    shown = 6  # enough to see the rhythm of the flight; a 30 min run has dozens
    for t, state in expected[:shown]:
        print('soak:   rule %-7s at %8.2f s' % (state, t))
    if len(expected) > shown:
        print('soak:   ... %d more' % (len(expected) - shown))
    problems = (['LED ' + p for p in led_problems] + ['call ' + p for p in call_problems]
                + ['repeated call: %s at %.2f s' % (s, t) for t, s in repeated])
    if warnings == 0:
        problems.append('no WARNING in the whole run: it proves nothing (run longer)')
    if leak:
        problems.append('exam node memory grew by %d KiB' % growth)
    for problem in problems:
        print('soak: FAIL ' + problem)
    print('soak: %s' % ('FAIL' if problems else 'PASS'))
    return 1 if problems else 0


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    sub = parser.add_subparsers(dest='command', required=True)
    checker = sub.add_parser('check', help='check a soak bag offline')
    checker.add_argument('--bag', required=True)
    checker.add_argument('--rss', required=True)
    checker.add_argument('--threshold', type=float, default=1300.0)
    checker.add_argument('--delay', type=float, default=5.0)
    checker.add_argument('--node', default='/exam')
    args = parser.parse_args(argv)
    return check(args.bag, args.rss, args.threshold, args.delay, args.node)


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

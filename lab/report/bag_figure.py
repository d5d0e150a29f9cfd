#!/usr/bin/env python3
"""Draws a recorded flight (or dive) as the report's figure: the published value, the threshold, the
LED, the service calls, and the true value when the bag has it. Debian 12 has no rqt_plot; this is the
short way to see a run as a picture (README, "See a flight as a picture").

Usage:
  rosbag record -O flight.bag /temperature /pressure /altitude /alt_warn_led    (Ctrl-C to stop)
  python3 lab/report/bag_figure.py flight.bag flight.png [--threshold 1300] [--delay 5]

The mode comes from the bag (``/altitude`` or ``/depth``); the threshold and delay are those the run
used (defaults: the mode's default threshold, 5 s), since a bag does not record parameters. Times count
from the bag's first message. Prints what it found: the spans above the threshold (the value recomputed
at each reading, as the exam node decides) and the LED's changes, one per successful service call.
"""
import argparse
import sys

from exam.modes import MODES

import analysis
import figures


def mode_of(series):
    """The exam mode whose output topic the bag holds (``/altitude`` or ``/depth``)."""
    found = [mode for mode in MODES.values() if '/' + mode.output in series]
    if len(found) != 1:
        raise ValueError('the bag must hold exactly one of %s; it has %s'
                         % (', '.join('/' + m.output for m in MODES.values()), ', '.join(sorted(series))))
    return found[0]


def summary_lines(facts, mode, threshold):
    """What the figure shows, in words: the spans beyond the threshold and the LED's changes."""
    lines = ['%s: %d values published over %.1f s' % (mode.output, len(facts['published']),
                                                      facts['published'][-1][0] if facts['published'] else 0.0)]
    for start, end, duration in facts['episodes']:
        lines.append('above %g %s from %.1f s %s' % (threshold, mode.unit, start,
                                                     'to the end' if end is None else
                                                     'to %.1f s (%.1f s)' % (end, duration)))
    lines.append('LED: ' + (', '.join('%s at %.1f s' % (colour, t) for t, colour in facts['changes'])
                            or 'no change'))
    return lines


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('bag', help='a bag recorded with rosbag record')
    parser.add_argument('png', help='the figure to write')
    parser.add_argument('--threshold', type=float, help='the run\'s threshold (default: the mode\'s)')
    parser.add_argument('--delay', type=float, default=5.0, help='the run\'s delay [s] (default 5)')
    args = parser.parse_args(argv)
    series = analysis.read_bag(args.bag)
    try:
        mode = mode_of(series)
    except ValueError as err:
        sys.exit('bag_figure: %s' % err)
    threshold = mode.default_threshold if args.threshold is None else args.threshold
    inputs = ['/' + i.topic for i in mode.inputs]
    missing = [topic for topic in inputs + ['/' + mode.led_topic] if topic not in series]
    if missing:
        sys.exit('bag_figure: the bag lacks %s: record %s' % (', '.join(missing), ' '.join(
            inputs + ['/' + mode.output, '/' + mode.led_topic])))
    truth = [topic for topic in series if topic.endswith('/true_' + mode.output)]
    origin = min(t for messages in series.values() for t, _ in messages)
    facts = analysis.summarise(series, inputs, mode.compute, '/' + mode.output, truth[0] if truth else None,
                               '/' + mode.led_topic, threshold, args.delay, origin)
    figures.run_figure(args.png, facts, args.bag, mode.output, mode.unit, threshold, args.delay,
                       '/' + mode.service, invert=mode.output == 'depth',
                       xlabel='time since the bag\'s first message [s]')
    print('\n'.join(summary_lines(facts, mode, threshold)))
    print('bag_figure: %s written' % args.png)


if __name__ == '__main__':
    main()

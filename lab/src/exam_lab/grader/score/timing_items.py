"""The rubric's items on the warning service, timed on the flight (:mod:`~exam_lab.grader.score.flight`):
WARNING while above and NORMAL once back (Q13), the launch file's threshold obeyed (Q14a), the delay
before the WARNING and the NORMAL at once (Q14b). Pure, no rospy.

Each ``score_*`` takes the views of the inspection's and the session's records
(:func:`~exam_lab.grader.score.measured.static_of`, :func:`~exam_lab.grader.score.measured.session_of`)
and gives the item's ``{"id", "points", "max", "evidence"}``. The windows are read through
:mod:`~exam_lab.grader.score.flight` at each call (a rescore's test narrows one there).
"""
import math

from exam_lab.grader.score import flight
from exam_lab.grader.score.measured import (inputs_lost, item, main_probe, no_node_words, node_ran, not_run, otherwise,
                                            stayed_up, threshold_probe, unstarted_runs)
from exam_lab.grader.score.sheets import DELAY, REQUESTS, SHEETS
from exam_lab.grader.score.tolerances import LOOP_REPEATS, NORMAL_LATE_S, WARNING_EARLY_S


def score_q13(sheet, session):
    probe = main_probe(session)
    schedule = flight.schedule_of(probe)
    if not node_ran(session) or schedule is None:
        return item('Q13', 0, not_run(session))
    if flight.unreached_legs(probe, ['long_up']):
        return item('Q13', 0, '%s (%s)' % (flight.leg_words(probe, 'long_up'), flight.driven_by(probe)))
    service = SHEETS[sheet].service
    up = flight.calls_between(probe, schedule['long_up'], flight.up_end(probe), 'WARNING')
    down_judged = not flight.unreached_legs(probe, ['long_down'])
    down = flight.calls_between(probe, schedule['long_down'], schedule['end'], 'NORMAL') if up else []
    repeats = flight.repeats(probe, schedule['rest'])
    total = len(flight.calls_between(probe, schedule['rest'], schedule['end']))
    looped = repeats >= LOOP_REPEATS
    above = schedule['long_down'] - flight.reached(probe, 'long_up')
    up_from = flight.timed_from(probe, 'long_up', stays=True)[0]
    if up and down and down_judged:
        points = 4.0
        evidence = 'WARNING while above, NORMAL once back below'
    elif up:
        points = 2.0
        evidence = 'WARNING while above, but %s' % (
            'no NORMAL within %.1f s back below' % (schedule['end'] - schedule['long_down']) if down_judged
            else flight.leg_words(probe, 'long_down'))
    else:
        points = 0.0
        evidence = 'no WARNING call on %s while the node\'s own value stayed above the threshold for %.1f s' % (
            service, above)
        others = sorted(set(r for t, m, r, _ in flight.calls(probe) if m not in REQUESTS))
        if others:
            evidence += ' (it called with %s, which mean neither WARNING nor NORMAL)' % ', '.join(
                '"%s"' % r[:40] for r in others[:4])
    if up and up[0][0] - up_from > flight.warning_window(probe)[1]:
        evidence += ' (the WARNING came late, %.1f s after the value went above: the flight waited for it)' % (
            up[0][0] - up_from)
    if up and down and down_judged and down[0][0] > flight.back_end(probe):
        evidence += ' (the NORMAL came late, %.1f s after the value came back below: the flight waited for it)' % (
            down[0][0] - flight.timed_from(probe, 'long_down')[0])
    refused = flight.refused_calls(probe, schedule['rest'], schedule['end'])
    if refused and points:
        points /= 2
        evidence += ('; but the drone refused its %s (success False: the LED never changed): the sheet\'s '
                     'requests are "WARNING" and "NORMAL", so half of Q13, once (the timing items judge when it '
                     'called)' % flight.refused_words(refused))
    if looped:
        points /= 2
        evidence += '; but called in a loop: %d calls in %.0f s of flight, %d repeating the previous status' % (
            total, schedule['end'] - schedule['rest'], repeats)
    else:
        evidence += '; %d call(s) in %.0f s of flight, %d repeating the previous status' % (
            total, schedule['end'] - schedule['rest'], repeats)
    return item('Q13', points, '%s (%s)' % (evidence, flight.driven_by(probe)))


def _reads(static, threshold):
    """What of the student's code reads the launch file's threshold: a parameter of that name (the
    last part of its name, however resolved), or for an ``args=`` word, argparse's option of that name
    or the index the code takes of ``rospy.myargv()`` / ``sys.argv`` (a positional argparse name too)."""
    name = threshold.name
    if threshold.how == 'args':
        found = static.args_in_code or ()
        if name.startswith('-'):
            return [a for a in found if a == name]
        return [a for a in found if a == name or not a.startswith(('-', 'argv['))]
    early = _read_too_early(static)
    return [p for p in otherwise(static.params_in_code, ()) if p.strip('~/').split('/')[-1] == name.split('/')[-1]
            and p not in early]


def _read_too_early(static):
    """{private parameter name: where} the code reads before init_node (then rospy resolves it against
    ``<ns>/unnamed``, never the node's name: ``rospy/names.py``)."""
    out = {}
    for entry in (static.code.private_before_init if static.code else None) or ():
        where, _, name = entry.rpartition(': ')
        out.setdefault(name, where)
    return out


def score_q14a(sheet, static, session):
    threshold = static.threshold
    if static.launch_files is None:
        return item('Q14a', 0, 'not judged: the package was not read (see runs)')
    if threshold is None:
        return item('Q14a', 0, otherwise(static.threshold_reason, 'no threshold parameter in the launch file'))
    name = threshold.name
    what = 'argument %s' % name if threshold.how == 'args' else 'parameter %s' % name
    if not node_ran(session):
        return item('Q14a', 0, '%s = %s in the launch file; %s' % (what, threshold.value, not_run(session)))
    read = _reads(static, threshold)
    # Judged from the code only for a node that runs: one that dies has not shown it uses anything.
    static_points = 0.5 if read and stayed_up(session) else 0.0
    static_note = ('the code reads %s' % ', '.join(read)) if read else 'the code reads no %s of that name' % (
        'argument' if threshold.how == 'args' else 'parameter')
    if read and not stayed_up(session):
        static_note += ', but the node died (see runs)'
    early = [(n, w) for n, w in sorted(_read_too_early(static).items())
             if n.strip('~/').split('/')[-1] == name.split('/')[-1]]
    if early:
        static_note += '; it reads %s before init_node (%s), where rospy resolves it as .../unnamed/%s (its name ' \
                       'until then), not as the node\'s parameter' % (early[0][0], early[0][1], early[0][0].lstrip('~'))
    probe2 = threshold_probe(session)
    skipped = session.threshold_skipped
    unstarted = [r for r in unstarted_runs(session) if r.tag == 'threshold']
    if probe2 is None or unstarted:
        why = ('in the threshold run %s, while the main run\'s node did (a doubt, see the status)'
               % no_node_words(probe2) if unstarted else skipped or threshold.not_rewritable or 'the threshold run failed')
        return item('Q14a', static_points, '%s = %s in the launch file; its effect could not be observed (%s); '
                    'judged from the code: %s' % (what, threshold.value, why, static_note))
    lost = inputs_lost(main_probe(session), probe2)
    if lost:  # the grader's drone did not reach the node there: nothing of the parameter was seen
        return item('Q14a', static_points, '%s = %s in the launch file; its effect could not be observed (in the '
                    'threshold run the node never received %s, which it received in the main run: the grader\'s '
                    'drone did not reach it); judged from the code: %s' % (what, threshold.value, ', '.join(lost),
                                                                         static_note))
    schedule = probe2.schedule or {}
    # The threshold run flies the main run's legs (its long excursion above the new value, below the
    # launch file's); measurements kept from before flew a single step.
    leg = 'long_up' if 'long_up' in schedule else 'step' if 'step' in schedule else None
    if leg is None:
        return item('Q14a', 0, 'with %s = %g the node did not run' % (name, probe2.threshold))
    if flight.unreached_legs(probe2, [leg]):
        return item('Q14a', static_points, '%s = %s; set to %g: %s; judged from the code: %s' % (
            what, threshold.value, probe2.threshold, flight.leg_words(probe2, leg), static_note))
    end = schedule['long_down'] if leg == 'long_up' else schedule['end']
    warned = flight.calls_between(probe2, schedule[leg], end, 'WARNING')
    if leg == 'long_up':
        calibration = probe2.calibration
        side = calibration.hi if calibration else None
    else:
        calibration = main_probe(session).calibration
        side = calibration.lo if calibration else None
    flown = otherwise(side.target if side else None, float('nan'))
    if warned:
        return item('Q14a', 1, 'launch file %s = %s; set to %g, the node warned %.2f s after %s went '
                    'above it, flown at %.1f, a value it kept NORMAL with %s' % (
                        what, threshold.value, probe2.threshold, warned[0][0] - flight.reached(probe2, leg),
                        'the first reading' if flight.silent(probe2) else 'its own value', flown, threshold.value))
    return item('Q14a', 0, 'launch file %s = %s; set to %g, the node stayed NORMAL for %.1f s at %.1f, above the new '
                'threshold: it does not obey the %s (%s)' % (
                    what, threshold.value, probe2.threshold, end - flight.reached(probe2, leg), flown,
                    'argument' if threshold.how == 'args' else 'parameter', static_note))


def score_q14b(sheet, session):
    probe = main_probe(session)
    schedule = flight.schedule_of(probe)
    if not node_ran(session) or schedule is None:
        return item('Q14b', 0, not_run(session))
    if flight.unreached_legs(probe, ['long_up']):
        return item('Q14b', 0, flight.leg_words(probe, 'long_up'))
    delay = otherwise(probe.delay, DELAY)
    early, late = flight.warning_window(probe)
    warnings = flight.calls_between(probe, schedule['long_up'], flight.up_end(probe), 'WARNING')
    if not warnings:
        return item('Q14b', 0, 'no WARNING in %.1f s above the threshold, so no delay to judge'
                    % (schedule['long_down'] - flight.reached(probe, 'long_up')))
    up_from, up_words = flight.timed_from(probe, 'long_up', stays=True)
    latency = warnings[0][0] - up_from
    warn_ok = early <= latency <= late
    short_judged = not flight.unreached_legs(probe, ['short_up'])
    short = flight.calls_between(probe, schedule['short_up'], schedule['long_up'], 'WARNING')
    short_from = flight.timed_from(probe, 'short_up')[0]
    short_back = flight.timed_from(probe, 'short_down')[0]
    # Above for the delay in its own frame (only a node beyond the lag tolerance gets there, and it is
    # then timed from the readings): a WARNING there is no mistake of the delay.
    own_long = short_back - short_from >= delay - WARNING_EARLY_S
    short_ok = short_judged and (not short or own_long)
    normal_judged = not flight.unreached_legs(probe, ['long_down'])
    back_from, back_words = flight.timed_from(probe, 'long_down')
    normals = flight.calls_between(probe, schedule['long_down'], flight.back_end(probe), 'NORMAL')
    normal_latency = normals[0][0] - back_from if normals else None
    # Timed from the readings for a silent output: its node may see the reading one slowest period later.
    normal_late = NORMAL_LATE_S + (flight.slowest_period(probe) if flight.silent(probe) else 0.0)
    normal_ok = normal_judged and normal_latency is not None and normal_latency <= normal_late
    points = 1.5 * warn_ok + 1.0 * short_ok + (0.5 * normal_ok if (warn_ok or short_ok) else 0.0)
    notes = ['WARNING %.2f s after %s went above the threshold and stayed (%s: %.2f-%.2f s%s) (%s/1.5)' % (
        latency, up_words, 'ok' if warn_ok else 'outside', early, late,
        ', at its own pace' if flight.own_period(probe) else '', 1.5 if warn_ok else 0)]
    if not short_judged:
        notes.append('short excursion: %s (0/1)' % flight.leg_words(probe, 'short_up'))
    else:
        stayed = (flight.leg_lag(probe, 'short_down') or 0.0)
        notes.append('%.1f s excursion above%s%s: %s (%s/1)' % (
            short_back - short_from, '' if short_from != schedule['short_up'] else ' (from the readings)',
            ' (the node\'s own value stayed above %.1f s longer: it did not follow its inputs)' % stayed
            if stayed > flight.lag_tolerance(probe) else '',
            'no WARNING' if not short else 'WARNING %.2f s after it began%s' % (
                short[0][0] - short_from, ', as long as the delay in its own values' if own_long else ''),
            1 if short_ok else 0))
    below = _near_words(probe)
    if not normal_judged:
        notes.append('NORMAL: %s (0/0.5)' % flight.leg_words(probe, 'long_down'))
    elif normal_latency is None:
        notes.append('no NORMAL while %s was back just below the threshold%s%s (0/0.5)' % (
            back_words, below, _later_normal_words(probe, back_from)))
    else:
        notes.append('NORMAL %.2f s after %s came back just below the threshold%s (%s/0.5%s)' % (
            normal_latency, back_words, below, 0.5 if normal_ok and (warn_ok or short_ok) else 0,
            '' if warn_ok or short_ok else ', counted only with a delay'))
    return item('Q14b', points, '; '.join(notes))


def _later_normal_words(probe, back_from):
    """What became of the NORMAL the return just below did not see: it came soon after the value went
    further below (the node waits for a margin), or later (it waits for a time: not at once), or not."""
    schedule = probe.schedule
    later = flight.calls_between(probe, flight.back_end(probe), schedule['end'], 'NORMAL')
    if not later:
        return ''
    deeper = flight.back_end(probe)
    if later[0][0] - deeper <= flight.lag_tolerance(probe):  # as soon as its value followed the input further below
        return '; it came %.2f s later, further below: it waits for a margin' % (later[0][0] - back_from)
    return '; it came %.2f s after the value came back, %.2f s after the input went further below: it waits for ' \
           'a time, not at once' % (later[0][0] - back_from, later[0][0] - deeper)


def _near_words(probe):
    """How far below the threshold the node's own value was on the return ('' when not recorded)."""
    near = probe.calibration.near if probe.calibration else None
    value, threshold = (near.value if near else None), probe.threshold
    if value is None or threshold is None or not math.isfinite(value):
        return ''
    return ' (%.2f, %.2f below)' % (value, threshold - value)

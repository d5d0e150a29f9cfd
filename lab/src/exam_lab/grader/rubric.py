"""The rubric: points for each item from what was measured, and why. Pure functions, no rospy.

Input: ``static`` (what the runner read in the package: the launch file, the threshold parameter,
the parameters the code reads) and ``session`` (what :mod:`exam_lab.grader.session` measured: the
build, the main run and the threshold run, each with the probe's result). Output: one
``{"id", "points", "max", "evidence"}`` per item of :data:`exam_lab.grader.sheets.ITEMS`.

Each tolerance is a constant below; docs/grading.md says why each is what it is.
"""
import math

from exam_lab.grader.sheets import DELAY, ITEMS, SHEETS

#: Question 11: the rate the sheet asks for, and the accepted relative deviation.
RATE_HZ = 10.0
RATE_TOLERANCE = 0.10
#: Question 11: a published value agrees when within this many metres, or this share of the value.
VALUE_TOLERANCE_M = 0.5
VALUE_TOLERANCE_REL = 0.001
#: Question 14b: WARNING accepted from delay - EARLY to delay + LATE s after the first reading beyond.
WARNING_EARLY_S = 0.3
WARNING_LATE_S = 0.5
#: Question 14b: NORMAL accepted up to this many s after the first reading back (at once).
NORMAL_LATE_S = 0.5
#: Question 13: this many calls repeating the previous status make "called in a loop".
LOOP_REPEATS = 3


def item(item_id, points, evidence):
    maximum = ITEMS[item_id][0]
    return {'id': item_id, 'points': round(max(0.0, min(points, maximum)) * 2) / 2, 'max': maximum,
            'evidence': evidence}


def main_probe(session):
    runs = [r for r in (session or {}).get('runs', []) if r['tag'] == 'main']
    return runs[0]['probe'] if runs and runs[0].get('probe') else None


def threshold_probe(session):
    runs = [r for r in (session or {}).get('runs', []) if r['tag'] == 'threshold']
    return runs[0]['probe'] if runs and runs[0].get('probe') else None


def node_ran(session):
    probe = main_probe(session)
    return bool(probe and probe.get('nodes'))


def stayed_up(session):
    """True when the node registered in the main run and roslaunch never saw it end."""
    runs = [r for r in (session or {}).get('runs', []) if r['tag'] == 'main']
    return node_ran(session) and not runs[0].get('launch', {}).get('ended')


def _not_run(session):
    build = (session or {}).get('build') or {}
    if build.get('status') != 0:
        return 'not measured: the package did not build (see runs)'
    return 'not measured: the node did not run (see runs)'


def score_runs(session):
    build = (session or {}).get('build')
    if build is None:
        return item('runs', 0, (session or {}).get('error', 'the submission could not be prepared'))
    if build['status'] is None:
        return item('runs', 0, 'catkin_make did not finish within %.0f s' % build['timeout'])
    if build['status'] != 0:
        return item('runs', 0, 'catkin_make failed (exit %s) in a workspace of its own next to the '
                    'simulators; its last lines:\n%s' % (build['status'], build['tail']))
    problems = []
    for run in session.get('runs', []):
        probe, launch = run.get('probe'), run.get('launch', {})
        for line in launch.get('not_started', []):
            problems.append('%s run: %s' % (run['tag'], line))
        for ended in launch.get('ended', []):
            problems.append('%s run: node %s %s%s' % (run['tag'], ended['node'],
                                                      'died' if ended['how'] == 'died' else 'ended',
                                                      ' (%s)' % ended['detail'] if ended['detail'] else ''))
        if probe is None:
            problems.append('%s run: the probe failed: %s' % (run['tag'], run.get('probe_error', '?')))
        elif not probe.get('nodes') and not launch.get('ended'):
            problems.append('%s run: no node of the package registered with the master within %.0f s'
                            % (run['tag'], probe.get('start_timeout', 0)))
    if not session.get('runs'):
        problems.append('the node was not run')
    if problems:
        tails = [r['launch']['tail'] for r in session.get('runs', []) if r.get('launch', {}).get('tail')]
        return item('runs', 1, 'builds (%.0f s); but: %s%s' % (
            build['seconds'], '; '.join(problems), '\nlast lines of its launch:\n%s' % tails[0] if tails else ''))
    seconds = sum(r.get('seconds', 0) for r in session['runs'])
    return item('runs', 2, 'builds (%.0f s); node up in %.1f s and still up after %.0f s of flight in %d run(s)'
                % (build['seconds'], main_probe(session).get('node_seen_s') or 0, seconds, len(session['runs'])))


def score_q10(sheet, session):
    probe = main_probe(session)
    if not node_ran(session):
        return item('Q10', 0, _not_run(session))
    subscribed = probe.get('subscribed', {})
    got = [t for t, nodes in sorted(subscribed.items()) if nodes]
    missing = [t for t, nodes in sorted(subscribed.items()) if not nodes]
    evidence = 'subscribes to %s' % (', '.join(got) or 'neither input')
    if missing:
        evidence += '; never to %s' % ', '.join(missing)
    return item('Q10', len(got), evidence)


def _agrees(expected, published):
    return published is not None and math.isfinite(published) and \
        abs(published - expected) <= max(VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * abs(expected))


def score_q11(sheet, session):
    probe = main_probe(session)
    if not node_ran(session):
        return item('Q11', 0, _not_run(session))
    output = probe.get('output') or {}
    expected = output.get('expected', '/' + SHEETS[sheet].output)
    points, notes = 0.0, []
    if output.get('topic') == expected and output.get('type') == 'std_msgs/Float32':
        points += 1.5
        notes.append('publisher: %s std_msgs/Float32 (1.5)' % expected)
    elif output.get('topic') == expected:
        notes.append('publisher: %s is %s, not std_msgs/Float32 (0/1.5)' % (expected, output.get('type')))
    elif output.get('topic'):
        notes.append('publisher: no %s; it publishes %s (%s) instead, measured there (0/1.5)'
                     % (expected, output['topic'], output.get('type')))
    else:
        notes.append('publisher: no %s, and no number topic to measure (publishes %s) (0/4)'
                     % (expected, ', '.join(output.get('candidates', [])) or 'nothing'))
        return item('Q11', 0, '; '.join(notes))
    rate = probe.get('rate') or {}
    hz = rate.get('hz')
    if hz is not None and abs(hz - RATE_HZ) <= RATE_TOLERANCE * RATE_HZ:
        points += 1.0
        notes.append('rate %.2f Hz (1)' % hz)
    elif hz is not None:
        notes.append('rate %.2f Hz, not 10 Hz +- %d %% (longest gap %.2f s) (0/1)'
                     % (hz, RATE_TOLERANCE * 100, rate.get('max_gap') or 0, ))
    else:
        notes.append('rate: %d message(s) in the flight, cannot measure (0/1)' % rate.get('samples', 0))
    rows = probe.get('formula', [])
    wrong = [r for r in rows if not _agrees(r['expected'], r['published'])]
    shown = '; '.join('%s -> %s, expected %.2f%s' % (
        ', '.join('%s %g' % (k.lstrip('/'), v) for k, v in sorted(r['inputs'].items())),
        'nothing' if r['published'] is None else '%.2f' % r['published'], r['expected'],
        '' if r['published'] is None or not math.isfinite(r['published'])
        else ' (error %+.2f m)' % (r['published'] - r['expected'])) for r in rows)
    if rows and not wrong:
        points += 1.5
        notes.append('values agree with equation (1) within max(%.1f m, %.1f %%) (1.5): %s'
                     % (VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, shown))
    else:
        notes.append('values: %d of %d disagree with equation (1) beyond max(%.1f m, %.1f %%) (0/1.5): %s'
                     % (len(wrong), len(rows), VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, shown or 'none read'))
    if rate.get('non_finite'):
        notes.append('%d published value(s) were not finite numbers' % rate['non_finite'])
    return item('Q11', points, '; '.join(notes))


def score_q12(sheet, static):
    launch = static.get('launch')
    if launch is None:
        return item('Q12', 0, 'no launch file in the package starts an exam node (launch files: %s)'
                    % (', '.join(static.get('launch_files', [])) or 'none'))
    drone = SHEETS[sheet]
    has_drone = launch['starts_drone']
    exam_ok = launch['exam_type_found']
    where = launch['file']
    if has_drone and exam_ok:
        return item('Q12', 1, '%s starts %s/%s and exam/%s' % (where, drone.drone_pkg, drone.drone_type,
                                                               launch['exam_type']))
    notes = []
    if not has_drone:
        notes.append('does not start the drone (%s/%s)' % (drone.drone_pkg, drone.drone_type))
    if not exam_ok:
        notes.append('starts exam/%s, which is no executable of the package' % launch['exam_type'])
    return item('Q12', 0.5, '%s starts an exam node but %s' % (where, ' and '.join(notes)))


def _calls_between(probe, start, end, status=None):
    return [(t, s) for t, s in probe.get('calls', []) if start <= t <= end and (status is None or s == status)]


def _repeats(probe, since):
    calls = sorted(probe.get('calls', []))
    return len([1 for previous, call in zip(calls, calls[1:]) if call[0] >= since and call[1] == previous[1]])


def _flight(probe):
    schedule = (probe or {}).get('schedule') or {}
    return schedule if 'long_up' in schedule else None


def _driven_by(probe):
    calibration = probe.get('calibration') or {}
    if calibration.get('by') == 'own':
        return 'driven at the node\'s own values %.1f / %.1f' % (calibration['lo']['value'],
                                                               calibration['hi']['value'])
    return 'driven at the oracle\'s values %.1f / %.1f (%s)' % (
        calibration.get('lo', {}).get('x', float('nan')), calibration.get('hi', {}).get('x', float('nan')),
        calibration.get('reason', ''))


def score_q13(sheet, session):
    probe = main_probe(session)
    schedule = _flight(probe)
    if not node_ran(session) or schedule is None:
        return item('Q13', 0, _not_run(session))
    service = SHEETS[sheet].service
    up = _calls_between(probe, schedule['long_up'], schedule['long_down'], 'WARNING')
    down = _calls_between(probe, schedule['long_down'], schedule['end'], 'NORMAL') if up else []
    repeats = _repeats(probe, schedule['rest'])
    total = len(_calls_between(probe, schedule['rest'], schedule['end']))
    looped = repeats >= LOOP_REPEATS
    if up and down:
        points = 4.0
        evidence = 'WARNING while above, NORMAL once back below'
    elif up:
        points = 2.0
        evidence = 'WARNING while above, but no NORMAL within %.1f s back below' % (schedule['end'] - schedule['long_down'])
    else:
        points = 0.0
        evidence = 'no WARNING call on %s while the value stayed above the threshold for %.1f s' % (
            service, schedule['long_down'] - schedule['long_up'])
    if looped:
        points /= 2
        evidence += '; but called in a loop: %d calls in %.0f s of flight, %d repeating the previous status' % (
            total, schedule['end'] - schedule['rest'], repeats)
    else:
        evidence += '; %d call(s) in %.0f s of flight, %d repeating the previous status' % (
            total, schedule['end'] - schedule['rest'], repeats)
    return item('Q13', points, '%s (%s)' % (evidence, _driven_by(probe)))


def score_q14a(sheet, static, session):
    threshold = static.get('threshold')
    if threshold is None:
        return item('Q14a', 0, static.get('threshold_reason', 'no threshold parameter in the launch file'))
    name = threshold['name']
    if not node_ran(session):
        return item('Q14a', 0, 'parameter %s = %s in the launch file; %s' % (name, threshold['value'], _not_run(session)))
    read = [p for p in static.get('params_in_code', []) if p.strip('~/').split('/')[-1] == name.split('/')[-1]]
    # Judged from the code only for a node that runs: one that dies has not shown it uses anything.
    static_points = 0.5 if read and stayed_up(session) else 0.0
    static_note = ('the code reads %s' % ', '.join(read)) if read else 'the code reads no parameter of that name'
    if read and not stayed_up(session):
        static_note += ', but the node died (see runs)'
    probe2 = threshold_probe(session)
    skipped = session.get('threshold_skipped')
    if probe2 is None:
        why = skipped or threshold.get('not_rewritable') or 'the threshold run failed'
        return item('Q14a', static_points, 'parameter %s = %s in the launch file; its effect could not be '
                    'observed (%s); judged from the code: %s' % (name, threshold['value'], why, static_note))
    schedule = probe2.get('schedule') or {}
    if 'step' not in schedule:
        return item('Q14a', 0, 'with %s = %g the node did not run' % (name, probe2['threshold']))
    warned = _calls_between(probe2, schedule['step'], schedule['end'], 'WARNING')
    main = main_probe(session)
    lo = (main.get('calibration') or {}).get('lo', {})
    if warned:
        return item('Q14a', 1, 'launch file %s = %s; set to %g, the node warned %.2f s after reaching %.1f, a value '
                    'it kept NORMAL with %s' % (name, threshold['value'], probe2['threshold'],
                                                warned[0][0] - schedule['step'], lo.get('target', float('nan')),
                                                threshold['value']))
    return item('Q14a', 0, 'launch file %s = %s; set to %g, the node stayed NORMAL for %.1f s at %.1f, above the new '
                'threshold: it does not obey the parameter (%s)' % (
                    name, threshold['value'], probe2['threshold'], schedule['end'] - schedule['step'],
                    lo.get('target', float('nan')), static_note))


def score_q14b(sheet, session):
    probe = main_probe(session)
    schedule = _flight(probe)
    if not node_ran(session) or schedule is None:
        return item('Q14b', 0, _not_run(session))
    delay = probe.get('delay', DELAY)
    warnings = _calls_between(probe, schedule['long_up'], schedule['long_down'], 'WARNING')
    if not warnings:
        return item('Q14b', 0, 'no WARNING in %.1f s above the threshold, so no delay to judge'
                    % (schedule['long_down'] - schedule['long_up']))
    latency = warnings[0][0] - schedule['long_up']
    warn_ok = delay - WARNING_EARLY_S <= latency <= delay + WARNING_LATE_S
    short = _calls_between(probe, schedule['short_up'], schedule['long_up'], 'WARNING')
    short_ok = not short
    normals = _calls_between(probe, schedule['long_down'], schedule['end'], 'NORMAL')
    normal_latency = normals[0][0] - schedule['long_down'] if normals else None
    normal_ok = normal_latency is not None and normal_latency <= NORMAL_LATE_S
    points = 1.5 * warn_ok + 1.0 * short_ok + (0.5 * normal_ok if (warn_ok or short_ok) else 0.0)
    notes = ['WARNING %.2f s after the first reading above (%s: %.1f-%.1f s) (%s/1.5)' % (
        latency, 'ok' if warn_ok else 'outside', delay - WARNING_EARLY_S, delay + WARNING_LATE_S,
        1.5 if warn_ok else 0)]
    notes.append('%.1f s excursion: %s (%s/1)' % (
        schedule['short_down'] - schedule['short_up'],
        'no WARNING' if short_ok else 'WARNING %.2f s after it began' % (short[0][0] - schedule['short_up']),
        1 if short_ok else 0))
    if normal_latency is None:
        notes.append('no NORMAL after the return below (0/0.5)')
    else:
        notes.append('NORMAL %.2f s after the first reading back below (%s/0.5%s)' % (
            normal_latency, 0.5 if normal_ok and (warn_ok or short_ok) else 0,
            '' if warn_ok or short_ok else ', counted only with a delay'))
    return item('Q14b', points, '; '.join(notes))


def score(sheet, static, session):
    """Every item of the rubric, in order."""
    return [score_runs(session), score_q10(sheet, session), score_q11(sheet, session),
            score_q12(sheet, static), score_q13(sheet, session), score_q14a(sheet, static, session),
            score_q14b(sheet, session)]

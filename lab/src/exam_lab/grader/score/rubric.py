"""The rubric: points for each item from what was measured, and why. Pure functions, no rospy.

Input: ``static`` (what the runner read in the package: the launch file, the threshold parameter,
the parameters the code reads) and ``session`` (what :mod:`exam_lab.grader.host.session` measured: the
build, the main run and the threshold run, each with the probe's result). Output: one
``{"id", "points", "max", "evidence"}`` per item of :data:`exam_lab.grader.score.sheets.ITEMS`.

Each tolerance is a constant below; docs/grading.md says why each is what it is.
"""
import math
import re

from exam_lab.grader.score.sheets import DELAY, ITEMS, REQUESTS, SHEETS, request_meaning
from exam_lab.harness import oracle

#: Question 11: the rate the sheet asks for, and the accepted relative deviation.
RATE_HZ = 10.0
RATE_TOLERANCE = 0.10
#: Question 11: a published value agrees when within this many metres, or this share of the value.
VALUE_TOLERANCE_M = 0.5
VALUE_TOLERANCE_REL = 0.001
#: Question 14b: WARNING accepted from delay - EARLY to delay + LATE s after the node's own value went
#: beyond the threshold and stayed: 5 s less one reading of the 2 Hz input (4.5 s) falls outside. LATE
#: is at least one period of the slowest input and a tick of the node's 10 Hz (:func:`warning_window`):
#: a node that checks its delay at each reading, or at each synchronised pair, warns at the first one
#: at or after 5 s, up to one reading later.
WARNING_EARLY_S = 0.3
WARNING_LATE_S = 0.5
#: Question 14b: NORMAL accepted up to this many s after the node's own value came back (at once); one
#: that comes later (the flight waits for it) is "not at once", Q14b's 0.5 alone.
NORMAL_LATE_S = 0.5
#: Question 13: this many calls repeating the previous status make "called in a loop".
LOOP_REPEATS = 3
#: Question 11: the publisher's types accepted on the output topic (the sheets name none).
NUMERIC_TYPES = tuple('std_msgs/%s' % t for t in ('Float32', 'Float64', 'Int8', 'Int16', 'Int32', 'Int64',
                                                  'UInt8', 'UInt16', 'UInt32', 'UInt64'))
#: Question 12: what a launch file without a single comment loses ("la moitie si pas de commentaires").
NO_COMMENT_LOSS = 0.5
#: Question 11's lag: the node's value follows its inputs within one period of its slowest input (a
#: node that waits for a fresh reading of each) plus this: a tick of its 10 Hz and the transport.
LAG_SLACK_S = 0.5
#: The slowest input's rate of a probe that did not record its rates (the lab's drone before issue 35).
OLD_SLOWEST_HZ = 2.0

#: Every student's status: what the teacher must do with the grade.
GRADED = 'graded'
GRADED_WITH_FIXES = 'graded with fixes'
HAND_GRADE = 'needs a hand grade'
NOT_GRADED = 'not graded'
STATUSES = (GRADED, GRADED_WITH_FIXES, HAND_GRADE, NOT_GRADED)


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


def threshold_run_value(static, session):
    """The threshold run's value, which no output a student reads may show: as flown (its probe's
    plan), else as drawn by the inspection (a run skipped or failed); None when there was none."""
    probe = threshold_probe(session)
    if probe and probe.get('threshold') is not None:
        return probe['threshold']
    return ((static or {}).get('threshold') or {}).get('run_value')


def node_ran(session):
    probe = main_probe(session)
    return bool(probe and probe.get('nodes'))


def published(session):
    """True when the node published a value in the main run. A node that dies before its first value
    "does not start", whether or not the probe saw it register on the way (a crash just after
    ``init_node`` is seen or not depending on the machine's load: the words must not)."""
    probe = main_probe(session)
    return node_ran(session) and bool((probe.get('trace') or {}).get('published') or
                                      (probe.get('rate') or {}).get('samples'))


def stayed_up(session):
    """True when the node registered in the main run and roslaunch never saw it end."""
    runs = [r for r in (session or {}).get('runs', []) if r['tag'] == 'main']
    return node_ran(session) and not runs[0].get('launch', {}).get('ended')


def _not_run(session):
    session = session or {}
    build = session.get('build')
    if session.get('refused'):
        return 'not measured: the upload was refused (see runs)'
    if build is None:
        return 'not measured: nothing was run (see runs)'
    if build.get('status') != 0:
        return 'not measured: the package did not build (see runs)'
    return 'not measured: the node did not run (see runs)'


def score_runs(session):
    build = (session or {}).get('build')
    if build is None:
        return item('runs', 0, (session or {}).get('error', 'the submission could not be prepared'))
    if build['status'] is None:
        return item('runs', 0, build.get('stopped') or 'catkin_make did not finish within %.0f s' % build['timeout'])
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
    types = probe.get('input_types') or {}
    refused = refused_inputs(probe)
    got = [t for t, nodes in sorted(subscribed.items()) if nodes and t not in refused]
    missing = [t for t, nodes in sorted(subscribed.items()) if not nodes]
    evidence = 'subscribes to %s' % (', '.join('%s%s' % (t, ' (%s)' % types[t]['type'] if (types.get(t) or {}).get('type')
                                                         else '') for t in got) or 'neither input')
    for topic in sorted(refused):
        if types[topic].get('adapted'):
            evidence += ('; subscribes to %s as %s, but %s, so with the drone it would never receive it (0/1); '
                         'the grader\'s drone then published it as %s, so the rest is judged on what the node '
                         'does with it' % (topic, types[topic]['type'], types[topic]['refused'], types[topic]['adapted']))
        else:
            evidence += '; subscribes to %s as %s, but %s, so the node never receives it (0/1)' % (
                topic, types[topic]['type'], types[topic]['refused'])
    if missing:
        evidence += '; never to %s' % ', '.join(missing)
    return item('Q10', len(got), evidence)


def refused_inputs(probe):
    """The input topics whose subscription rospy refused (another message type than the drone's)."""
    return sorted(t for t, info in ((probe or {}).get('input_types') or {}).items() if info and info.get('refused'))


def adapted_inputs(probe):
    """The grader's fixes for refused subscriptions, one line each: the inputs its drone published in
    the type the node asked for (:meth:`exam_lab.grader.judge.probe.Probe.input_types`)."""
    return ['the drone published %s as %s, the type the node subscribed with (rospy refused the drone\'s %s): '
            'Q10 lost that input once, the rest judged on that run' % (
                topic, info['adapted'], info.get('published', 'std_msgs/Float32'))
            for topic, info in sorted(((probe or {}).get('input_types') or {}).items())
            if info and info.get('refused') and info.get('adapted')]


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
    elif output.get('topic') == expected and output.get('type') in NUMERIC_TYPES:
        points += 1.5
        notes.append('publisher: %s %s, a numeric type (the sheet names none: any numeric std_msgs type '
                     'is accepted) (1.5)' % (expected, output.get('type')))
    elif output.get('topic') == expected:
        notes.append('publisher: %s is %s, not a numeric std_msgs type (0/1.5)' % (expected, output.get('type')))
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
    constant = _constant_input(sheet, rows, refused_inputs(probe)) if rows and wrong else None
    if rows and not wrong:
        points += 1.5
        notes.append('values agree with equation (1) within max(%.1f m, %.1f %%) (1.5): %s'
                     % (VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, shown))
    elif constant is not None:
        points += 1.5
        notes.append('values agree with equation (1) within max(%.1f m, %.1f %%) at the constant %s %g the node '
                     'kept, since it never received %s (its subscription was refused: Q10\'s loss, not this one\'s) '
                     '(1.5): %s' % (VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, constant[0].lstrip('/'),
                                    constant[1], constant[0], shown))
    else:
        notes.append('values: %d of %d disagree with equation (1) beyond max(%.1f m, %.1f %%) (0/1.5): %s'
                     % (len(wrong), len(rows), VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, shown or 'none read'))
    if rate.get('non_finite'):
        notes.append('%d published value(s) were not finite numbers' % rate['non_finite'])
    lag = lag_words(probe)
    if lag:
        notes.append(lag)
    return item('Q11', points, '; '.join(notes))


def _constant_input(sheet, rows, refused):
    """``(topic, value)`` when the node's values agree with equation (1) for one constant value of a
    fixed input it never received (``refused``), as a node whose subscription was refused computes
    with its initial value; None otherwise."""
    fixed = [t for t in refused if t.rstrip('/').split('/')[-1] == {'altitude': 'temperature',
                                                                   'depth': 'pressure_remote'}[sheet]]
    usable = [r for r in rows if r['published'] is not None and math.isfinite(r['published'])]
    if not fixed or len(usable) < 2 or len(usable) < len(rows):
        return None
    topic = fixed[0]
    moving = [[v for t, v in sorted(r['inputs'].items()) if t != topic][0] for r in usable]
    first, value = moving[0], usable[0]['published']
    try:
        if sheet == 'altitude':
            constant = value * oracle.MU_AIR * oracle.G / (oracle.R * math.log(oracle.P0 / first)) - oracle.ZERO_CELSIUS
            expected = [oracle.altitude_of(constant, m) for m in moving]
        else:
            constant = first - value * oracle.RHO_SEA_WATER * oracle.G
            expected = [oracle.depth_of(m, constant) for m in moving]
    except (ValueError, ZeroDivisionError):
        return None
    if all(_agrees(e, r['published']) for e, r in zip(expected, usable)):
        return topic, round(constant, 2)
    return None


def score_q12(sheet, static, session=None):
    launch = static.get('launch')
    if static.get('launch_files') is None:
        return item('Q12', 0, 'not judged: the package was not read (see runs)')
    if launch is None:
        return item('Q12', 0, 'no launch file in the package starts an exam node (launch files: %s)'
                    % (', '.join(static.get('launch_files', [])) or 'none'))
    drone = SHEETS[sheet]
    verdict = (session or {}).get('launch_check') or {}
    if verdict.get('refused'):
        return item('Q12', 0, 'roslaunch refuses %s as handed in, so `roslaunch` starts nothing: "%s" (the grader '
                    'ran it without the drone\'s node, a fix named in the status)' % (verdict['file'], verdict['refused']))
    warned = ('; roslaunch warns: %s' % ' | '.join(verdict['warnings'])) if verdict.get('warnings') else ''
    has_drone = launch['starts_drone']
    exam_ok = launch['exam_type_found']
    where = launch['file']
    package = launch.get('package', 'exam')
    commented = launch.get('comments', 1) > 0
    comment_note = '' if commented else '; but not a single comment in it (-%g: half, as the notes say)' % NO_COMMENT_LOSS
    if has_drone and exam_ok:
        return item('Q12', 1 - (0 if commented else NO_COMMENT_LOSS), '%s starts %s/%s and %s/%s%s%s' % (
            where, drone.drone_pkg, drone.drone_type, package, launch['exam_type'], comment_note, warned))
    notes = []
    if not has_drone:
        notes.append('does not start the drone (%s/%s)' % (drone.drone_pkg, drone.drone_type))
    if not exam_ok:
        notes.append('starts %s/%s, which is no executable of the package' % (package, launch['exam_type']))
    return item('Q12', 0.5 - (0 if commented else NO_COMMENT_LOSS), '%s starts an exam node but %s%s%s'
                % (where, ' and '.join(notes), comment_note, warned))


def calls(probe):
    """Every call the node made: ``[(time, meaning, request, accepted)]``, ``meaning`` the status the
    request was meant as (:func:`~exam_lab.grader.score.sheets.request_meaning`; the request itself when
    it means neither), ``accepted`` the drone's answer (success). A refused request is a call all the same."""
    answers = {(a[0], a[1]): bool(a[2]) for a in (probe or {}).get('answers') or []}
    out = []
    for t, request in sorted((probe or {}).get('calls', [])):
        meaning = request_meaning(request)
        out.append((t, meaning or request, request, answers.get((t, request), request in REQUESTS)))
    return out


def refused_calls(probe, start=float('-inf'), end=float('inf')):
    """The calls the drone refused between ``start`` and ``end``: ``[(time, request)]``."""
    return [(t, request) for t, _, request, accepted in calls(probe) if not accepted and start <= t <= end]


def _refused_words(refused):
    requests = sorted(set(r for _, r in refused))
    return '%d call(s) with %s' % (len(refused), ', '.join('"%s"' % r[:40] for r in requests[:4]))


def _calls_between(probe, start, end, status=None):
    return [(t, s) for t, s, _, _ in calls(probe) if start <= t <= end and (status is None or s == status)]


def _repeats(probe, since):
    made = calls(probe)
    return len([1 for previous, call in zip(made, made[1:]) if call[0] >= since and call[1] == previous[1]])


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


#: The legs of the flights, in words.
LEG_WORDS = {'rest': 'rest below', 'short_up': 'short excursion above', 'short_down': 'gap below',
             'long_up': 'long excursion above', 'long_down': 'return just below', 'deep_down': 'return further below',
             'start': 'start below',
             'step': 'step above the new threshold'}


def unreached_legs(probe, names=None):
    """Legs of a flight whose node's own value never reached the side they were flown for."""
    legs = (probe or {}).get('legs') or {}
    return [n for n in (names or sorted(legs)) if n in legs and legs[n].get('reached') is None]


def _leg_words(probe, name):
    leg = probe['legs'][name]
    shown = 'nothing' if leg.get('first') is None else '%.1f to %.1f' % (leg['first'], leg['last'])
    return ('not judged: in the %s the node\'s own value never went %s the threshold %g (it published %s), '
            'so nothing is judged on that leg' % (LEG_WORDS.get(name, name), leg['side'],
                                                  probe.get('threshold', float('nan')), shown))


def _reached(probe, name):
    """When the node's own value reached the leg's side (the input's change when it cannot be read)."""
    leg = ((probe or {}).get('legs') or {}).get(name) or {}
    return leg.get('reached') or probe['schedule'][name]


def slowest_period(probe):
    """Seconds between two readings of the slowest input the judge's drone published: the sheet's drone,
    at the rates its package's SPEC gives (``input_rates``, recorded by the probe)."""
    rates = [r for r in ((probe or {}).get('input_rates') or {}).values() if r and r > 0]
    return 1.0 / min(rates or [OLD_SLOWEST_HZ])


def lag_tolerance(probe):
    """Seconds the node's value may take to follow its inputs: one period of the slowest input the
    drone flew plus LAG_SLACK_S."""
    return slowest_period(probe) + LAG_SLACK_S


def warning_window(probe):
    """``(earliest, latest)`` s after the node's own value went beyond and stayed, for a WARNING on time:
    the delay less WARNING_EARLY_S; the delay and the larger of WARNING_LATE_S and one period of the
    slowest input and one tick of the node's 10 Hz (a node that checks at each reading)."""
    delay = (probe or {}).get('delay', DELAY)
    return delay - WARNING_EARLY_S, delay + max(WARNING_LATE_S, slowest_period(probe) + 1.0 / RATE_HZ)


def leg_lag(probe, name):
    """Seconds from the input's change to the node's own first value on leg ``name``'s side, or None
    (the leg was not flown, its value never reached the side, or the output cannot be read)."""
    leg = ((probe or {}).get('legs') or {}).get(name) or {}
    start = ((probe or {}).get('schedule') or {}).get(name)
    if leg.get('reached') is None or start is None:
        return None
    return leg['reached'] - start


def timed_from(probe, name, stays=False):
    """``(time, words)``: where a timing rule on leg ``name`` counts from, in the node's own frame: when
    its own value went beyond and stayed (``stays``: the delay) or first came to the leg's side (the
    return). A node whose value took longer than :func:`lag_tolerance` to follow its inputs there is
    timed from the input's change instead (its lag is then its mistake, said here and in Q11), and so
    is one whose output cannot be read."""
    start = probe['schedule'][name]
    lag = leg_lag(probe, name)
    if lag is None:
        return start, 'the first reading'
    if lag > lag_tolerance(probe):
        return start, 'the first reading (the node\'s own value followed %.1f s later, more than one input ' \
                      'period: timed from the reading)' % lag
    leg = probe['legs'][name]
    own = leg.get('stays') if stays and leg.get('stays') is not None else leg['reached']
    return own, 'its own value'


def lag_words(probe):
    """Question 11's evidence of how fast the node's value followed its inputs on the flight's legs,
    or '' when nothing was measured."""
    measured = [(name, leg_lag(probe, name)) for name in LEG_WORDS if leg_lag(probe, name) is not None
                and name in ((probe or {}).get('schedule') or {}) and name not in ('start', 'step')]
    if not measured:
        return ''
    name, worst = max(measured, key=lambda m: m[1])
    tolerance = lag_tolerance(probe)
    if worst <= tolerance:
        return 'its value followed the inputs within %.2f s (at most %.2f s: one period of the slowest input ' \
               'and a tick); the timing items are judged from its own values' % (max(worst, 0.0), tolerance)
    return 'its value followed the inputs %.1f s late in the %s, more than one period of the slowest input ' \
           '(%.2f s): the timing items are judged from the readings there' % (worst, LEG_WORDS[name], tolerance)


def _up_end(probe):
    """Until when a WARNING belongs to the long excursion: the node's own value back below (or the
    input's return, if later)."""
    schedule = probe['schedule']
    return max(schedule['long_down'], _reached(probe, 'long_down'))


def _back_end(probe):
    """Until when a NORMAL is the return's "at once": the end of the leg just below the threshold."""
    schedule = probe['schedule']
    return schedule.get('deep_down', schedule['end'])


def score_q13(sheet, session):
    probe = main_probe(session)
    schedule = _flight(probe)
    if not node_ran(session) or schedule is None:
        return item('Q13', 0, _not_run(session))
    if unreached_legs(probe, ['long_up']):
        return item('Q13', 0, '%s (%s)' % (_leg_words(probe, 'long_up'), _driven_by(probe)))
    service = SHEETS[sheet].service
    up = _calls_between(probe, schedule['long_up'], _up_end(probe), 'WARNING')
    down_judged = not unreached_legs(probe, ['long_down'])
    down = _calls_between(probe, schedule['long_down'], schedule['end'], 'NORMAL') if up else []
    repeats = _repeats(probe, schedule['rest'])
    total = len(_calls_between(probe, schedule['rest'], schedule['end']))
    looped = repeats >= LOOP_REPEATS
    above = schedule['long_down'] - _reached(probe, 'long_up')
    up_from = timed_from(probe, 'long_up', stays=True)[0]
    if up and down and down_judged:
        points = 4.0
        evidence = 'WARNING while above, NORMAL once back below'
    elif up:
        points = 2.0
        evidence = 'WARNING while above, but %s' % (
            'no NORMAL within %.1f s back below' % (schedule['end'] - schedule['long_down']) if down_judged
            else _leg_words(probe, 'long_down'))
    else:
        points = 0.0
        evidence = 'no WARNING call on %s while the node\'s own value stayed above the threshold for %.1f s' % (
            service, above)
        others = sorted(set(r for t, m, r, _ in calls(probe) if m not in REQUESTS))
        if others:
            evidence += ' (it called with %s, which mean neither WARNING nor NORMAL)' % ', '.join(
                '"%s"' % r[:40] for r in others[:4])
    if up and up[0][0] - up_from > warning_window(probe)[1]:
        evidence += ' (the WARNING came late, %.1f s after the value went above: the flight waited for it)' % (
            up[0][0] - up_from)
    if up and down and down_judged and down[0][0] > _back_end(probe):
        evidence += ' (the NORMAL came late, %.1f s after the value came back below: the flight waited for it)' % (
            down[0][0] - timed_from(probe, 'long_down')[0])
    refused = refused_calls(probe, schedule['rest'], schedule['end'])
    if refused and points:
        points /= 2
        evidence += ('; but the drone refused its %s (success False: the LED never changed): the sheet\'s '
                     'requests are "WARNING" and "NORMAL", so half of Q13, once (the timing items judge when it '
                     'called)' % _refused_words(refused))
    if looped:
        points /= 2
        evidence += '; but called in a loop: %d calls in %.0f s of flight, %d repeating the previous status' % (
            total, schedule['end'] - schedule['rest'], repeats)
    else:
        evidence += '; %d call(s) in %.0f s of flight, %d repeating the previous status' % (
            total, schedule['end'] - schedule['rest'], repeats)
    return item('Q13', points, '%s (%s)' % (evidence, _driven_by(probe)))


def _reads(static, threshold):
    """What of the student's code reads the launch file's threshold: a parameter of that name (the
    last part of its name, however resolved), or for an ``args=`` word, argparse's option of that name
    or the index the code takes of ``rospy.myargv()`` / ``sys.argv`` (a positional argparse name too)."""
    name = threshold['name']
    if threshold.get('how') == 'args':
        found = static.get('args_in_code') or []
        if name.startswith('-'):
            return [a for a in found if a == name]
        return [a for a in found if a == name or not a.startswith(('-', 'argv['))]
    early = _read_too_early(static)
    return [p for p in static.get('params_in_code', []) if p.strip('~/').split('/')[-1] == name.split('/')[-1]
            and p not in early]


def _read_too_early(static):
    """{private parameter name: where} the code reads before init_node (then rospy resolves it against
    ``<ns>/unnamed``, never the node's name: ``rospy/names.py``)."""
    out = {}
    for entry in ((static.get('code') or {}).get('private_before_init') or []):
        where, _, name = entry.rpartition(': ')
        out.setdefault(name, where)
    return out


def score_q14a(sheet, static, session):
    threshold = static.get('threshold')
    if static.get('launch_files') is None:
        return item('Q14a', 0, 'not judged: the package was not read (see runs)')
    if threshold is None:
        return item('Q14a', 0, static.get('threshold_reason', 'no threshold parameter in the launch file'))
    name = threshold['name']
    what = 'argument %s' % name if threshold.get('how') == 'args' else 'parameter %s' % name
    if not node_ran(session):
        return item('Q14a', 0, '%s = %s in the launch file; %s' % (what, threshold['value'], _not_run(session)))
    read = _reads(static, threshold)
    # Judged from the code only for a node that runs: one that dies has not shown it uses anything.
    static_points = 0.5 if read and stayed_up(session) else 0.0
    static_note = ('the code reads %s' % ', '.join(read)) if read else 'the code reads no %s of that name' % (
        'argument' if threshold.get('how') == 'args' else 'parameter')
    if read and not stayed_up(session):
        static_note += ', but the node died (see runs)'
    early = [(n, w) for n, w in sorted(_read_too_early(static).items())
             if n.strip('~/').split('/')[-1] == name.split('/')[-1]]
    if early:
        static_note += '; it reads %s before init_node (%s), where rospy resolves it as .../unnamed/%s (its name ' \
                       'until then), not as the node\'s parameter' % (early[0][0], early[0][1], early[0][0].lstrip('~'))
    probe2 = threshold_probe(session)
    skipped = session.get('threshold_skipped')
    if probe2 is None:
        why = skipped or threshold.get('not_rewritable') or 'the threshold run failed'
        return item('Q14a', static_points, '%s = %s in the launch file; its effect could not be observed (%s); '
                    'judged from the code: %s' % (what, threshold['value'], why, static_note))
    schedule = probe2.get('schedule') or {}
    # The threshold run flies the main run's legs (its long excursion above the new value, below the
    # launch file's); measurements kept from before flew a single step.
    leg = 'long_up' if 'long_up' in schedule else 'step' if 'step' in schedule else None
    if leg is None:
        return item('Q14a', 0, 'with %s = %g the node did not run' % (name, probe2['threshold']))
    if unreached_legs(probe2, [leg]):
        return item('Q14a', static_points, '%s = %s; set to %g: %s; judged from the code: %s' % (
            what, threshold['value'], probe2['threshold'], _leg_words(probe2, leg), static_note))
    end = schedule['long_down'] if leg == 'long_up' else schedule['end']
    warned = _calls_between(probe2, schedule[leg], end, 'WARNING')
    if leg == 'long_up':
        flown = ((probe2.get('calibration') or {}).get('hi') or {}).get('target', float('nan'))
    else:
        flown = ((main_probe(session).get('calibration') or {}).get('lo') or {}).get('target', float('nan'))
    if warned:
        return item('Q14a', 1, 'launch file %s = %s; set to %g, the node warned %.2f s after its own value went '
                    'above it, flown at %.1f, a value it kept NORMAL with %s' % (
                        what, threshold['value'], probe2['threshold'], warned[0][0] - _reached(probe2, leg), flown,
                        threshold['value']))
    return item('Q14a', 0, 'launch file %s = %s; set to %g, the node stayed NORMAL for %.1f s at %.1f, above the new '
                'threshold: it does not obey the %s (%s)' % (
                    what, threshold['value'], probe2['threshold'], end - _reached(probe2, leg), flown,
                    'argument' if threshold.get('how') == 'args' else 'parameter', static_note))


def score_q14b(sheet, session):
    probe = main_probe(session)
    schedule = _flight(probe)
    if not node_ran(session) or schedule is None:
        return item('Q14b', 0, _not_run(session))
    if unreached_legs(probe, ['long_up']):
        return item('Q14b', 0, _leg_words(probe, 'long_up'))
    delay = probe.get('delay', DELAY)
    early, late = warning_window(probe)
    warnings = _calls_between(probe, schedule['long_up'], _up_end(probe), 'WARNING')
    if not warnings:
        return item('Q14b', 0, 'no WARNING in %.1f s above the threshold, so no delay to judge'
                    % (schedule['long_down'] - _reached(probe, 'long_up')))
    up_from, up_words = timed_from(probe, 'long_up', stays=True)
    latency = warnings[0][0] - up_from
    warn_ok = early <= latency <= late
    short_judged = not unreached_legs(probe, ['short_up'])
    short = _calls_between(probe, schedule['short_up'], schedule['long_up'], 'WARNING')
    short_from = timed_from(probe, 'short_up')[0]
    short_back = timed_from(probe, 'short_down')[0]
    # Above for the delay in its own frame (only a node beyond the lag tolerance gets there, and it is
    # then timed from the readings): a WARNING there is no mistake of the delay.
    own_long = short_back - short_from >= delay - WARNING_EARLY_S
    short_ok = short_judged and (not short or own_long)
    normal_judged = not unreached_legs(probe, ['long_down'])
    back_from, back_words = timed_from(probe, 'long_down')
    normals = _calls_between(probe, schedule['long_down'], _back_end(probe), 'NORMAL')
    normal_latency = normals[0][0] - back_from if normals else None
    normal_ok = normal_judged and normal_latency is not None and normal_latency <= NORMAL_LATE_S
    points = 1.5 * warn_ok + 1.0 * short_ok + (0.5 * normal_ok if (warn_ok or short_ok) else 0.0)
    notes = ['WARNING %.2f s after %s went above the threshold and stayed (%s: %.2f-%.2f s) (%s/1.5)' % (
        latency, up_words, 'ok' if warn_ok else 'outside', early, late, 1.5 if warn_ok else 0)]
    if not short_judged:
        notes.append('short excursion: %s (0/1)' % _leg_words(probe, 'short_up'))
    else:
        stayed = (leg_lag(probe, 'short_down') or 0.0)
        notes.append('%.1f s excursion above%s%s: %s (%s/1)' % (
            short_back - short_from, '' if short_from != schedule['short_up'] else ' (from the readings)',
            ' (the node\'s own value stayed above %.1f s longer: it did not follow its inputs)' % stayed
            if stayed > lag_tolerance(probe) else '',
            'no WARNING' if not short else 'WARNING %.2f s after it began%s' % (
                short[0][0] - short_from, ', as long as the delay in its own values' if own_long else ''),
            1 if short_ok else 0))
    below = _near_words(probe)
    if not normal_judged:
        notes.append('NORMAL: %s (0/0.5)' % _leg_words(probe, 'long_down'))
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
    schedule = probe['schedule']
    later = _calls_between(probe, _back_end(probe), schedule['end'], 'NORMAL')
    if not later:
        return ''
    deeper = _back_end(probe)
    if later[0][0] - deeper <= lag_tolerance(probe):  # as soon as its value followed the input further below
        return '; it came %.2f s later, further below: it waits for a margin' % (later[0][0] - back_from)
    return '; it came %.2f s after the value came back, %.2f s after the input went further below: it waits for ' \
           'a time, not at once' % (later[0][0] - back_from, later[0][0] - deeper)


def _near_words(probe):
    """How far below the threshold the node's own value was on the return ('' when not recorded)."""
    near = ((probe or {}).get('calibration') or {}).get('near') or {}
    value, threshold = near.get('value'), (probe or {}).get('threshold')
    if value is None or threshold is None or not math.isfinite(value):
        return ''
    return ' (%.2f, %.2f below)' % (value, threshold - value)


def score(sheet, static, session):
    """Every item of the rubric, in order."""
    return [score_runs(session), score_q10(sheet, session), score_q11(sheet, session),
            score_q12(sheet, static, session), score_q13(sheet, session), score_q14a(sheet, static, session),
            score_q14b(sheet, session)]


_EXCEPTION = re.compile(r'^\s*((?:\w+\.)*\w*(?:Error|Exception|Interrupt|Exit)\b.*)$')
_FRAME = re.compile(r'File "([^"]+)", line (\d+)')


def crash_summary(text):
    """The last exception line of a log and the last file:line of its traceback that is not
    Python's or ROS's own ("KeyError: '~threshold' at exam/scripts/exam_node.py:26"), or ''."""
    lines = (text or '').splitlines()
    errors = [(i, m.group(1).strip()) for i, m in ((i, _EXCEPTION.match(l)) for i, l in enumerate(lines)) if m]
    if not errors:
        return ''
    index, error = errors[-1]
    frames = [m for m in (_FRAME.search(l) for l in lines[:index]) if m
              and not m.group(1).startswith(('/usr/', '/opt/', '<'))]
    where = ' at %s:%s' % (frames[-1].group(1), frames[-1].group(2)) if frames else ''
    return '%s%s' % (error[:200], where)


def missing_evidence(static, session):
    """Rules the runs could not observe while the code holds what they need: one line each, naming
    the code's ``file:line`` (issue 35 point 5: a doubt, never a silent zero). A node that never
    published its value while its code publishes; a node that never called the warning service in a
    whole flight, its own value above the threshold for longer than the delay, while its code calls it."""
    static, session = static or {}, session or {}
    code = static.get('code') or {}
    probe = main_probe(session)
    schedule = _flight(probe)
    if not node_ran(session) or not stayed_up(session) or schedule is None:
        return []
    out = []
    sheet = SHEETS.get(probe.get('sheet')) or SHEETS['altitude']
    rate = probe.get('rate')
    if rate is not None and not rate.get('samples') and code.get('publishes'):
        out.append('the node never published its value while flown, yet its code publishes at %s: nothing '
                   'measured for Q11, Q13, Q14; read its code' % ', '.join(code['publishes'][:3]))
    elif not calls(probe) and code.get('service_calls') and not unreached_legs(probe, ['long_up']):
        out.append('the node never called %s in the whole flight (its own value above the threshold for %.1f s), '
                   'yet its code calls it at %s: no call to judge Q13, Q14a, Q14b on; read its code to see why '
                   'the call is never reached' % ('/' + sheet.service.lstrip('/'), schedule['long_down'] - _reached(probe, 'long_up'),
                                                  ', '.join(code['service_calls'][:3])))
    return out


def status(static, session, fixes=()):
    """``(status, reason)``: what the teacher must do with this grade (one of STATUSES; the reason is
    one line, '' when graded).

    Not graded: the upload was refused or unreadable, or the grader could not run it. Needs a hand
    grade: its grading used up its budget (a step stopped or left out), the package has no node, does
    not build, its node does not start or dies (the traceback's
    last line and file:line; Python 2 named), a run's measurement was refused (the node set the time,
    its master went over its memory bound), a leg of a flight was not reached (nothing judged there), or a
    rule could not be observed while the code holds it (:func:`missing_evidence`: the code's file:line).
    Graded with fixes: the grader made a teacher's fix (each in for_the_teacher).
    """
    static, session = static or {}, session or {}
    build = session.get('build')
    if session.get('refused'):
        return NOT_GRADED, _one_line(session.get('error', 'the upload was refused'))
    if build is None and not session.get('no_node'):
        return NOT_GRADED, _one_line(session.get('error', 'the submission could not be graded'))
    if session.get('budget_used'):  # a step stopped or left out: what it would have measured is missing
        return HAND_GRADE, _one_line(session['budget_used'])
    python2 = static.get('python2') or []
    python2_words = 'Python 2 code (%s): it cannot start under ROS Noetic\'s Python 3; read its algorithm by hand' \
        % ', '.join(python2[:3])
    if build is None:
        return HAND_GRADE, _one_line(session.get('error', 'nothing to run'))
    if build.get('status') != 0:
        last = [l for l in (build.get('tail') or '').splitlines() if l.strip()]
        return HAND_GRADE, _one_line('the package does not build%s' % (': %s' % last[-1] if last else ''))
    runs = session.get('runs', [])
    refused = [r for r in runs if r.get('probe_refused')]
    if refused:
        return HAND_GRADE, _one_line('the %s run was not measured: %s' % (refused[0]['tag'], refused[0]['probe_refused']))
    tails = '\n'.join(r.get('launch', {}).get('tail', '') for r in runs)
    if not node_ran(session) or not stayed_up(session):
        if python2:
            return HAND_GRADE, _one_line(python2_words)
        crash = crash_summary(tails)
        return HAND_GRADE, _one_line('the node %s%s' % ('died' if published(session) else 'does not start',
                                                          ': %s' % crash if crash else ' (see runs)'))
    missing = missing_evidence(static, session)
    if missing:
        return HAND_GRADE, _one_line(missing[0])
    for run in runs:
        missed = unreached_legs(run.get('probe'))
        if missed:
            types = (run.get('probe') or {}).get('input_types') or {}
            cause = ''.join('; rospy refused its subscription to %s as %s, so it never received that input'
                            % (t, types[t]['type']) for t in refused_inputs(run.get('probe')) if not types[t].get('adapted'))
            return HAND_GRADE, _one_line(
                'in the %s run the node\'s own value never reached the side of the threshold of its %s: '
                'nothing judged there, read its code%s' % (run['tag'], ', '.join(LEG_WORDS.get(m, m) for m in missed),
                                                         cause))
    refused = refused_calls(main_probe(session))
    if refused:
        return HAND_GRADE, _one_line(
            'the drone refused %s (not the sheet\'s "WARNING"/"NORMAL"): the calls were judged on when they '
            'came and Q13 lost half for the request; check' % _refused_words(refused))
    ambiguous = [u for u in static.get('uploads') or [] if u.get('ambiguous')]
    if ambiguous:
        return HAND_GRADE, _one_line('several uploads: %s; check which one is the last' % ambiguous[0]['why'])
    verdict = session.get('launch_check') or {}
    if verdict.get('refused'):
        fixes = list(fixes) + ['roslaunch refuses %s as handed in ("%s"): the grader ran it without the drone\'s '
                               'node; Q12 judged on the file as handed in' % (verdict['file'], verdict['refused'])]
    fixes = list(fixes) + adapted_inputs(main_probe(session))
    if fixes:
        return GRADED_WITH_FIXES, _one_line('; '.join(fixes))
    return GRADED, ''


def doubts(static, session):
    """What makes a grade doubtful, one line each, for the "needs the teacher" box whatever the status:
    refused service calls, roslaunch refusing (or warning about) the launch file as handed in, several
    uploads, a run whose measurement was refused, a rule not observed while the code holds it."""
    static, session = static or {}, session or {}
    out = list(missing_evidence(static, session))
    refused = refused_calls(main_probe(session))
    if refused:
        out.append('the drone refused %s' % _refused_words(refused))
    verdict = session.get('launch_check') or {}
    if verdict.get('refused'):
        out.append('roslaunch refuses %s as handed in: %s' % (verdict['file'], verdict['refused']))
    elif verdict.get('warnings'):
        out.append('roslaunch warns about %s: %s' % (verdict['file'], ' | '.join(verdict['warnings'])))
    for upload in static.get('uploads') or []:
        out.append('several uploads: %s' % upload['why'])
    for run in session.get('runs', []):
        if run.get('probe') is None and run.get('probe_error'):
            out.append('%s run: %s' % (run['tag'], run['probe_error'].splitlines()[0] if run['probe_error'] else ''))
    return [_one_line(line) for line in out]


def _one_line(text, limit=300):
    text = ' '.join(str(text).split())
    return text if len(text) <= limit else text[:limit - 3] + '...'

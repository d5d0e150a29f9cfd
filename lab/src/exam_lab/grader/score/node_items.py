"""The rubric's items on the node itself: it builds and runs (``runs``), subscribes to its inputs
(Q10), publishes its value at 10 Hz with the sheet's equation (Q11), and its launch file starts the
drone and the node (Q12). Pure, no rospy.

Each ``score_*`` takes the views of the inspection's and the session's records
(:func:`~exam_lab.grader.score.measured.static_of`, :func:`~exam_lab.grader.score.measured.session_of`)
and gives the item's ``{"id", "points", "max", "evidence"}``.
"""
import itertools
import math

from exam_lab.grader.score.flight import lag_words, worst_lag
from exam_lab.grader.score.measured import (item, main_probe, no_node_words, node_ran, not_run, otherwise,
                                            refused_inputs, run_of, unstarted_runs)
from exam_lab.grader.score.sheets import SHEETS
from exam_lab.grader.score.tolerances import (NO_COMMENT_LOSS, NUMERIC_TYPES, RATE_HZ, RATE_TOLERANCE,
                                              VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL)
from exam_lab.harness import oracle


def score_runs(session):
    build = session.build
    if build is None:
        return item('runs', 0, otherwise(session.error, 'the submission could not be prepared'))
    if build.status is None:
        return item('runs', 0, build.stopped or 'catkin_make did not finish within %.0f s' % build.timeout)
    if build.status != 0:
        return item('runs', 0, 'catkin_make failed (exit %s) in a workspace of its own next to the '
                    'simulators; its last lines:\n%s' % (build.status, build.tail))
    problems, unstarted = [], [r.tag for r in unstarted_runs(session)]
    for run in session.runs or ():
        if run.tag in unstarted:
            continue
        probe, launch = run.probe, run.launch
        for line in (launch.not_started if launch else None) or ():
            problems.append('%s run: %s' % (run.tag, line))
        for ended in (launch.ended if launch else None) or ():
            problems.append('%s run: node %s %s%s' % (run.tag, ended.node,
                                                      'died' if ended.how == 'died' else 'ended',
                                                      ' (%s)' % ended.detail if ended.detail else ''))
        if probe is None:
            problems.append('%s run: the probe failed: %s' % (run.tag, otherwise(run.probe_error, '?')))
        elif not probe.nodes and not (launch and launch.ended):
            problems.append('%s run: %s' % (run.tag, no_node_words(probe)))
    if not session.runs:
        problems.append('the node was not run')
    if problems:
        tails = [r.launch.tail for r in session.runs or () if r.launch and r.launch.tail]
        return item('runs', 1, 'builds (%.0f s); but: %s%s' % (
            build.seconds, '; '.join(problems), '\nlast lines of its launch:\n%s' % tails[0] if tails else ''))
    seconds = sum(otherwise(r.seconds, 0) for r in session.runs)
    return item('runs', 2, 'builds (%.0f s); node up in %.1f s and still up after %.0f s of flight in %d run(s)%s'
                % (build.seconds, main_probe(session).node_seen_s or 0, seconds, len(session.runs),
                   ''.join('; in the %s run its node never came (%s) while the main run\'s did: not counted, see the '
                           'doubt' % (tag, no_node_words(run_of(session, tag).probe)) for tag in unstarted)))


def score_q10(sheet, session):
    probe = main_probe(session)
    if not node_ran(session):
        return item('Q10', 0, not_run(session))
    subscribed = otherwise(probe.subscribed, {})
    types = probe.input_types or {}
    refused = refused_inputs(probe)
    got = [t for t, nodes in sorted(subscribed.items()) if nodes and t not in refused]
    missing = [t for t, nodes in sorted(subscribed.items()) if not nodes]
    evidence = 'subscribes to %s' % (', '.join('%s%s' % (t, ' (%s)' % types[t].type if _type_of(types.get(t))
                                                         else '') for t in got) or 'neither input')
    for topic in sorted(refused):
        if types[topic].adapted:
            evidence += ('; subscribes to %s as %s, but %s, so with the drone it would never receive it (0/1); '
                         'the grader\'s drone then published it as %s, so the rest is judged on what the node '
                         'does with it' % (topic, types[topic].type, types[topic].refused, types[topic].adapted))
        else:
            evidence += '; subscribes to %s as %s, but %s, so the node never receives it (0/1)' % (
                topic, types[topic].type, types[topic].refused)
    if missing:
        evidence += '; never to %s' % ', '.join(missing)
    return item('Q10', len(got), evidence)


def _type_of(info):
    """The message type an input was subscribed with, or None."""
    return info.type if info else None


def _agrees(expected, published):
    return published is not None and math.isfinite(published) and \
        abs(published - expected) <= max(VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * abs(expected))


def score_q11(sheet, session):
    probe = main_probe(session)
    if not node_ran(session):
        return item('Q11', 0, not_run(session))
    output = probe.output
    topic, kind = (output.topic, output.type) if output else (None, None)
    expected = otherwise(output.expected if output else None, '/' + SHEETS[sheet].output)
    points, notes = 0.0, []
    if topic == expected and kind == 'std_msgs/Float32':
        points += 1.5
        notes.append('publisher: %s std_msgs/Float32 (1.5)' % expected)
    elif topic == expected and kind in NUMERIC_TYPES:
        points += 1.5
        notes.append('publisher: %s %s, a numeric type (the sheet names none: any numeric std_msgs type '
                     'is accepted) (1.5)' % (expected, kind))
    elif topic == expected:
        notes.append('publisher: %s is %s, not a numeric std_msgs type (0/1.5)' % (expected, kind))
    elif topic:
        notes.append('publisher: no %s; it publishes %s (%s) instead, measured there (0/1.5)'
                     % (expected, topic, kind))
    else:
        notes.append('publisher: no %s, and no number topic to measure (publishes %s) (0/4)'
                     % (expected, ', '.join(otherwise(output.candidates if output else None, ())) or 'nothing'))
        return item('Q11', 0, '; '.join(notes))
    rate = probe.rate
    hz = rate.hz if rate else None
    if hz is not None and abs(hz - RATE_HZ) <= RATE_TOLERANCE * RATE_HZ:
        points += 1.0
        notes.append('rate %.2f Hz (1)' % hz)
    elif hz is not None:
        notes.append('rate %.2f Hz, not 10 Hz +- %d %% (longest gap %.2f s) (0/1)'
                     % (hz, RATE_TOLERANCE * 100, rate.max_gap or 0, ))
    else:
        notes.append('rate: %d message(s) in the flight, cannot measure (0/1)'
                     % otherwise(rate.samples if rate else None, 0))
    rows = otherwise(probe.formula, ())
    lag = max(0.0, (worst_lag(probe) or (None, 0.0))[1])
    paced = [r for r in rows if not _agrees(r.expected, r.published) and _agrees_at_its_pace(sheet, r, lag)]
    wrong = [r for r in rows if not _agrees(r.expected, r.published) and r not in paced]
    shown = '; '.join('%s -> %s, expected %.2f%s' % (
        ', '.join('%s %g' % (k.lstrip('/'), v) for k, v in sorted(r.inputs.items())),
        'nothing' if r.published is None else '%.2f' % r.published, r.expected,
        '' if r.published is None or not math.isfinite(r.published)
        else ' (error %+.2f m)' % (r.published - r.expected)) for r in rows)
    constant = _constant_input(sheet, rows, refused_inputs(probe)) if rows and wrong else None
    if rows and not wrong:
        points += 1.5
        notes.append('values agree with equation (1) within max(%.1f m, %.1f %%)%s (1.5): %s'
                     % (VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, _pace_words(paced, lag), shown))
    elif constant is not None:
        points += 1.5
        notes.append('values agree with equation (1) within max(%.1f m, %.1f %%) at the constant %s %g the node '
                     'kept, since it never received %s (its subscription was refused: Q10\'s loss, not this one\'s) '
                     '(1.5): %s' % (VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, constant[0].lstrip('/'),
                                    constant[1], constant[0], shown))
    else:
        notes.append('values: %d of %d disagree with equation (1) beyond max(%.1f m, %.1f %%) (0/1.5): %s'
                     % (len(wrong), len(rows), VALUE_TOLERANCE_M, VALUE_TOLERANCE_REL * 100, shown or 'none read'))
    if rate and rate.non_finite:
        notes.append('%d published value(s) were not finite numbers' % rate.non_finite)
    lag = lag_words(probe)
    if lag:
        notes.append(lag)
    return item('Q11', points, '; '.join(notes))


def _could_have_seen(row, t, lag):
    """The input pairs (``{topic: value}``) a value published at ``t`` may have been computed from:
    each input's value before its change too, when the change came less than ``lag`` s before ``t``."""
    options = []
    for topic, value in sorted(row.inputs.items()):
        changed = (row.changes or {}).get(topic)
        old = (row.before or {}).get(topic)
        seen = [value] + ([old] if old is not None and changed is not None and t - lag < changed else [])
        options.append([(topic, v) for v in seen])
    return [dict(pair) for pair in itertools.product(*options)]


def _expected(sheet, inputs):
    """Equation (1) of one pair of the drone's inputs, by their topics' names."""
    named = {topic.rstrip('/').split('/')[-1]: value for topic, value in inputs.items()}
    try:
        if sheet == 'altitude':
            return oracle.altitude_of(named['temperature'], named['pressure'])
        return oracle.depth_of(named['pressure_robot'], named['pressure_remote'])
    except (KeyError, ValueError, ZeroDivisionError):
        return None


def _agrees_at_its_pace(sheet, row, lag):
    """Whether every value the node published in the row's window agrees with equation (1) of inputs
    it could have seen within its measured ``lag`` (issue 45: a node that publishes once a second is
    read still showing the inputs of before; its rate is question 11's loss, not its values). A row
    kept without its window (a probe of before) is judged on its last value alone."""
    if not row.values or row.changes is None:
        return False
    for t, value in row.values:
        expected = [_expected(sheet, pair) for pair in _could_have_seen(row, t, lag)]
        if not any(e is not None and _agrees(e, value) for e in expected):
            return False
    return True


def _pace_words(paced, lag):
    if not paced:
        return ''
    return (' at its own pace: %d value(s) read were of the inputs before the change, published within its '
            'measured lag (%.2f s) of it' % (len(paced), lag))


def _constant_input(sheet, rows, refused):
    """``(topic, value)`` when the node's values agree with equation (1) for one constant value of a
    fixed input it never received (``refused``), as a node whose subscription was refused computes
    with its initial value; None otherwise."""
    fixed = [t for t in refused if t.rstrip('/').split('/')[-1] == {'altitude': 'temperature',
                                                                   'depth': 'pressure_remote'}[sheet]]
    usable = [r for r in rows if r.published is not None and math.isfinite(r.published)]
    if not fixed or len(usable) < 2 or len(usable) < len(rows):
        return None
    topic = fixed[0]
    moving = [[v for t, v in sorted(r.inputs.items()) if t != topic][0] for r in usable]
    first, value = moving[0], usable[0].published
    try:
        if sheet == 'altitude':
            constant = value * oracle.MU_AIR * oracle.G / (oracle.R * math.log(oracle.P0 / first)) - oracle.ZERO_CELSIUS
            expected = [oracle.altitude_of(constant, m) for m in moving]
        else:
            constant = first - value * oracle.RHO_SEA_WATER * oracle.G
            expected = [oracle.depth_of(m, constant) for m in moving]
    except (ValueError, ZeroDivisionError):
        return None
    if all(_agrees(e, r.published) for e, r in zip(expected, usable)):
        return topic, round(constant, 2)
    return None


def score_q12(sheet, static, session):
    launch = static.launch
    if static.launch_files is None:
        return item('Q12', 0, 'not judged: the package was not read (see runs)')
    verdict = session.launch_check
    if launch is None and static.launch_unread:
        return item('Q12', 0, '%s%s' % (static.launch_unread, ': "%s"' % verdict.refused if verdict and verdict.refused
                                        else ''))
    if launch is None:
        return item('Q12', 0, 'no launch file in the package starts an exam node (launch files: %s)'
                    % (', '.join(static.launch_files) or 'none'))
    drone = SHEETS[sheet]
    if verdict and verdict.refused:
        # The file's one loss (issue 45): what it starts and sets is judged as written, run repaired.
        return item('Q12', 0, 'roslaunch refuses %s as handed in, so `roslaunch` starts nothing: "%s" (the grader '
                    'ran it %swithout the drone\'s node, the fixes named in the status; the rest is judged on what '
                    'it starts and sets as written)' % (verdict.file, verdict.refused,
                                                        'repaired and ' if launch.repairs else ''))
    warned = ('; roslaunch warns: %s' % ' | '.join(verdict.warnings)) if verdict and verdict.warnings else ''
    has_drone = launch.starts_drone
    exam_ok = launch.exam_type_found
    where = launch.file
    package = otherwise(launch.package, 'exam')
    commented = otherwise(launch.comments, 1) > 0
    comment_note = '' if commented else '; but not a single comment in it (-%g: half, as the notes say)' % NO_COMMENT_LOSS
    if has_drone and exam_ok:
        return item('Q12', 1 - (0 if commented else NO_COMMENT_LOSS), '%s starts %s/%s and %s/%s%s%s' % (
            where, drone.drone_pkg, drone.drone_type, package, launch.exam_type, comment_note, warned))
    notes = []
    if not has_drone:
        notes.append('does not start the drone (%s/%s)' % (drone.drone_pkg, drone.drone_type))
    if not exam_ok:
        notes.append('starts %s/%s, which is no executable of the package' % (package, launch.exam_type))
    return item('Q12', 0.5 - (0 if commented else NO_COMMENT_LOSS), '%s starts an exam node but %s%s%s'
                % (where, ' and '.join(notes), comment_note, warned))

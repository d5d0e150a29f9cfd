"""What the teacher must do with a grade: its status (graded, with fixes, by hand, not graded) and one
line of why, the doubts for the "needs the teacher" box, the rules the runs could not observe while
the code holds them, and a crash in one line. Pure, no rospy.

:func:`status` and :func:`doubts` take the inspection's and the session's records as kept (dicts) or as
their views, and read the views.
"""
import re

from exam_lab.grader.score.flight import LEG_WORDS, calls, reached, refused_calls, refused_words, schedule_of, \
    silent, unreached_legs
from exam_lab.grader.score.measured import adapted_inputs, main_probe, no_node_words, node_ran, otherwise, \
    published, refused_inputs, session_of, static_of, stayed_up, unstarted_runs
from exam_lab.grader.score.sheets import SHEETS

#: Every student's status: what the teacher must do with the grade.
GRADED = 'graded'
GRADED_WITH_FIXES = 'graded with fixes'
HAND_GRADE = 'needs a hand grade'
NOT_GRADED = 'not graded'
STATUSES = (GRADED, GRADED_WITH_FIXES, HAND_GRADE, NOT_GRADED)

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
    static, session = static_of(static or {}), session_of(session)
    code = static.code
    publishes, service_calls = (code.publishes, code.service_calls) if code else (None, None)
    probe = main_probe(session)
    schedule = schedule_of(probe)
    if not node_ran(session) or not stayed_up(session) or schedule is None:
        return []
    out = []
    sheet = SHEETS.get(probe.sheet) or SHEETS['altitude']
    rate = probe.rate
    if rate is not None and not rate.samples and publishes and silent(probe) and calls(probe):
        out.append('the judge received nothing on %s%s, yet its code publishes at %s: Q13, Q14a, Q14b judged from its '
                   'calls against the judge\'s own value of the flight, Q11\'s rate and values not measured; read '
                   'its code' % (probe.output.topic if probe.output else '?', _silence_cause(session),
                                 ', '.join(publishes[:3])))
    elif rate is not None and not rate.samples and publishes:
        out.append('the node never published its value while flown, yet its code publishes at %s: nothing '
                   'measured for Q11, Q13, Q14; read its code' % ', '.join(publishes[:3]))
    elif not calls(probe) and service_calls and not unreached_legs(probe, ['long_up']):
        out.append('the node never called %s in the whole flight (its own value above the threshold for %.1f s), '
                   'yet its code calls it at %s: no call to judge Q13, Q14a, Q14b on; read its code to see why '
                   'the call is never reached' % ('/' + sheet.service.lstrip('/'), schedule['long_down'] - reached(probe, 'long_up'),
                                                  ', '.join(service_calls[:3])))
    return out


#: rospy's words, in the node's log, for a subscriber's connection its publisher failed to take.
_INBOUND_FAILED = re.compile(r'Inbound TCP/IP connection failed: ([^\n]{1,200})')


def _silence_cause(session):
    """Why a publisher's subscribers received nothing, when its node's log (the main run's) says it:
    rospy's words for the failed connection, or '' (rospy/topics.py: ``Publisher(name, data_class,
    subscriber_listener=None, ...)``, so a ROS 2 style ``Publisher(topic, Float32, 10)`` makes 10 the
    listener, whose ``peer_subscribe`` fails at every subscriber's connection, which rospy then closes)."""
    run = [r for r in session.runs or () if r.tag == 'main']
    found = _INBOUND_FAILED.search((run[0].launch.tail if run and run[0].launch else None) or '')
    if not found:
        return ''
    if 'peer_subscribe' in found.group(1):
        return (' (rospy.Publisher\'s third positional argument is subscriber_listener, not the queue size: '
                'every connection failed)')
    return ' (rospy: "Inbound TCP/IP connection failed: %s")' % found.group(1).strip()


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
    static, session = static_of(static or {}), session_of(session)
    build = session.build
    if session.refused:
        return NOT_GRADED, _one_line(otherwise(session.error, 'the upload was refused'))
    if build is None and not session.no_node:
        return NOT_GRADED, _one_line(otherwise(session.error, 'the submission could not be graded'))
    if session.budget_used:  # a step stopped or left out: what it would have measured is missing
        return HAND_GRADE, _one_line(session.budget_used)
    python2 = static.python2 or ()
    python2_words = 'Python 2 code (%s): it cannot start under ROS Noetic\'s Python 3; read its algorithm by hand' \
        % ', '.join(python2[:3])
    if build is None:
        return HAND_GRADE, _one_line(otherwise(session.error, 'nothing to run'))
    if build.status != 0:
        last = [l for l in (build.tail or '').splitlines() if l.strip()]
        return HAND_GRADE, _one_line('the package does not build%s' % (': %s' % last[-1] if last else ''))
    runs = otherwise(session.runs, ())
    refused = [r for r in runs if r.probe_refused]
    if refused:
        return HAND_GRADE, _one_line('the %s run was not measured: %s' % (refused[0].tag, refused[0].probe_refused))
    tails = '\n'.join(otherwise(r.launch.tail if r.launch else None, '') for r in runs)
    if not node_ran(session) or not stayed_up(session):
        if python2:
            return HAND_GRADE, _one_line(python2_words)
        crash = crash_summary(tails)
        return HAND_GRADE, _one_line('the node %s%s' % ('died' if published(session) else 'does not start',
                                                          ': %s' % crash if crash else ' (see runs)'))
    unstarted = unstarted_runs(session)
    if unstarted:
        return HAND_GRADE, _one_line(_unstarted_words(unstarted[0]))
    missing = missing_evidence(static, session)
    if missing:
        return HAND_GRADE, _one_line(missing[0])
    for run in runs:
        missed = unreached_legs(run.probe)
        if missed:
            types = (run.probe.input_types if run.probe else None) or {}
            cause = ''.join('; rospy refused its subscription to %s as %s, so it never received that input'
                            % (t, types[t].type) for t in refused_inputs(run.probe) if not types[t].adapted)
            return HAND_GRADE, _one_line(
                'in the %s run the node\'s own value never reached the side of the threshold of its %s: '
                'nothing judged there, read its code%s' % (run.tag, ', '.join(LEG_WORDS.get(m, m) for m in missed),
                                                         cause))
    refused = refused_calls(main_probe(session))
    if refused:
        return HAND_GRADE, _one_line(
            'the drone refused %s (not the sheet\'s "WARNING"/"NORMAL"): the calls were judged on when they '
            'came and Q13 lost half for the request; check' % refused_words(refused))
    ambiguous = [u for u in static.uploads or () if u.ambiguous]
    if ambiguous:
        return HAND_GRADE, _one_line('several uploads: %s; check which one is the last' % ambiguous[0].why)
    if static.launch_unread:
        return HAND_GRADE, _one_line(static.launch_unread)
    verdict = session.launch_check
    if verdict and verdict.refused:
        fixes = list(fixes) + ['roslaunch refuses %s as handed in ("%s"): the grader ran it %swithout the drone\'s '
                               'node; Q12 judged on the file as handed in (its one loss), the rest on what it starts '
                               'and sets as written' % (verdict.file, verdict.refused,
                                                        'repaired and ' if static.launch and static.launch.repairs
                                                        else '')]
    fixes = list(fixes) + adapted_inputs(main_probe(session))
    if silent(main_probe(session)) and calls(main_probe(session)):
        fixes.append('the judge received nothing on %s: Q13, Q14a, Q14b judged from its calls against the judge\'s '
                     'own value of the flight, timed from the readings' % main_probe(session).output.topic)
    if fixes:
        return GRADED_WITH_FIXES, _one_line('; '.join(fixes))
    return GRADED, ''


def doubts(static, session):
    """What makes a grade doubtful, one line each, for the "needs the teacher" box whatever the status:
    refused service calls, roslaunch refusing (or warning about) the launch file as handed in, several
    uploads, a run whose measurement was refused, a rule not observed while the code holds it."""
    static, session = static_of(static or {}), session_of(session)
    out = list(missing_evidence(static, session))
    refused = refused_calls(main_probe(session))
    if refused:
        out.append('the drone refused %s' % refused_words(refused))
    verdict = session.launch_check
    if verdict and verdict.refused:
        out.append('roslaunch refuses %s as handed in: %s' % (verdict.file, verdict.refused))
    elif verdict and verdict.warnings:
        out.append('roslaunch warns about %s: %s' % (verdict.file, ' | '.join(verdict.warnings)))
    for upload in static.uploads or ():
        out.append('several uploads: %s' % upload.why)
    out.extend(_unstarted_words(run) for run in unstarted_runs(session))
    for run in session.runs or ():
        if run.probe is None and run.probe_error:
            out.append('%s run: %s' % (run.tag, run.probe_error.splitlines()[0] if run.probe_error else ''))
    return [_one_line(line) for line in out]


def _unstarted_words(run):
    return ('in the %s run %s, while the main run\'s node did with the same code: what that run judges (Q14a '
            'for the threshold run) was judged from the code; grade again or by hand' % (run.tag, no_node_words(run.probe)))


def _one_line(text, limit=300):
    text = ' '.join(str(text).split())
    return text if len(text) <= limit else text[:limit - 3] + '...'

"""What a grading measured, as the rubric reads it: the session's and the inspection's records through
their views (:func:`~exam_lab.grader.score.fields.view`), the main and threshold runs' probes, whether
the node ran, published and stayed up, the inputs rospy refused, and an item's record. Pure, no rospy.

Every function here takes the records as they are kept (dicts, from ``measurements.json`` or a test)
or as views, and reads views only.
"""
from exam_lab.grader.score import fields, inspection, records
from exam_lab.grader.score.runs import judged
from exam_lab.grader.score.sheets import ITEMS


def session_of(session):
    """The view of a session's record (:class:`~exam_lab.grader.score.records.SessionRecord`) as the
    rubric counts its runs (:func:`~exam_lab.grader.score.runs.judged`: a result that is not its run's
    measurement set aside); an empty one for None (a session that did not run: every field None). A
    view is one already: given as it is."""
    if isinstance(session, fields.Fields):
        return session
    if isinstance(session, records.Record):
        session = session.value
    return fields.view(judged(session or {}), records.SessionRecord.SCHEMA)


def static_of(static):
    """The view of what the inspection read (:data:`~exam_lab.grader.score.inspection.STATIC`), None
    staying None."""
    return fields.view(static, inspection.STATIC)


def probe_of(probe):
    """The view of a probe's result (:class:`~exam_lab.grader.score.records.ProbeRecord`); an empty one
    for None (no run, no result: every field None)."""
    return fields.view(probe or {}, records.ProbeRecord.SCHEMA)


def otherwise(value, default):
    """``value``, or ``default`` when it is None (a key its record lacks)."""
    return default if value is None else value


def item(item_id, points, evidence):
    maximum = ITEMS[item_id][0]
    return {'id': item_id, 'points': round(max(0.0, min(points, maximum)) * 2) / 2, 'max': maximum,
            'evidence': evidence}


def run_of(session, tag):
    """The session's run ``tag`` ('main', 'threshold'), or None."""
    runs = [r for r in session_of(session).runs or () if r.tag == tag]
    return runs[0] if runs else None


def main_probe(session):
    run = run_of(session, 'main')
    return run.probe if run and run.probe else None


def threshold_probe(session):
    run = run_of(session, 'threshold')
    return run.probe if run and run.probe else None


def threshold_run_value(static, session):
    """The threshold run's value, which no output a student reads may show: as flown (its probe's
    plan), else as drawn by the inspection (a run skipped or failed); None when there was none."""
    probe = threshold_probe(session)
    if probe and probe.threshold is not None:
        return probe.threshold
    threshold = static_of(static or {}).threshold
    return threshold.run_value if threshold else None


def node_ran(session):
    probe = main_probe(session)
    return bool(probe and probe.nodes)


def published(session):
    """True when the node published a value in the main run. A node that dies before its first value
    "does not start", whether or not the probe saw it register on the way (a crash just after
    ``init_node`` is seen or not depending on the machine's load: the words must not)."""
    probe = main_probe(session)
    return node_ran(session) and bool((probe.trace and probe.trace.published) or
                                      (probe.rate and probe.rate.samples))


def stayed_up(session):
    """True when the node registered in the main run and roslaunch never saw it end."""
    if not node_ran(session):
        return False
    launch = run_of(session, 'main').launch
    return not (launch and launch.ended)


def no_node_words(probe):
    """Why a run's probe saw no node: none registered within its ``start_timeout`` of roslaunch's start
    (the probe's ``launch_seen_s``), or roslaunch never came up on the master."""
    probe = probe_of(probe)
    if probe.launch_seen_s is None:
        return 'roslaunch never came up on the master: no node of the package registered'
    return ('no node of the package registered with the master within %.0f s of roslaunch\'s start'
            % otherwise(probe.start_timeout, 0))


def unstarted_runs(session):
    """The runs after the main one whose node never registered, no death of it seen, while the main
    run's did: the same package and code, only the threshold changed, so the cause is the machine (a
    start under heavy load), not the student's. A doubt for the teacher, never a point lost."""
    if not node_ran(session):
        return []
    return [run for run in session_of(session).runs or ()
            if run.tag != 'main' and run.probe is not None and not run.probe.nodes
            and not (run.launch and run.launch.ended)]


def not_run(session):
    """Why an item was not measured: the upload refused, nothing run, no build, or no node."""
    session = session_of(session)
    build = session.build
    if session.refused:
        return 'not measured: the upload was refused (see runs)'
    if build is None:
        return 'not measured: nothing was run (see runs)'
    if build.status != 0:
        return 'not measured: the package did not build (see runs)'
    return 'not measured: the node did not run (see runs)'


def refused_inputs(probe):
    """The input topics whose subscription rospy refused (another message type than the drone's)."""
    return sorted(t for t, info in (probe_of(probe).input_types or {}).items() if info and info.refused)


def inputs_lost(main, other):
    """The input topics the node received in the ``main`` run's probe but not in the ``other`` run's (the
    grader's drone, re-typed for it or not, never connected there): that run shows nothing of the node.
    An input the other run does not list (a result kept before inputs were listed) is not said lost."""
    before, after = probe_of(main).input_types or {}, probe_of(other).input_types or {}
    return sorted(t for t, info in before.items() if info and info.connected and
                  after.get(t) is not None and not after.get(t).connected)


def adapted_inputs(probe):
    """The grader's fixes for refused subscriptions, one line each: the inputs its drone published in
    the type the node asked for (:meth:`exam_lab.grader.judge.node.NodeFinder.input_types`)."""
    return ['the drone published %s as %s, the type the node subscribed with (rospy refused the drone\'s %s): '
            'Q10 lost that input once, the rest judged on that run' % (
                topic, info.adapted, 'std_msgs/Float32' if info.published is None else info.published)
            for topic, info in sorted((probe_of(probe).input_types or {}).items())
            if info and info.refused and info.adapted]

"""The teacher's text of a grade: what the machine saw but does not score (``for_the_teacher``), how the
student's code was read and run.
"""
import os
import pwd
import re

from exam_lab.grader.publish import report
from exam_lab.grader.score import measured

#: Log lines worth the teacher's eye: warnings, errors, tracebacks.
_ODD = re.compile(r'\[(WARN|ERROR|FATAL)\]|Traceback|Error\b|Exception\b')


def hints(static, session, notes, comments, isolate, how_run=None):
    """The for_the_teacher list: what the machine saw but does not score.

    :param comments: the inspection's comment statistics (``{"comments", "code", "files"}``) or None.
    """
    out = list(notes)
    if comments:
        out.append('comments (not scored): %d comment lines for %d lines of code (%.0f %%) in %s'
                   % (comments['comments'], comments['code'], 100.0 * comments['comments'] / max(comments['code'], 1),
                      ', '.join(comments['files'])))
    static, session = measured.static_of(static), measured.session_of(session)
    probe = measured.main_probe(session)
    if probe:
        for node, info in sorted((probe.graph or {}).items()):
            out.append('node %s: publishes %s; subscribes %s; serves %s' % (
                node, ', '.join('%s (%s)' % tuple(p) for p in info.publishes if p[0] != '/rosout') or 'nothing',
                ', '.join('%s (%s)' % tuple(s) for s in info.subscribes) or 'nothing',
                ', '.join(info.services) or 'nothing'))
        calibration = probe.calibration
        if calibration and calibration.by == 'oracle' and calibration.reason:
            out.append('Q13/Q14 flown by the oracle\'s values: %s' % calibration.reason)
    for run in session.runs or ():
        tail = measured.otherwise(run.launch.tail if run.launch else None, '')
        odd = [l for l in tail.splitlines() if _ODD.search(l)]
        if odd:
            out.append('%s run, odd lines in the log: %s' % (run.tag, ' | '.join(odd[:4])))
    if static and static.launch and static.launch.file and len(static.launch_files or ()) > 1:
        out.append('launch file graded: %s (of %s)' % (static.launch.file, ', '.join(static.launch_files)))
    if session.build is not None:  # something of the student's ran
        out.append('ran in a network namespace with only loopback' if isolate else
                   'ran WITHOUT network isolation (no network namespace could be made): the student code could '
                   'reach the network')
        out.append(how_run or 'not run')
    if session.budget_used:
        out.append(session.budget_used)
    if session.survivors:
        out.append('%d processes of the student were still alive after its steps ended: killed'
                   % session.survivors)
    out.append('not scored by the machine: %s' % report.NOT_SCORED)
    return out


def how_run(box):
    if box.rootless:
        return ('ran in a bubblewrap sandbox WITHOUT ROOT, as the grading user (uid %d): its own user, PID, '
                'mount, IPC and UTS namespaces, a clean environment, only its workspace writable, none of '
                'that user\'s files visible; limited per process in memory, CPU time and file size. Unlike '
                'a box made by root: no uid of its own (boxes told apart by their PID namespaces and mounts), '
                '%s, no size limit on its work folder (docs/grading.md, "Without root")'
                % (box.uid, 'a cgroup delegated to the user' if box.cgroups else
                   'no memory or process cgroup (processes counted in the session\'s user namespace)'))
    if box.bwrap:
        return ('ran in a bubblewrap sandbox as uid %d: its own user, PID, mount, IPC and UTS namespaces, '
                'a clean environment, only its workspace writable; limited in memory, processes, CPU time '
                'and file size%s; the master and the probe ran as the judge\'s uid %d, not root'
                % (box.uid, ', %g core(s) of CPU' % box.cpus if box.cpus and box.cgroups else '', box.judge_uid))
    if box.slot is not None:
        return 'ran WITHOUT its sandbox (the teacher\'s flag) as uid %d, with resource limits only' % box.uid
    try:
        user = pwd.getpwuid(os.geteuid()).pw_name
    except KeyError:  # a uid without an account (a container's, a test's)
        user = 'uid %d' % os.geteuid()
    return ('ran WITHOUT its sandbox (the teacher\'s flag) as the grading user %s: it could read and change '
            'that user\'s files' % user)


def how_read(box, uid, bounds):
    """What read the upload, as which uid (the one the inspection saw itself run as), within which bounds."""
    timeout, _, memory = bounds
    where = 'in a bubblewrap box without network' if box.bwrap else \
        'WITHOUT its sandbox (the teacher\'s flag), in a subprocess'
    return ('the upload was read (unpacked, its launch files, code and PDFs analysed) %s as uid %d, within %.0f s '
            'and %d MB' % (where, uid, timeout, memory >> 20))

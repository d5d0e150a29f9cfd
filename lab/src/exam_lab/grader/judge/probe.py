"""The grader's probe: plays the drone for a student's node and measures what the rubric asks.

Run inside its own rospy process, on the master of one submission, by :mod:`exam_lab.grader.host.session`::

    python3 -m exam_lab.grader.judge.probe JOB.json TAG RESULT.json ENDED [WORD.json]

The drone is the harness's :class:`~exam_lab.harness.fake_drone.Drone`, the sheet's own drone (its
topics, rates, service, answers and LED, from the drone package's SPEC; a new value goes out at the
sensor's next tick, as the real drone's reading does), driven by a script with noise-free values from
the oracle, so the same package gets the same measurements. The probe only
measures; the points are given by :mod:`exam_lab.grader.score.rubric` from the JSON it writes.

The plan is the run ``TAG``'s of the session's job (:class:`~exam_lab.grader.score.job.JobRecord`,
:data:`~exam_lab.grader.score.job.PLAN`), as the runner made it: ``kind`` ("main": the whole
scenario, "threshold": the check of question 14a, the same scenario around the threshold drawn for
it), ``sheet``, ``threshold`` (student units), ``margin`` (how far beyond the threshold to fly),
``delay`` (s), ``start_timeout`` (s to wait for the node once roslaunch is up), ``late_warning`` (s a
late WARNING is waited for, 0 for none). ``ENDED`` is the mark the session leaves once the student's
roslaunch has exited. The threshold run also reads the main run's word in ``WORD.json``
(:class:`MainWord`): how late its WARNING came.

Every time is the wall clock's (``time.time()``), never rospy's ROS time: a student's node can set
``/use_sim_time`` on the master before the probe's ``init_node`` and publish ``/clock``, and rospy would
follow. The probe watches for both (a subscriber on ``/clock``, the parameter read at its start and
end: ``clock`` in its result), and the session refuses such a run.

The main scenario (times are the script's, all recorded as wall-clock times of the events):

1. wait for the student's node; note which inputs it subscribes to and what it publishes;
2. question 11: a few input pairs (one with another temperature / remote pressure), the value the node
   publishes for each after it settled;
3. calibration: from those values, the inputs that make the *node's own* value sit ``margin`` below
   and above the threshold and ``NEAR_M`` below it, checked by flying there (a wrong formula costs
   question 11 only);
4. the flight (docs/grading.md's table of legs says which wrong node each leg tells from a right one):
   rest below (``REST_S``, longer for a NORMAL the node owes), a short excursion above (``SHORT_S``),
   just below (``near``, ``GAP_S``), a long excursion (delay + ``AFTER_S``, longer for a late WARNING),
   just below (``BACK_S``), further below (``DEEP_S``, longer for a late NORMAL); every service call is
   recorded with its arrival time. Each leg's hold counts from
   the node's own first value on its side, and every leg is checked on the node's own values (``legs``):
   the rubric times each rule from them and judges nothing on a leg the node's value did not reach.

The probe's parts, each a module of :mod:`exam_lab.grader.judge`: :mod:`~.graph` (the master's view,
rospy's refusals, the clock and the node's pid watched), :mod:`~.node` (step 1), :mod:`~.pilot`
(steps 2 to 4) and :mod:`~.legs` (the legs' holds and checks, pure). This module runs them in order
and writes the result (:class:`~exam_lab.grader.score.records.ProbeRecord`).
"""
import json
import logging
import os
import sys
import time

import rosgraph
import rospy

from exam_lab.grader.judge.pilot import Calibration, Flight, Inputs
from exam_lab.grader.judge.graph import ClockWatch, Graph, NodeWatch, RefusedConnections, node_pid, node_uri
from exam_lab.grader.judge.legs import AFTER_S, trace
from exam_lab.grader.judge.node import NodeFinder
from exam_lab.grader.score.job import JobRecord
from exam_lab.grader.score.records import RecordError
from exam_lab.harness.fake_drone import Drone


class Probe(object):
    """One run of the probe: the drone up and the graph watched from its start, then the plan flown
    (:meth:`run`); ``result`` is what it measured."""

    def __init__(self, plan, word=None, launch_ended=lambda: False):
        self.plan, self.word, self.launch_ended = plan, word, launch_ended
        self.result = {'kind': plan.kind, 'sheet': plan.sheet, 'threshold': plan.threshold,
                       'margin': plan.margin, 'delay': plan.delay, 'start_timeout': plan.start_timeout}
        self.graph = Graph()
        self.refusals = RefusedConnections()
        logging.getLogger('rosout').addHandler(self.refusals)
        self.clock = ClockWatch()
        # Handles of the watch's own: an XML-RPC connection is never shared between two threads.
        watched, lookups = Graph(), rosgraph.Master(rospy.get_name())
        self.watch = NodeWatch(watched.student_nodes, lambda name: node_uri(lookups, name), node_pid).start()
        self.drone = Drone(plan.sheet, clock=time.time, on_ticks=True)
        self.result['input_rates'] = dict(self.drone.rates)
        self.recorder = self.drone.output
        self.inputs = Inputs(self.drone)
        self.t0 = time.time()

    def threshold_check(self):
        """Question 14a: the node restarted with its launch file's threshold changed to a value drawn at
        grading time, flown exactly as the main run (issue 36 point 7: a node cannot tell the two runs
        apart but by the threshold its launch file gave it) around that value, whose long excursion
        stays below the launch file's threshold. A WARNING that came late in the main run (its word,
        :class:`MainWord`) is waited for that long, no longer: a node that ignores the new value costs
        the long excursion, not the late window."""
        self.main_flight(MainWord(self.plan, self.word).late_warning if self.word else None)

    def main_flight(self, late_warning=None):
        """The scenario's steps 1 to 4: a step whose node, or whose readable output, is missing ends it."""
        # Inputs from the start: a node that waits for data before it subscribes to the rest still runs.
        self.inputs.fly(self.plan.threshold - self.plan.margin)
        finder = NodeFinder(self.plan, self.graph, self.refusals, self.drone, self.t0, self.launch_ended)
        found = finder.wait_for_node()
        self.result.update(found)
        if not found['nodes']:
            return
        self.result['output'], self.recorder = finder.find_output(self.recorder)
        calibration, points = Calibration(self.inputs, self.recorder, self.plan), []
        if self.result['output']['topic'] is not None and self.recorder is not None:
            self.result['formula'], points = calibration.formula()
        self.result['calibration'], (lo, hi, near) = calibration.calibrate(points)
        flight = Flight(self.plan, self.inputs.fly, self.recorder, self.drone, self.graph, late_warning)
        self.result.update(flight.fly_legs(lo, hi, near))

    def run(self):
        if self.plan.kind == 'main':
            self.main_flight()
        else:
            self.threshold_check()
        self.result['node_watch'] = self.watch.stop()
        self.result['calls'] = [[t, s] for t, s in self.drone.service.calls()]
        self.result['answers'] = [[t, s, ok, message] for t, s, ok, message in self.drone.service.answers()]
        self.result['graph'] = self.graph.summary()
        seen = self.result.get('input_types') or {}
        for info in self.result['graph'].values():  # the master gives the publisher's type, not the subscriber's
            for entry in info['subscribes']:
                if entry[0] in seen:
                    entry[1] = '%s%s' % (seen[entry[0]]['type'] or 'type unknown: no connection',
                                         ', refused by rospy' if seen[entry[0]]['refused'] else '')
        self.result['alive_at_end'] = bool(self.graph.student_nodes())
        self.result['t0'] = self.t0
        self.result['clock'] = self.clock.seen(self.graph)
        self.result['judge_uid'] = os.getuid()
        published = self.recorder.samples(self.t0) if self.recorder is not None else []
        self.result['trace'] = trace(published, self.inputs.flown)
        return self.result


def late_bound(plan, warn_after):
    """s the threshold run waits for a late WARNING when the main run's took ``warn_after`` s: as long,
    no longer (and never past the plan's own ``late_warning``)."""
    return min(plan.late_warning, max(warn_after, plan.delay) + AFTER_S)


class MainWord(object):
    """What the main run says of its WARNING to this threshold run: the session writes ``{"warned":
    whether it warned in its long excursion, "warn_after": its latency (s) or null}`` in the file
    ``word`` before the threshold run starts (one after the other), or, flown beside it, once the main
    run's result is in (or the main run ended without one). Until then the threshold run waits for a
    late WARNING as the main run does (the plan's ``late_warning``); then as long as the main run's
    took (:func:`late_bound`), or not at all when the main run never warned (the threshold run is then
    not scored)."""

    def __init__(self, plan, word):
        self.plan, self.word, self.said = plan, word, None

    def late_warning(self):
        if self.said is None and os.path.isfile(self.word):
            try:
                with open(self.word) as f:
                    self.said = json.load(f)
            except (OSError, ValueError):
                pass
        if self.said is None:
            return self.plan.late_warning
        if not self.said.get('warned') or not isinstance(self.said.get('warn_after'), (int, float)):
            return 0.0
        return late_bound(self.plan, self.said['warn_after'])


#: Most seconds the probe keeps the drone up after writing its result, waiting to be stopped.
LINGER_S = 60.0


def main(argv):
    """Measure, write the result (atomically), then keep the fake drone serving until stopped
    (SIGINT) or LINGER_S: the student's node must not lose its drone before the grader stops it."""
    if len(argv) not in (4, 5) or argv[1] not in ('main', 'threshold'):
        sys.stderr.write('usage: python3 -m exam_lab.grader.judge.probe JOB.json main|threshold RESULT.json '
                         'ENDED [WORD.json]\n')
        return 2
    # ENDED: the mark the session leaves once the student's roslaunch has exited (no node can come then).
    job_path, tag, result_path, ended = argv[:4]
    try:
        plan = JobRecord.read(job_path).plan(tag)
    except RecordError as err:  # the grader's own bug: the session says the probe failed, and why
        sys.stderr.write('the plan is not one: %s\n' % err)
        return 2
    rospy.init_node('grader_probe', disable_signals=True)
    probe = Probe(plan, argv[4] if len(argv) == 5 else None, launch_ended=lambda: os.path.lexists(ended))
    try:
        result = probe.run()
        with open(result_path + '.part', 'w') as f:
            json.dump(result, f, indent=1, sort_keys=True)
        os.rename(result_path + '.part', result_path)
        time.sleep(LINGER_S)
    except KeyboardInterrupt:
        pass  # the session stopped us, after the student's node
    finally:
        probe.drone.close()
        rospy.signal_shutdown('probe done')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))

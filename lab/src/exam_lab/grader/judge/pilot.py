"""The probe's pilot, what it flies: the drone's inputs set (:class:`Inputs`), question 11's check
points and the calibration that puts the node's own value where each leg needs it (:class:`Calibration`),
and the legs themselves (:class:`Flight`), every leg held from the node's own first value on its side.
The rules each leg keeps (holds, calls owed, checks) are :mod:`exam_lab.grader.judge.legs`'s; this
module only flies them, on the wall clock.
"""
import math
import time

from exam_lab.grader.judge.legs import (AFTER_S, BACK_S, DEEP_S, FLIGHT_LEGS, GAP_S, IGNORE_S, REST_S, SETTLE_S,
                                        SHORT_S, last_value, leg_check, normal_wait, on_side, owes, settled)
from exam_lab.harness import oracle
from exam_lab.harness.wait import wait_until

#: After a change of both inputs, read one period of the slowest input plus this later.
SETTLE_SLACK_S = 0.5
#: The return legs fly the node's own value this far below the threshold (student units), accepted
#: up to NEAR_MAX_M below: closer than any noise band a student might wait for (mydrone's thermometer
#: alone moves the altitude by about 0.45 m).
NEAR_M = 0.1
NEAR_MAX_M = 0.2
#: The most values of a question 11 row's window kept (its last ones): 6 s at 10 Hz.
MAX_ROW_VALUES = 60
#: The most seconds a leg waits for the node's own value to reach the side of the threshold it is
#: flown for (a node that blocks a callback for 5 s publishes a stale value meanwhile).
REACH_S = 8.0


class Inputs(object):
    """The drone's two inputs as the probe sets them, every change kept for the flight plot's trace."""

    def __init__(self, drone):
        self.drone = drone
        #: The fixed input last sent; None sends it again at the next change.
        self.fixed_now = None
        #: How long after the last change the node's value is read (see set).
        self.settle = SETTLE_S
        self.flown = []  # [time, oracle value] at every input change, for the flight plot's trace
        #: Each input's value now, and when each input set last was first read ({topic: time}).
        self.now, self.changes = {}, {}

    def set(self, fixed, moving):
        """Change the inputs (the fixed one only when it changes, as a real drone's would); return the
        time of the first reading of the new values (the later input's next tick)."""
        drone = self.drone
        changed = None
        self.settle = SETTLE_S
        self.changes = {}
        if fixed != self.fixed_now:
            changed = self.changes[drone.fixed_topic] = drone.feeder.set(drone.fixed_topic, fixed)
            self.fixed_now = fixed
            # A node that computes on each reading publishes a mixed pair in between (new fixed, old
            # moving); one that waits for a fresh reading of each follows up to the slowest period later.
            self.settle = max(SETTLE_S, 1.0 / min(drone.rates.values()) + SETTLE_SLACK_S)
        since = self.changes[drone.moving_topic] = drone.feeder.set(drone.moving_topic, moving)
        since = max(since, changed or since)
        self.now.update({drone.fixed_topic: fixed, drone.moving_topic: moving})
        self.flown.append([since, drone.expected(fixed, moving)])
        return since

    def fly(self, x):
        """Put the drone where the oracle's value is ``x`` (reference fixed input); return the time."""
        return self.set(self.drone.fixed_value, self.drone.input_for(x))


class Calibration(object):
    """Question 11's check points and, from them, where to fly so that the node's own value sits where
    each leg needs it: read from ``recorder`` (None: the output cannot be read) while ``inputs`` flies."""

    def __init__(self, inputs, recorder, plan):
        self.inputs, self.recorder, self.plan = inputs, recorder, plan

    def formula(self):
        """Question 11's check points: (fixed input, oracle value) pairs; returns the probe's result's
        ``formula`` (one row a point) and the calibration points."""
        drone, threshold, margin = self.inputs.drone, self.plan.threshold, self.plan.margin
        sheet = self.plan.sheet
        other_fixed = {'altitude': -5.0, 'depth': 90000.0}[sheet]
        cases = [(drone.fixed_value, threshold - 2 * margin), (drone.fixed_value, threshold + 2 * margin),
                 (other_fixed, threshold)]
        points, rows = [], []
        # The value before the first change, so that a node that follows a reading later is waited for.
        before = last_value(self.recorder, 0.0)[0]
        # The fixed input sent again at its next tick: the node's subscription may have connected after
        # its last reading (a publisher registered anew in the node's type), and it reads it once a period.
        self.inputs.fixed_now = None
        for fixed, x in cases:
            if sheet == 'altitude':
                moving = oracle.pressure_at(x, fixed)
            else:
                moving = oracle.pressure_robot_at(x, fixed)
            earlier = dict(self.inputs.now)
            since = self.inputs.set(fixed, moving)
            value, count = settled(self.recorder, since, before, self.inputs.settle)
            before = value
            # Every value of the row's window, the inputs before and when each changed: the rubric
            # judges each value against the inputs the node could have seen (issue 45).
            rows.append({'inputs': {drone.fixed_topic: fixed, drone.moving_topic: moving},
                         'expected': drone.expected(fixed, moving), 'published': value, 'samples': count,
                         'before': earlier, 'changes': dict(self.inputs.changes),
                         'values': [[t, v] for t, v in self.recorder.samples(since + IGNORE_S)][-MAX_ROW_VALUES:]})
            if fixed == drone.fixed_value:
                points.append((x, value))
        return rows, points

    def calibrate(self, points):
        """Oracle values ``lo`` / ``hi`` where the node's own value is ``margin`` below / above the
        threshold: fits value = a*x + b through the check points, flies there, corrects with the
        fitted slope (twice at most). Falls back to the oracle's values when that fails. Returns the
        probe's result's ``calibration`` and the oracle values ``(lo, hi, near)`` to fly."""
        threshold, margin = self.plan.threshold, self.plan.margin
        targets = {'lo': threshold - margin, 'hi': threshold + margin, 'near': threshold - NEAR_M}
        # How close to its target each value must come: the near one just below the threshold.
        close = {'lo': lambda v, t: abs(v - t) < margin / 3, 'hi': lambda v, t: abs(v - t) < margin / 3,
                 'near': lambda v, t: threshold - NEAR_MAX_M <= v <= threshold}
        calibration = {'by': 'oracle', 'reason': '', 'fit': None}
        usable = [(x, y) for x, y in points if y is not None and math.isfinite(y)]
        if self.recorder is None or len(usable) < 2:
            calibration['reason'] = 'no readable output: flying by the oracle\'s values'
        else:
            (x1, y1), (x2, y2) = usable[:2]
            a = (y2 - y1) / (x2 - x1)
            if not math.isfinite(a) or abs(a) < 1e-3:
                calibration['reason'] = ('the output hardly depends on the input (slope %.3g): flying by '
                                         'the oracle\'s values' % a)
            else:
                calibration.update(by='own', fit=[a, y1 - a * x1])
        chosen = {}
        for side, target in sorted(targets.items()):
            x = target
            if calibration['by'] == 'own':
                a, b = calibration['fit']
                x = (target - b) / a
            value = None
            for _ in range(4 if side == 'near' else 3):
                if not self.inputs.drone.can_give(x):  # a fit to a wild value: the oracle's values instead
                    value = None
                    break
                previous = last_value(self.recorder, 0.0)[0] if self.recorder is not None else None
                since = self.inputs.fly(x)
                value = None if self.recorder is None else \
                    settled(self.recorder, since, previous, self.inputs.settle)[0]
                if calibration['by'] != 'own' or value is None or not math.isfinite(value) \
                        or close[side](value, target):
                    break
                x += (target - value) / calibration['fit'][0]
            chosen[side] = {'x': x, 'target': target, 'value': value}
        own_ok = all(v['value'] is not None and math.isfinite(v['value']) for v in chosen.values()) \
            and chosen['lo']['value'] <= threshold < chosen['hi']['value'] and chosen['near']['value'] <= threshold
        if calibration['by'] == 'own' and not own_ok:
            calibration.update(by='oracle', fit=None, reason=(
                'the node\'s values did not come out on both sides of the threshold (%s): flying by the '
                'oracle\'s values' % ', '.join('%s %r' % (k, v['value']) for k, v in sorted(chosen.items()))))
            chosen = {side: {'x': target, 'target': target, 'value': None} for side, target in targets.items()}
        calibration.update(chosen)
        return calibration, (chosen['lo']['x'], chosen['hi']['x'], chosen['near']['x'])


class Flight(object):
    """The main flight's legs around the calibrated values: ``fly`` (oracle value -> the time of the
    input's change) moves the drone, ``recorder`` reads the node's own value (None when it cannot be
    read), ``drone.service`` the calls it made, ``graph`` whether it still runs."""

    def __init__(self, plan, fly, recorder, drone, graph, late_warning=None):
        self.plan, self.fly, self.recorder, self.drone, self.graph = plan, fly, recorder, drone, graph
        #: s a late WARNING is waited for, asked again as the wait goes (the threshold run flown beside
        #: the main run learns the main run's latency during its flight: :class:`~.probe.MainWord`).
        self.late_warning = late_warning or (lambda: plan.late_warning)
        #: The output is read but nothing came on it before the flight (the node publishes nothing a
        #: subscriber receives): each leg is held from the input's change, as with no output, and the
        #: rubric times the calls against the judge's own value of the flight (issue 45).
        self.silent = recorder is not None and not recorder.samples(0.0)

    def leg(self, x, side, hold, late=0.0, late_from=None):
        """Fly at ``x`` for ``hold`` s counted from the node's own first value on ``side`` (the input's
        change when the output cannot be read or is :attr:`silent`, or when that value never comes
        within REACH_S); with
        ``late``, keep flying while the node still owes this side's call (:func:`owes`), up to ``late``
        s after ``late_from`` (default: that first value). Returns ``(the input's change, that first
        value's time)``. ``late`` may be a function, asked on every look: the bound as it is known now."""
        since = self.fly(x)
        start = since
        if self.recorder is not None and not self.silent:
            threshold = self.plan.threshold
            reached = wait_until(lambda: next((t for t, v in self.recorder.samples(since)
                                               if on_side(v, threshold, side)), None), REACH_S, period=0.05)
            start = reached if reached is not None else since
        time.sleep(max(0.0, start + hold - time.time()))
        bound = late if callable(late) else (lambda: late)
        begin = start if late_from is None else late_from
        if bound() > 0 and begin + bound() > time.time():
            wait_until(lambda: not owes(self.drone.service.calls(), side, since) or not self.graph.student_nodes()
                       or time.time() >= begin + bound(), begin + bound() - time.time(), period=0.1)
        return since, start

    def fly_legs(self, lo, hi, near):
        """Fly every leg of FLIGHT_LEGS; returns the probe's result's ``schedule`` (each leg's input
        change, and the end), ``legs`` (each checked on the node's own values) and, when the output
        could be read, ``rate`` (how often the node published during the flight)."""
        delay = self.plan.delay
        late = self.late_warning
        late_normal = normal_wait(delay, self.drone.rates)
        schedule = {}
        schedule['rest'] = self.leg(lo, 'below', REST_S, late_normal)[0]
        schedule['short_up'] = self.leg(hi, 'above', SHORT_S)[0]
        schedule['short_down'] = self.leg(near, 'below', GAP_S)[0]
        schedule['long_up'] = self.leg(hi, 'above', delay + AFTER_S, late)[0]
        schedule['long_down'], back = self.leg(near, 'below', BACK_S)
        schedule['deep_down'] = self.leg(lo, 'below', DEEP_S, late_normal, late_from=back)[0]
        schedule['end'] = time.time()
        flown = {'schedule': schedule, 'legs': self.legs(schedule, FLIGHT_LEGS), 'silent': self.silent}
        if self.recorder is not None:
            samples = self.recorder.samples(schedule['rest'], schedule['end'])
            rate = {'samples': len(samples), 'hz': None, 'max_gap': None}
            if len(samples) >= 2:
                span = samples[-1][0] - samples[0][0]
                rate['hz'] = (len(samples) - 1) / span if span > 0 else None
                rate['max_gap'] = max(b[0] - a[0] for a, b in zip(samples, samples[1:]))
                values = [v for _, v in samples]
                rate['non_finite'] = len([v for v in values if not math.isfinite(v)])
            flown['rate'] = rate
        return flown

    def legs(self, schedule, names):
        """Each leg checked on the node's own values (None when the output cannot be read)."""
        if self.recorder is None:
            return None
        keys = sorted(schedule, key=schedule.get)
        out = {}
        for name in names:
            end = schedule[keys[keys.index(name) + 1]]
            side = 'above' if name.endswith('up') or name == 'step' else 'below'
            out[name] = leg_check(self.recorder.samples(schedule[name]), self.plan.threshold, side,
                                  schedule[name], end)
        return out

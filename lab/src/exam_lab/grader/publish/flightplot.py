"""The flight plot of one student: what its node published against the oracle, the threshold, the
warning service's calls and the legs the grader flew, one panel per run. No rospy here.

Drawn from the probe's results as the grading kept them (:func:`load_runs`: the session's record in
the student's measurements, never a file of the judge's or a box's read back) with matplotlib's Agg
backend (no display needed); times are seconds from the probe's start.
"""
import io
import math
import os

from exam_lab.grader import contract
from exam_lab.grader.score.kept import MeasurementsRecord
from exam_lab.grader.score.records import MEASUREMENTS
from exam_lab.grader.score.flight import calls
from exam_lab.grader.score.safe_text import one_line

#: Legs of each run, in order, and the side of the threshold each is flown on.
LEGS = {'rest': 'below', 'short_up': 'above', 'short_down': 'below', 'long_up': 'above', 'long_down': 'below', 'deep_down': 'below',
        'start': 'below', 'step': 'above'}
#: Each leg's name on the plot: the manual's (docs/grading.md, "The legs of the flight"; a docs test
#: holds the two together); the threshold run's first two its own.
LEG_NAMES = {'rest': 'rest', 'short_up': 'short excursion', 'short_down': 'just below', 'long_up': 'long excursion',
             'long_down': 'return just below', 'deep_down': 'further below', 'start': 'start', 'step': 'step'}
_SIDE_COLOUR = {'above': '#f4cccc', 'below': '#d9e8f5'}
#: Up to this many calls of a kind, each is also a vertical line across the panel.
FEW_CALLS = 10
_CALL_COLOUR = {'WARNING': '#cc0000', 'NORMAL': '#2a9d2a'}
#: Values are drawn within +-LIMIT (student units; the drones fly within a few thousand): a node that
#: published +-1.7e308 once made matplotlib's scaling overflow (LinAlgError) and stopped the desk.
#: A value beyond is clamped to the limit (a published one is drawn as an arrow at the panel's edge,
#: so the node's other values keep their scale), a time or value that is not a number is left out,
#: and the panel says how many of each.
LIMIT = 1e6


def load_runs(folder):
    """``[(tag, probe result)]`` of the runs whose probe gave a result, one the rubric refuses (its
    times, its master) too (kept as ``refused_probe`` by a grader of before 2026-12-02), from the
    measurements the grading kept in ``folder`` (:class:`~exam_lab.grader.score.kept.MeasurementsRecord`,
    the grader's own file, read as a record: capped, checked): their session is the
    :class:`~exam_lab.grader.score.records.SessionRecord` made when the student was graded, its text
    made safe there. ``[]`` without measurements; raises
    :class:`~exam_lab.grader.score.records.RecordError` (naming the file and the field) when they are
    not a record. Drawn as they are: a value out of range only costs what :class:`Clamp` leaves out."""
    path = os.path.join(folder, MEASUREMENTS)
    if not contract.exists(path):
        return []
    runs = [(run['tag'], run['probe'] or run.get('refused_probe'))
            for run in contract.read_record(path, MeasurementsRecord).session['runs']]
    return [(tag, probe) for tag, probe in runs if probe is not None]


def legs(schedule):
    """``[(name, start, end, side)]`` of a run's schedule (ROS times)."""
    names = sorted((k for k in schedule if k in LEGS), key=schedule.get)
    ends = sorted(schedule.values())
    out = []
    for name in names:
        later = [t for t in ends if t > schedule[name]]
        out.append((name, schedule[name], later[0] if later else schedule[name], LEGS[name]))
    return out


def draw(runs, path, title=''):
    """Write the PNG at ``path``; return False (and write nothing) when no run has anything to draw."""
    runs = [(tag, probe) for tag, probe in runs if probe.get('trace') or probe.get('calls')]
    if not runs:
        return False
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib import pyplot as plt
    fig, axes = plt.subplots(len(runs), 1, figsize=(9.5, 3.1 * len(runs)), dpi=90, squeeze=False)
    try:
        for ax, (tag, probe) in zip(axes[:, 0], runs):
            _panel(ax, tag, probe)
        if title:
            fig.suptitle(one_line(title), fontsize=11)  # a student's name: no control character
        fig.tight_layout()
        image = io.BytesIO()
        fig.savefig(image, format=os.path.splitext(path)[1][1:] or 'png')
        contract.write_bytes(path, image.getvalue())
    finally:
        plt.close(fig)  # a plot that failed must not keep its figure for the class's next one
    return True


class Clamp(object):
    """Numbers made drawable, counting what was changed for the panel's note: values within
    +-:data:`LIMIT`, times (seconds from the probe's start) within the same bound or left out."""

    def __init__(self, limit=LIMIT):
        self.limit, self.clamped, self.dropped = limit, 0, 0

    def _number(self, x):
        try:
            x = float(x)
        except (TypeError, ValueError):
            return None
        return None if math.isnan(x) else x

    def value(self, x):
        """``x`` within +-limit, or None (counted) when it is not a number at all."""
        x = self._number(x)
        if x is None:
            self.dropped += 1
        elif abs(x) > self.limit:
            self.clamped += 1
            x = math.copysign(self.limit, x)
        return x

    def time(self, t, t0):
        """``t - t0``, or None (counted) when it is not a number or beyond the limit: a time drawn at
        the limit would stretch the panel as far."""
        t = self._number(t)
        if t is None or not abs(t - t0) <= self.limit:
            self.dropped += 1
            return None
        return t - t0

    def pairs(self, pairs, t0):
        """``[(t - t0, value)]`` of ``[[t, value]]``; a pair whose value is None (the probe's word for
        a non-finite value) is left out uncounted, one that is malformed or not a number is counted."""
        out = []
        for pair in pairs or []:
            if not isinstance(pair, (list, tuple)) or len(pair) != 2:
                self.dropped += 1
            elif pair[1] is not None:
                t, v = self.time(pair[0], t0), self.value(pair[1])
                if t is not None and v is not None:
                    out.append((t, v))
        return out

    def note(self):
        """What the panel says of the numbers changed, or ''."""
        parts = []
        if self.clamped:
            parts.append('%d value(s) beyond ±%g (published ones: arrows at the edge)' % (self.clamped, self.limit))
        if self.dropped:
            parts.append('%d time(s) or value(s) not a number or out of range, not drawn' % self.dropped)
        return '; '.join(parts)


def _limits(ax, published, oracle, threshold):
    """The y range of the node's own values and the threshold, so its crossings show; the oracle's
    values beyond that range (a formula far off) are said in the panel rather than squashing it."""
    own = published + ([threshold] if threshold is not None else [])
    if not published:
        return
    low, high = min(own), max(own)
    pad = max(0.08 * (high - low), 1.0)
    low, high = low - pad, high + pad
    ax.set_ylim(low, high)
    outside = [v for v in oracle if not low <= v <= high]
    if outside:
        ax.text(0.01, 0.04, 'oracle off this scale: %.0f to %.0f' % (min(outside), max(outside)),
                transform=ax.transAxes, fontsize=8, color='#555555', va='bottom',
                bbox=dict(facecolor='white', alpha=0.85, lw=0))


def _panel(ax, tag, probe):
    clamp = Clamp()
    t0 = probe.get('t0') or 0.0
    t0 = t0 if isinstance(t0, (int, float)) and math.isfinite(t0) else 0.0
    trace = probe.get('trace') or {}
    published = clamp.pairs(trace.get('published'), t0)
    beyond = [(t, v) for t, v in published if abs(v) >= clamp.limit]
    published = [(t, v) for t, v in published if abs(v) < clamp.limit]
    oracle = clamp.pairs(trace.get('oracle'), t0)
    schedule = {k: clamp.time(v, t0) for k, v in (probe.get('schedule') or {}).items()}
    schedule = {k: v for k, v in schedule.items() if v is not None}  # seconds from the probe's start
    end = max([t for t, _ in published + beyond] + [t for t, _ in oracle] + [schedule.get('end', 0.0)])
    for row, (name, start, stop, side) in enumerate(legs(schedule)):
        ax.axvspan(start, stop, color=_SIDE_COLOUR[side], alpha=0.6, lw=0)
        # Two rows, one leg in two on each: the short legs' names (2 s wide) never overlap.
        ax.text((start + stop) / 2, 1.0 + 0.08 * (row % 2), LEG_NAMES[name], transform=ax.get_xaxis_transform(),
                ha='center', va='bottom', fontsize=7, color='#555555')
    if oracle:
        xs = [t for t, _ in oracle] + [end]
        ys = [v for _, v in oracle] + [oracle[-1][1]]
        ax.step(xs, ys, where='post', color='#888888', lw=1.5, label='oracle (equation 1)')
    if not published and not beyond:
        ax.text(0.5, 0.5, 'the node published no value the probe could read', transform=ax.transAxes,
                ha='center', fontsize=10, color='#b00000')
    if published:
        ax.plot([t for t, _ in published], [v for _, v in published], '.', ms=2.5, color='#1f5fa8',
                label='published by the node')
    for sign, edge, marker in ((1, 0.98, '^'), (-1, 0.02, 'v')):
        times = [t for t, v in beyond if v * sign > 0]
        if times:
            ax.plot(times, [edge] * len(times), marker, color='#1f5fa8', ms=7, clip_on=False,
                    transform=ax.get_xaxis_transform(), label='published beyond %s%g (%d)' % (
                        '+' if sign > 0 else '-', clamp.limit, len(times)))
    threshold = probe.get('threshold')
    threshold = clamp.value(threshold) if threshold is not None else None
    if threshold is not None:
        ax.axhline(threshold, color='#cc0000', ls='--', lw=1, label='threshold %g' % threshold)
    made = calls(probe)
    # grade.md counts the calls of the flight (rest to end, question 13): so does the legend; those of the
    # calibration before it are drawn and counted apart.
    flown = (schedule.get('rest'), schedule.get('end')) if 'rest' in schedule and 'end' in schedule else None

    def counted(times):
        inside = [t for t in times if flown is None or flown[0] <= t <= flown[1]]
        return '%d in the flight%s' % (len(inside), ', %d before' % (len(times) - len(inside))
                                         if len(inside) < len(times) else '') if flown else '%d' % len(times)

    for kind in ('WARNING', 'NORMAL'):
        for accepted in (True, False):
            times = [clamp.time(t, t0) for t, meaning, _, ok in made if meaning == kind and ok == accepted]
            times = [t for t in times if t is not None]
            requests = sorted(set(r for _, meaning, r, ok in made if meaning == kind and ok == accepted))
            if len(times) <= FEW_CALLS:
                for t in times:
                    ax.axvline(t, color=_CALL_COLOUR[kind], lw=1, alpha=0.8, ls='-' if accepted else ':')
            if times:
                ax.plot(times, [0.96] * len(times), 'v', color=_CALL_COLOUR[kind], ms=6, clip_on=False,
                        mfc=_CALL_COLOUR[kind] if accepted else 'white', transform=ax.get_xaxis_transform(),
                        label='%s calls (%s)' % (kind, counted(times)) if accepted else
                        'REFUSED %s calls (%s)' % (' / '.join('"%s"' % r[:12] for r in requests[:2]), counted(times)))
    other = [(clamp.time(t, t0), r) for t, meaning, r, _ in made if meaning not in _CALL_COLOUR]
    other = [(t, r) for t, r in other if t is not None]
    if other:
        ax.plot([t for t, _ in other], [0.96] * len(other), 'x', color='#7a4a00', ms=6, clip_on=False,
                transform=ax.get_xaxis_transform(), label='REFUSED other calls (%s)' % counted([t for t, _ in other]))
    _limits(ax, [v for _, v in published], [v for _, v in oracle], threshold)
    if clamp.note():
        ax.text(0.99, 0.04, clamp.note(), transform=ax.transAxes, fontsize=8, color='#b00000', ha='right',
                va='bottom', bbox=dict(facecolor='white', alpha=0.85, lw=0))
    run = 'main run' if tag == 'main' else 'threshold run (lowered threshold, question 14a)'
    ax.set_title(run, fontsize=9, loc='left', pad=22)
    ax.set_xlabel('s from the probe\'s start')
    ax.set_ylabel(probe.get('sheet') or 'value')
    ax.set_xlim(0, max(end, 1.0))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc='center left', bbox_to_anchor=(1.0, 0.5))

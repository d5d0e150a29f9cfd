"""Whether a run counts: the rubric's rules over the facts the session recorded of it. Pure, no rospy.

The session (:func:`exam_lab.grader.host.run.run_one`) records what happened and judges nothing: the
probe's result as it read it (``probe``), the wall times the probe was started and its result was in
(``probe_wall``), the run's master (its memory, whether it ended during the run: ``master.died``).
:func:`judged` applies the rules: a result that cannot be the run's measurement (:func:`probe_problem`:
no times, times outside its run, the clock set, a flight shorter than the rule's delay) or a run whose
master failed it (:func:`master_problem`) is set aside (:func:`refuse`), and the deaths the judge's
watch saw cost what roslaunch's do (:func:`watched_deaths`). The rubric reads a session only as judged
(:func:`~exam_lab.grader.score.measured.session_of`), by a grading and by make rescore alike: a rescore
judges the kept runs again with today's rules.

A run kept without ``probe_wall`` was judged by the session that flew it (measurements kept before
2026-12-02): its verdict and its deaths are read as kept, so its rescore gives the grade it had.
"""
from exam_lab.grader.score.sheets import DELAY, request_meaning

#: The most deaths of one run the judge's watch reports.
WATCHED_DEATHS = 20


def watched_deaths(probe):
    """The deaths the probe's :class:`~exam_lab.grader.judge.graph.NodeWatch` saw (a node started again
    or gone during the run) in its record (a :class:`~exam_lab.grader.score.records.ProbeRecord`'s
    value: checked, its text clean), as entries of a run's ``launch.ended``: they cost what a death in
    roslaunch's words costs, and they are the judge's own, whatever roslaunch's log kept."""
    return [{'node': d['node'][:100], 'how': 'died', 'detail': 'seen by the judge: %s' % d['detail'][:200]}
            for d in probe['node_watch']['deaths'][:WATCHED_DEATHS]]


def warned_in_long_excursion(probe):
    """True when the main run saw a WARNING call while the value was above the threshold for long: the
    threshold run is flown (or kept, flown beside it) only then."""
    schedule = (probe or {}).get('schedule') or {}
    if 'long_up' not in schedule:
        return False
    return any(request_meaning(status) == 'WARNING' and schedule['long_up'] <= t <= schedule['long_down']
               for t, status in probe.get('calls', []))


def warning_latency(probe):
    """Seconds from the long excursion's start to the main run's first WARNING in it, or None."""
    schedule = (probe or {}).get('schedule') or {}
    times = [t for t, status in (probe or {}).get('calls', []) if request_meaning(status) == 'WARNING'
             and schedule.get('long_up', float('inf')) <= t <= schedule.get('long_down', 0.0)]
    return min(times) - schedule['long_up'] if times else None


def clock_problem(clock):
    """Why a run whose probe saw ``clock`` (its ``ClockWatch``) is not the judge's to measure, or None:
    someone set ``/use_sim_time`` or published ``/clock`` (the node under test counting on a clock of
    its own making; the probe times on the wall clock regardless)."""
    if not isinstance(clock, dict):
        return 'the probe did not say whether /clock was published'
    said = []
    if any(clock.get('use_sim_time') or []):
        said.append('/use_sim_time was set on the master')
    if clock.get('messages') or clock.get('publishers'):
        said.append('/clock was published (%s messages%s)' % (
            clock.get('messages', 0),
            ' by %s' % ', '.join(map(str, clock['publishers'])) if clock.get('publishers') else ''))
    if said:
        return '%s: the grader times the node on the wall clock only; grade it by hand' % ' and '.join(said)
    return None


def probe_problem(result, started, finished, *, kind, delay):
    """Why the probe's ``result`` cannot be this run's measurement, or None: it has times, nobody set
    the time (:func:`clock_problem`), every time it records (wall clock) must lie between the probe's
    start and the result's arrival, and the flight must have lasted its schedule (in a ``kind``
    'main' run, the long excursion at least the rule's ``delay``)."""
    schedule = result.get('schedule') or {}
    times = [t for t in [result.get('t0')] + list(schedule.values()) if isinstance(t, (int, float))]
    if not times:
        return 'the probe\'s result has no times'
    problem = clock_problem(result.get('clock'))
    if problem:
        return problem
    if min(times) < started - 1.0 or max(times) > finished + 1.0:
        return 'the probe\'s times (%.1f to %.1f) are not within its run (%.1f to %.1f)' % (
            min(times), max(times), started, finished)
    if kind == 'main' and 'long_up' in schedule and 'long_down' in schedule \
            and schedule['long_down'] - schedule['long_up'] < delay:
        return 'the long excursion lasted %.1f s, less than the %.1f s delay' % (
            schedule['long_down'] - schedule['long_up'], delay)
    return None


def master_problem(master, died):
    """Why a run whose master ended early (``died``) or hit its memory bound (``master``: the cgroup's
    :func:`~exam_lab.grader.host.cgroups.memory_use`) is not one to score, or None."""
    memory = master.get('memory') or {}
    if memory.get('oom_kills'):
        return ('the master the node talks to went over its memory bound of %d MB (%d process(es) killed): '
                'the node\'s parameters or messages filled it' % ((memory.get('limit') or 0) >> 20, memory['oom_kills']))
    if died:
        return 'the master the node talks to ended during the run'
    return None


def refuse(run, problem):
    """Set aside a run's result that is not its measurement (``problem``: why), in ``run`` (a copy the
    judge owns): the rubric sees no probe; the result stays as ``refused_probe`` (the teacher's flight
    plot draws it)."""
    if run['probe'] is not None:
        run['refused_probe'] = run['probe']
    run['probe'], run['probe_refused'] = None, problem
    run['probe_error'] = 'result refused: %s' % problem


def judged_run(run):
    """``run`` (one of a session's record, as the session recorded it) as the rubric counts it: a new
    value, without ``probe_wall`` (so judging it again changes nothing), ``run`` unchanged. The probe's
    result is judged first, its master then (whose problem is the one said when there are both)."""
    if 'probe_wall' not in run:
        return run
    started, finished = run['probe_wall']
    run = {key: value for key, value in run.items() if key != 'probe_wall'}
    probe, master = run.get('probe'), run.get('master') or {}
    if probe is not None:
        run['launch'] = dict(run['launch'], ended=list(run['launch']['ended']) + watched_deaths(probe))
        problem = probe_problem(probe, started, finished, kind=run['tag'], delay=DELAY)
        if problem:
            refuse(run, problem)
    problem = master_problem(master, master.get('died'))
    if problem:
        refuse(run, problem)
    return run


def judged(session):
    """A session's record (its value, as kept) with each run :func:`judged_run`."""
    if not session or not session.get('runs'):
        return session
    return dict(session, runs=[judged_run(run) for run in session['runs']])

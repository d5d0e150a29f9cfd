"""The session's job (``job.json``): what root hands down to the session and, run by run, to the judge.
Pure, no rospy.

:func:`exam_lab.grader.runner.plan_job` makes it once from the inspection's record (each run's
:class:`Plan`, the judge's orders); :func:`~exam_lab.grader.runner.run_session` adds where the
session runs; the session (:mod:`exam_lab.grader.host.session`) and the judge
(:mod:`exam_lab.grader.judge.probe`) read it back through :meth:`JobRecord.read`, checked. Frozen
dataclasses: nothing on the way changes a plan.
"""
import typing
from dataclasses import dataclass

from exam_lab.grader.score.records import NAME
from exam_lab.grader.score.schema import DataRecord, Items, Map, Maybe, Number, OneOf, Optional, RecordError, Text
from exam_lab.grader.score.sheets import SHEETS

#: A folder or file of the grader's machine (the session's work folders, the underlay).
_PATH = Text(4096)


#: One run's plan, the judge's orders (:mod:`exam_lab.grader.judge.probe`): the sheet, the threshold
#: flown and its margin, the rule's delay, how long the node may take to start, the output topic
#: expected, how long a late WARNING is waited for (``late_warning``; 0 when the code calls no
#: service). Part of the job (:class:`JobRecord`), made once by :func:`exam_lab.grader.runner.plan_job`.
PLAN = {
    'kind': OneOf('main', 'threshold'), 'sheet': OneOf(*sorted(SHEETS)), 'threshold': Number(),
    'margin': Number(0), 'delay': Number(0), 'start_timeout': Number(0), 'output': NAME,
    'late_warning': Number(0),
}


@dataclass(frozen=True)
class Plan(object):
    """One run's plan (:data:`PLAN`), as the judge reads it."""
    kind: str
    sheet: str
    threshold: float
    margin: float
    delay: float
    start_timeout: float
    output: str
    late_warning: float


#: A box as the runner opened it, for the session to make its command lines
#: (:meth:`exam_lab.grader.host.sandbox.Box.describe`).
_BOX = {'work': _PATH, 'bwrap': bool, 'cpus': Maybe(Number(0, 4096)), 'binds': [_PATH],
        'slot': Maybe(Number(0, 1e6, integer=True)), 'cgroups': [_PATH], 'judge_cgroups': Map(Text(50), [_PATH], 10),
        'rootless': bool, 'owner': Maybe(Number(0, 2 ** 32, integer=True)), 'netns': Maybe(Text(200)),
        'name': Optional(OneOf('box', 'box-twin'))}


@dataclass(frozen=True)
class BoxPlace(object):
    """A box as the runner opened it (:data:`_BOX`): what another process needs to make its command
    lines (:meth:`exam_lab.grader.host.sandbox.Box.attached`)."""
    work: str
    bwrap: bool
    cpus: typing.Optional[float]
    binds: typing.Tuple[str, ...]
    slot: typing.Optional[int]
    cgroups: typing.Tuple[str, ...]
    judge_cgroups: typing.Mapping[str, typing.Tuple[str, ...]]
    rootless: bool
    owner: typing.Optional[int]
    netns: typing.Optional[str]
    name: typing.Optional[str] = None


@dataclass(frozen=True)
class JobRun(object):
    """One run of the job: its ``tag``, its launch file, its :class:`Plan`; flown side by side, the
    ``box`` and ``judge_home`` of its own (None: the job's)."""
    tag: str
    launch: str
    plan: Plan
    box: typing.Optional[BoxPlace] = None
    judge_home: typing.Optional[str] = None


@dataclass(frozen=True)
class JobRecord(DataRecord):
    """The session's job (``job.json``, read by :mod:`exam_lab.grader.host.session`): the runs (each a
    :class:`JobRun`: its tag, its launch file, its :class:`Plan`), the student's namespace, the time
    limits, the launch file as handed in (for roslaunch's check). :func:`~exam_lab.grader.runner.plan_job`
    makes it from the inspection, the launch files relative to the workspace;
    :func:`~exam_lab.grader.runner.run_session` adds where the session runs (``workspace``, the
    ``underlay``, the folders, the ``box``) and the student's ``budget``, the launch files then absolute;
    with ``side_by_side``, the two runs fly at once, the threshold run in a ``box`` and a ``judge_home``
    of its own. The plans are made once, there, and go down to the judge as they are, in the job
    (:meth:`plan`): nothing on the way changes them. What the threshold run learns of the main run
    (how late its WARNING came) is the main run's word, not its plan
    (:class:`~exam_lab.grader.judge.probe.MainWord`)."""
    FILE = 'job.json'
    MAX_BYTES = 1 << 20
    SCHEMA = {
        'namespace': Text(1000), 'build_timeout': Number(0), 'run_timeout': Number(0),
        'runs': Items({'tag': OneOf('main', 'threshold'), 'launch': _PATH, 'plan': PLAN,
                       'box': Optional(_BOX), 'judge_home': Optional(_PATH)}, 2),
        'handed_in_launch': Maybe(_PATH), 'side_by_side': Optional(bool),
        'workspace': Optional(_PATH), 'underlay': Optional(_PATH), 'log_dir': Optional(_PATH),
        'judge_home': Optional(_PATH), 'box': Optional(_BOX), 'budget': Optional(Number()),
        'student_budget': Optional(Number(0)),
    }
    namespace: str
    build_timeout: float
    run_timeout: float
    runs: typing.Tuple[JobRun, ...]
    handed_in_launch: typing.Optional[str]
    side_by_side: typing.Optional[bool] = None
    workspace: typing.Optional[str] = None
    underlay: typing.Optional[str] = None
    log_dir: typing.Optional[str] = None
    judge_home: typing.Optional[str] = None
    box: typing.Optional[BoxPlace] = None
    budget: typing.Optional[float] = None
    student_budget: typing.Optional[float] = None

    def validate(self):
        if [run.tag for run in self.runs] not in (['main'], ['main', 'threshold']):
            raise RecordError('job.json.runs: the main run, then the threshold run if any')
        for run in self.runs:
            if run.plan.kind != run.tag:
                raise RecordError('job.json.runs: the %s run with a plan of a %s run' % (run.tag, run.plan.kind))

    def plan(self, tag):
        """The :class:`Plan` of the run ``tag``: the judge's orders."""
        for run in self.runs:
            if run.tag == tag:
                return run.plan
        raise RecordError('job.json.runs: no %s run' % tag)

    def run(self, tag):
        """The :class:`JobRun` ``tag``."""
        return next(run for run in self.runs if run.tag == tag)

    def box_of(self, run):
        """Where ``run`` flies: its own box (side by side), else the job's."""
        return run.box or self.box

    def judge_home_of(self, run):
        """The judge's folder of ``run``: its own (side by side), else the job's."""
        return run.judge_home or self.judge_home

"""What the drone really prints (the reference outputs of questions 4-9), as a record, and what of
it is expected to vary from run to run. Pure, no rospy.

:mod:`exam_lab.grader.host.reference` runs the sheet's drone and captures the commands' outputs into a
:class:`ReferenceRecord`; the checks of :mod:`exam_lab.grader.score.answers` read the facts a
student's paste must share with it (:func:`facts`), leaving out what differs on every run: pids, ports,
hosts and file descriptors, the ``/rosout_agg`` line (a master of another version may lack it), the
topics only this simulator has (its LED, its ground truth, ``/diagnostics``: the course's drone has
none), the float digits of the readings.
"""
import re
import typing
from dataclasses import dataclass

from exam_lab.grader.score.schema import DataRecord, Map, Maybe, Number, OneOf, Text
from exam_lab.grader.score.sheets import SHEETS


def reference_file(sheet):
    """The reference's file name in OUT."""
    return 'reference-%s.json' % sheet


@dataclass(frozen=True)
class Command(object):
    """One command as the drone's reference ran it: its line, its output, its exit status."""
    line: str
    output: str
    status: typing.Optional[int]


@dataclass(frozen=True)
class ReferenceRecord(DataRecord):
    """The reference outputs of one sheet's drone (``reference-<sheet>.json``): its package, its node's
    name, the question's topic and the other input, the rates its spec configures (Hz by topic name),
    each command's ``{line, output, status}`` by key (:func:`~exam_lab.grader.host.reference.commands`,
    and ``catkin_create_pkg``), the files ``catkin_create_pkg`` made."""
    FILE = 'reference.json'
    MAX_BYTES = 1 << 20
    CLEAN = True
    SCHEMA = {
        'version': OneOf(1), 'sheet': OneOf(*sorted(SHEETS)), 'drone': Text(100), 'node': Text(200),
        'topic': Text(200), 'other_topic': Text(200), 'rates': Map(Text(100), Number(0, 1e6), 10),
        'commands': Map(Text(50), {'line': Text(500), 'output': Text(10000),
                                   'status': Maybe(Number(-1e6, 1e6, integer=True))}, 20),
        'created': [Text(500)],
    }
    version: int
    sheet: str
    drone: str
    node: str
    topic: str
    other_topic: str
    rates: typing.Mapping[str, float]
    commands: typing.Mapping[str, Command]
    created: typing.Tuple[str, ...]


#: rostopic hz's line of a rate ("average rate: 0.778").
AVERAGE_RATE = re.compile(r'average\s+rate\s*:\s*([0-9]+(?:[.,][0-9]+)?)', re.I)
#: Topics this simulator publishes that the course's drone does not (the sheet's rosnode info lists none).
SIMULATOR_EXTRAS = ('alt_warn_led', 'depth_warn_led', 'diagnostics', 'true_altitude', 'true_depth')


def _listed(output):
    """The names a ``rosnode list`` / ``rostopic list`` output (or a list section) gives, in order."""
    return [m.group(1) for m in re.finditer(r'(?m)^\s*(?:\*\s*)?(/[\w/]+)', output)]


def _extra(name):
    return name == '/rosout_agg' or name.rsplit('/', 1)[-1] in SIMULATOR_EXTRAS


def facts(record):
    """The facts of the drone's outputs that every run shares, as a plain dict: ``nodes`` (rosnode
    list), ``topics`` (rostopic list, the simulator's extras and /rosout_agg left out), ``type`` (of the
    question's topic), ``fields`` (rosmsg info's lines), ``rate`` (configured, Hz) and ``measured``
    (rostopic hz's last average, or None), ``other_rate`` (the other input's), ``publications`` (the
    node's, without the extras), ``services`` (the node's own service), ``created`` (the files
    catkin_create_pkg made), ``node``, ``topic``, ``other_topic``, ``drone``."""
    value = record.value if isinstance(record, ReferenceRecord) else record
    out = value['commands']

    def output(key):
        return (out.get(key) or {}).get('output') or ''

    def measured(key):
        rates = AVERAGE_RATE.findall(output(key))
        return float(rates[-1].replace(',', '.')) if rates else None

    info = output('rosnode_info')
    publications = info.split('Publications:', 1)[-1].split('Subscriptions:', 1)[0]
    services = info.split('Services:', 1)[-1].split('contacting node', 1)[0]
    return {
        'drone': value['drone'], 'node': value['node'], 'topic': value['topic'], 'other_topic': value['other_topic'],
        'nodes': _listed(output('rosnode_list')),
        'topics': [t for t in _listed(output('rostopic_list')) if not _extra(t)],
        'type': output('rostopic_type').strip().splitlines()[-1].strip() if output('rostopic_type').strip() else None,
        'fields': [l.strip() for l in output('rosmsg_info').splitlines() if l.strip()],
        'rate': value['rates'].get(value['topic'].lstrip('/')),
        'other_rate': value['rates'].get(value['other_topic'].lstrip('/')),
        'measured': measured('rostopic_hz'), 'other_measured': measured('rostopic_hz_other'),
        'publications': [t for t in _listed(publications) if not _extra(t)],
        'services': [s for s in _listed(services) if not s.endswith(('/get_loggers', '/set_logger_level'))],
        'created': list(value['created']),
    }

"""What the grader needs to know of each exam sheet, and the rubric's maxima. No rospy here.

Topic and service names are the sheets' own (relative, as the drones publish them); the values the
grader drives with come from :mod:`exam_lab.harness.oracle`, the drone itself is
:class:`exam_lab.harness.fake_drone.Drone`.
"""
import collections
import re

Sheet = collections.namedtuple('Sheet', 'name seed drone_pkg drone_type inputs output service threshold')

SHEETS = collections.OrderedDict([
    ('altitude', Sheet('altitude', '000', 'mydrone', 'mydrone_node.py', ('temperature', 'pressure'),
                       'altitude', 'altitude_warning', 1300.0)),
    ('depth', Sheet('depth', '001', 'submarinedrone', 'submarine_drone_node.py',
                    ('pressure_robot', 'pressure_remote'), 'depth', 'depth_warning', 150.0)),
])

#: The package a student must create (question 9).
PACKAGE = 'exam'
#: The delay of question 14(b), s (both sheets).
DELAY = 5.0
#: A node whose WARNING has not come by the end of the long excursion is kept above the threshold up
#: to this many s after its own value went there (only when its code makes a service client), so a
#: late WARNING costs question 14b's delay only, not questions 13 and 14a too.
LATE_WARNING_S = 60.0

#: The rubric (sheet 000's grader notes, used for sheet 001 too): item id -> (points, what it asks).
ITEMS = collections.OrderedDict([
    ('runs', (2.0, 'the package builds, the node starts and stays up')),
    ('Q10', (2.0, 'the node subscribes to both input topics')),
    ('Q11', (4.0, 'the output topic: Float32 publisher, 10 Hz, values of equation (1)')),
    ('Q12', (1.0, 'a launch file starts the drone node and the exam node')),
    ('Q13', (4.0, 'the warning service is called on crossings, and only there')),
    ('Q14a', (1.0, 'the threshold is a launch-file parameter that the node obeys')),
    ('Q14b', (3.0, 'WARNING after 5 s beyond the threshold, not for less, NORMAL at once')),
])

#: What the machine does not judge, scored by the teacher by hand (sheet 000's notes, for both sheets):
#: the report's questions 4-9, the comments and the code quality. With ITEMS: 17 + 13 = 30 points.
HAND_ITEMS = collections.OrderedDict([
    ('Q4', (1.0, 'report: the running nodes listed (half without a comment)')),
    ('Q5', (2.0, 'report: the drone node\'s information, each line explained (1 if lines are not)')),
    ('Q6', (1.0, 'report: the topics listed and /rosout\'s role explained (0 without it)')),
    ('Q7', (1.0, 'report: the message type of the first input topic (half without a comment)')),
    ('Q8', (1.0, 'report: a few messages and their rate (0.5 if the command is right, the rate wrong)')),
    ('Q9', (1.0, 'report: the package created and explained (0 if nothing is explained)')),
    ('comments', (4.0, 'the code is commented throughout, clearly (half if few, 0 if clearly not enough)')),
    ('quality', (2.0, 'code quality: algorithmically well written, following good practice')),
])


#: The requests the sheets name for the warning service (the drone refuses any other string).
REQUESTS = ('WARNING', 'NORMAL')
#: Other words students send for each status, upper case: the LED's colours and labels, on/off and
#: true/false, English and French (the course's language). A request is read by its whole text, else by
#: its first word ("WARNING: too high"), so "NOT NORMAL" means neither.
MEANINGS = {
    'WARNING': ('WARNING', 'WARN', 'WARNED', 'ALERT', 'ALARM', 'DANGER', 'RED', 'ON', 'TRUE', 'HIGH', 'ABOVE',
                'ALT WARN', 'DEPTH WARN', 'ALTITUDE WARNING', 'DEPTH WARNING', 'TOO HIGH', 'TOO DEEP',
                'ALERTE', 'ATTENTION', 'ROUGE', 'AVERTISSEMENT'),
    'NORMAL': ('NORMAL', 'OK', 'OKAY', 'GREEN', 'OFF', 'FALSE', 'LOW', 'BELOW', 'SAFE', 'CLEAR', 'NOMINAL',
               'NORMALE', 'VERT', 'VERTE'),
}
_MEANING_OF = {word: meaning for meaning, words in MEANINGS.items() for word in words}


def request_meaning(request):
    """The status a warning-service request was meant as: ``'WARNING'`` or ``'NORMAL'`` for the sheets'
    words in any case, spacing, quoting or punctuation ("warning", " Normal", "'WARNING'", "WARNING!") and
    for the other words of :data:`MEANINGS` ("RED", "alert", "ok"), else None.

    The drone refuses all but the exact words; the rubric still judges *when* the node called from
    what it meant, so a wrong word costs once (question 13), not every timing item too.
    """
    words = re.findall(r'[A-Z0-9]+', str(request).upper())
    if not words:
        return None
    return _MEANING_OF.get(' '.join(words)) or _MEANING_OF.get(words[0])


def drone_packages():
    """The simulator packages of both sheets."""
    return [sheet.drone_pkg for sheet in SHEETS.values()]


def sheet_of_drone(pkg):
    """The sheet whose drone lives in package ``pkg``, or None."""
    for sheet in SHEETS.values():
        if sheet.drone_pkg == pkg:
            return sheet.name
    return None


def _ros_names(sheet):
    """Patterns of the ROS names only this sheet has: its drone's package and service (a slash before
    or not), its topics (with their slash: "pressure" alone is prose)."""
    names = [r'(?<!\w)' + re.escape(word) for word in (sheet.drone_pkg, sheet.service)]
    return names + [r'(?<![\w/])/' + re.escape(topic) for topic in sheet.inputs + (sheet.output,)]


def sheet_named_in(text):
    """``(sheet, words)``: the sheet a student's text (a report, of a student whose package does not say
    it) is about, when it names that sheet's ROS names (:func:`_ros_names`) at least twice and at least
    twice as often as the other's, else None; ``words`` how many of each it named, for the teacher.
    Only whole names count: ``/pressure`` is not ``/pressure_robot``, prose ("la pression") nothing."""
    counts = collections.OrderedDict(
        (name, sum(len(re.findall(pattern + r'(?![\w/])', text)) for pattern in _ros_names(sheet)))
        for name, sheet in SHEETS.items())
    words = ', '.join('%d of the %s sheet\'s' % (n, name) for name, n in counts.items())
    (first, most), (_, other) = sorted(counts.items(), key=lambda item: -item[1])
    return (first if most >= 2 and most >= 2 * other else None), 'it names %s ROS names' % words


def margin_of(threshold):
    """How far beyond the threshold the probe flies (student units): 10 %, at least 10 m."""
    return max(0.1 * abs(threshold), 10.0)


#: The threshold run's value: the launch file's threshold lowered by this many margins, at random in
#: the range (issue 36 point 7). Its flight (the main run's, around that value) then stays below the
#: launch file's value: the long excursion at most LOWERED_BY[0] - 1 margins below it, the highest
#: check point LOWERED_BY[0] - 2.
LOWERED_BY = (2.5, 4.0)


def threshold_run_value(threshold, draw):
    """The threshold of the threshold run for a launch file's ``threshold`` and a ``draw`` in [0, 1)
    made at grading time (kept in the measurements): the one place it is computed."""
    if not 0.0 <= draw < 1.0:
        raise ValueError('draw %r is not in [0, 1)' % draw)
    low, high = LOWERED_BY
    return round(threshold - (low + (high - low) * draw) * margin_of(threshold), 1)

"""A generator of student answers: complete catkin ``exam`` packages that answer either sheet, written
the ways students write them, and one-mistake variants of them, each with the points the rubric must
give it (issue 35 point 7). Pure Python, no rospy: the packages are text; `make fairness` grades them.

The style axes (:data:`AXES`) are what students vary: where the state lives (globals, a class, a dict),
what drives the computation (a ``rospy.Rate`` loop, a ``rospy.Timer``, the input callbacks), how the
5 s delay is kept (loop ticks, message counts at the drone's rates, timestamps, a one-shot timer), how
the two inputs are held (a cache of the last readings, ``message_filters.ApproximateTimeSynchronizer``
with ``allow_headerless``), how the threshold arrives (private, global parameter, ``args=`` read with
``rospy.myargv``) and one node or two (one computing, one warning). :func:`covering_sample` draws a
pairwise covering sample of them, seeded and deterministic; every drawn style is a correct answer.

Each mistake of :data:`MISTAKES` is one rule of the rubric broken in a correct answer, with the points
the items must get then (one mistake, one loss) or ``FLAGGED`` (the grade needs the teacher's hand).
The drones' rates come from their own packages' simulators (mydrone: temperature 0.778 Hz, pressure
2 Hz; submarinedrone: pressure_robot 2 Hz, pressure_remote 1 Hz).
"""
import collections
import itertools
import os
import random
import re

from exam_lab.grader.score.sheets import DELAY, ITEMS, SHEETS

#: The style axes and their values, in the order a style's name lists them.
AXES = collections.OrderedDict([
    ('sheet', ('altitude', 'depth')),
    ('state', ('globals', 'class', 'dict')),
    ('loop', ('rate', 'timer', 'callback')),
    ('delay', ('ticks', 'counts', 'stamps', 'oneshot')),
    ('inputs', ('cache', 'sync')),
    ('threshold', ('private', 'global', 'args')),
    ('nodes', ('one', 'two')),
])
#: Short words for a style's name (the student's name in the class run).
SHORT = {'altitude': 'alt', 'depth': 'dep', 'globals': 'glob', 'class': 'cls', 'dict': 'dict', 'rate': 'rate',
         'timer': 'timer', 'callback': 'cb', 'ticks': 'ticks', 'counts': 'counts', 'stamps': 'stamps',
         'oneshot': 'oneshot', 'cache': 'cache', 'sync': 'sync', 'private': 'priv', 'global': 'glob',
         'args': 'args', 'one': '1node', 'two': '2nodes'}

#: The drones' publishing rates (Hz), as their simulators publish by default
#: (mydrone/src/mydrone/simulator.py, submarinedrone/src/submarinedrone/simulator.py).
DRONE_RATES = {
    'altitude': collections.OrderedDict([('temperature', 0.778), ('pressure', 2.0)]),
    'depth': collections.OrderedDict([('pressure_robot', 2.0), ('pressure_remote', 1.0)]),
}
#: The input whose messages a "counts" node counts (the fastest: 2 Hz on both drones).
COUNTED = {'altitude': 'pressure', 'depth': 'pressure_robot'}
#: The sheet's drone's service type: (module, class).
SERVICE_TYPES = {'altitude': ('mydrone.srv', 'AltitudeWarning'), 'depth': ('submarinedrone.srv', 'DepthWarning')}
#: The rate the sheet asks of the output (question 11), Hz.
OUTPUT_HZ = 10
#: The synchroniser's slop, s: above half the fastest input's period, so every reading of the slower
#: input finds a partner.
SLOP_S = 0.5

#: The expectation of an answer the grader must send to the teacher (needs a hand grade).
FLAGGED = 'flagged'

Style = collections.namedtuple('Style', list(AXES))
#: One generated answer: its student name, its style, its mistake (None: correct) and what it must get:
#: ``{item: points}`` for the items below their maximum (``{}``: 17/17), or FLAGGED.
Answer = collections.namedtuple('Answer', 'name style mistake expected form', defaults=('plain',))

#: Correct forms of the rules issue 45 added (an answer's ``form``; 'plain' for the others): a launch
#: file opened by its XML declaration, each input awaited once with ``rospy.wait_for_message`` before
#: the node's loop or spin (the drone's first readings). Each is graded as any correct answer: 17/17.
FORMS = collections.OrderedDict([
    ('declared', 'the launch file opened by <?xml version="1.0"?>'),
    ('wait_first', 'rospy.wait_for_message for each input once, before the loop'),
])

#: What one mistake is: the rule it breaks, in words; the points the items must get then (FLAGGED: a
#: hand grade; ``(low, high)``: any points in that range); the sheets it applies to; and what the
#: correct answer it is made from must be.
Mistake = collections.namedtuple('Mistake', 'words expected sheets needs')

_COUNTER = {'delay': ('ticks', 'counts')}
MISTAKES = collections.OrderedDict([
    ('every_cycle', Mistake('the service called every cycle with the current status', {'Q13': 2.0},
                            ('altitude', 'depth'), _COUNTER)),
    ('repeat_warning', Mistake('WARNING called again every cycle while above (NORMAL once)', {'Q13': 2.0},
                               ('altitude', 'depth'), _COUNTER)),
    ('no_kelvin', Mistake('the temperature left in degrees Celsius in equation (1)', {'Q11': 2.5},
                          ('altitude',), {})),
    ('wrong_rho', Mistake('fresh water\'s density (1000) in equation (1)', {'Q11': 2.5}, ('depth',), {})),
    ('no_delay', Mistake('no delay: WARNING at the first value above', {'Q14b': 0.0}, ('altitude', 'depth'),
                         _COUNTER)),
    ('short_delay', Mistake('the delay 5 s less one input period (4.5 s: 9 readings at 2 Hz)', {'Q14b': 1.5},
                            ('altitude', 'depth'), {'delay': ('counts',), 'inputs': ('cache',), 'nodes': ('one',)})),
    # How much of 14b it keeps depends on how long the flight kept it above before the long excursion
    # (the short one, a calibration): it loses the short excursion's point at least, the delay's maybe.
    ('no_reset', Mistake('the counter not reset below the threshold', {'Q14b': (0.0, 1.5)},
                         ('altitude', 'depth'), _COUNTER)),
    ('margin', Mistake('NORMAL only once 5 % below the threshold, not at once', {'Q14b': 2.5},
                       ('altitude', 'depth'), _COUNTER)),
    ('normal_delayed', Mistake('NORMAL also after 5 s below, not at once', {'Q14b': 2.5}, ('altitude', 'depth'),
                               {'delay': ('stamps',)})),
    ('hard_threshold', Mistake('the threshold hard-coded (the launch file\'s parameter never read)',
                               {'Q14a': 0.0}, ('altitude', 'depth'), {'threshold': ('private', 'global')})),
    ('param_name', Mistake('the code reads another parameter name than the launch file gives', {'Q14a': 0.0},
                           ('altitude', 'depth'), {'threshold': ('private', 'global')})),
    ('one_subscriber', Mistake('one subscriber: the temperature taken as a constant 15 degC', {'Q10': 1.0, 'Q11': 2.5},
                               ('altitude',), {'inputs': ('cache',)})),
    ('wrong_topic', Mistake('the output published on another topic name', {'Q11': 2.5}, ('altitude', 'depth'), {})),
    ('slow_rate', Mistake('the output published from the input callbacks only (not 10 Hz)', {'Q11': 3.0},
                          ('altitude', 'depth'), {'loop': ('callback',), 'nodes': ('one',)})),
    ('launch_no_drone', Mistake('the launch file does not start the drone', {'Q12': 0.5}, ('altitude', 'depth'), {})),
    ('launch_no_comment', Mistake('not a single comment in the launch file', {'Q12': 0.5}, ('altitude', 'depth'), {})),
    ('lowercase_request', Mistake('the service called with "warning"/"normal" (the drone refuses them)',
                                  {'Q13': 2.0}, ('altitude', 'depth'), {})),
    ('never_warns', Mistake('one misplaced word: the WARNING call can never run', FLAGGED, ('altitude', 'depth'),
                            _COUNTER)),
    # Issue 45: one mistake, one loss, on launch files roslaunch refuses, a slow loop, a silent output.
    ('launch_no_root', Mistake('the launch file\'s elements without their <launch> root (roslaunch refuses it)',
                               {'Q12': 0.0}, ('altitude', 'depth'), {})),
    ('node_no_name', Mistake('the exam node\'s <node> without its name (ROS 2\'s habit; roslaunch refuses it)',
                             {'Q12': 0.0}, ('altitude', 'depth'), {})),
    ('slow_loop', Mistake('rospy.wait_for_message for each input in the loop: a value about once a second',
                          {'Q11': 3.0}, ('altitude', 'depth'),
                          {'loop': ('rate',), 'nodes': ('one',), 'inputs': ('cache',), 'delay': ('stamps',)})),
    ('silent_output', Mistake('the value computed and the LED set, but never published', {'Q11': 1.5},
                              ('altitude', 'depth'), {'nodes': ('one',), 'loop': ('rate', 'timer')})),
    ('positional_queue', Mistake('rospy.Publisher(topic, Float32, 10): the queue size given as the third '
                                 'argument, subscriber_listener (nothing is received)', {'Q11': 1.5},
                                 ('altitude', 'depth'), {'nodes': ('one',)})),
])
#: Mistakes whose grade is flagged (a hand grade) and must still give the points it says: the output
#: silent while the code publishes, the calls judged against the judge's own value (issue 45).
JUDGED_WHEN_FLAGGED = ('positional_queue',)


def valid(style):
    """Whether a style is an answer a student can write: loop ticks need a loop."""
    return not (style.loop == 'callback' and style.delay == 'ticks')


def style_name(style):
    return '-'.join(SHORT[getattr(style, axis)] for axis in AXES)


def _pairs(style):
    values = list(style)
    return set((i, values[i], j, values[j]) for i, j in itertools.combinations(range(len(values)), 2))


def _all_valid():
    return [s for s in (Style(*values) for values in itertools.product(*AXES.values())) if valid(s)]


def covering_sample(count, seed=0):
    """``count`` (at least the covering's size) distinct valid styles that together hold every pair of
    values of two axes that some valid style holds: greedy, each step the style covering most pairs
    not yet held (ties broken by a seeded shuffle); then seeded draws of styles not yet taken."""
    rng = random.Random(seed)
    pool = _all_valid()
    rng.shuffle(pool)
    uncovered = set().union(*(_pairs(s) for s in pool))
    chosen = []
    while uncovered:
        best = max(pool, key=lambda s: len(_pairs(s) & uncovered))
        chosen.append(best)
        pool.remove(best)
        uncovered -= _pairs(best)
    rest = pool[:]
    rng.shuffle(rest)
    chosen.extend(rest[:max(0, count - len(chosen))])
    return chosen


def _fits(style, mistake):
    spec = MISTAKES[mistake]
    return style.sheet in spec.sheets and all(getattr(style, axis) in values for axis, values in spec.needs.items())


#: The sheet's own answer (its grader's notes: global variables, a ``rospy.Rate(10)`` loop counting
#: cycles, the cached readings, ``<param name="threshold">`` at the top of the launch file, one node).
REFERENCE = {'state': 'globals', 'loop': 'rate', 'delay': 'ticks', 'inputs': 'cache', 'threshold': 'global',
             'nodes': 'one'}


def reference_style(sheet, mistake):
    """The sheet's own answer, changed only where the mistake needs another style (the first value it
    allows), and then, if that makes no answer (loop ticks without a loop), in its delay."""
    values = dict(REFERENCE, sheet=sheet)
    for axis, allowed in MISTAKES[mistake].needs.items():
        if values[axis] not in allowed:
            values[axis] = allowed[0]
    style = Style(**values)
    for delay in AXES['delay']:
        if valid(style) and _fits(style, mistake):
            return style
        style = style._replace(delay=delay)
    return style


def answers(correct=40, seed=0):
    """The matrix: ``correct`` correct answers (a pairwise covering sample, both sheets), the sheet's own
    answer of each sheet (:data:`REFERENCE`) unless the sample holds it, and two answers per mistake
    of :data:`MISTAKES`: one made from the sheet's own answer
    (:func:`reference_style`), one from a correct answer of the sample that fits the mistake, drawn
    (seeded), on the other sheet where the mistake allows. Deterministic for a seed."""
    styles = covering_sample(correct, seed)
    out = [Answer('c%02d-%s' % (n + 1, style_name(s)), s, None, {}) for n, s in enumerate(styles)]
    # the sheet's own answer of each sheet, correct, so its variants' other losses can be read
    references = [s for s in (Style(**dict(REFERENCE, sheet=sheet)) for sheet in SHEETS) if s not in styles]
    out += [Answer('r%02d-%s' % (n + 1, style_name(s)), s, None, {}) for n, s in enumerate(references)]
    # each correct form of issue 45's rules, on the sheet's own answer of each sheet
    forms = [(form, Style(**dict(REFERENCE, sheet=sheet))) for form in FORMS for sheet in SHEETS]
    out += [Answer('v%02d-%s-%s' % (n + 1, form.replace('_', ''), style_name(s)), s, None, {}, form)
            for n, (form, s) in enumerate(forms)]
    rng = random.Random(seed + 1)
    pool = _all_valid()
    made = []
    for n, mistake in enumerate(MISTAKES):
        spec = MISTAKES[mistake]
        sheet = spec.sheets[n % len(spec.sheets)]
        made.append((mistake, reference_style(sheet, mistake)))
        other = spec.sheets[(n + 1) % len(spec.sheets)]
        # the variant of a correct answer graded in the same run, where one fits
        fitting = [s for s in styles if s.sheet == other and _fits(s, mistake) and s != made[-1][1]] or \
            [s for s in pool if s.sheet == other and _fits(s, mistake) and s != made[-1][1]]
        made.append((mistake, rng.choice(fitting)))
    for n, (mistake, base) in enumerate(made):
        out.append(Answer('m%02d-%s-%s' % (n + 1, mistake.replace('_', ''), style_name(base)), base, mistake,
                          MISTAKES[mistake].expected))
    return out


def sample(count=10, seed=0, correct_share=0.5):
    """``count`` answers drawn from the matrix (seeded): about ``correct_share`` correct, the rest
    one-mistake (each mistake once), each kind taken from both sheets in turn."""
    everything = answers(seed=seed)
    rng = random.Random(seed + 2)
    n_right = int(round(count * correct_share))
    drawn = []
    for wanted, mistaken in ((n_right, False), (count - n_right, True)):
        by_sheet = [[a for a in everything if (a.mistake is not None) == mistaken and a.style.sheet == sheet]
                    for sheet in SHEETS]
        for answers_of_sheet in by_sheet:
            rng.shuffle(answers_of_sheet)
        turns = itertools.chain.from_iterable(zip(*by_sheet))
        taken, mistakes = [], set()
        for answer in turns:  # each mistake once: as many rules as the count allows
            if len(taken) == wanted:
                break
            if answer.mistake is None or answer.mistake not in mistakes:
                taken.append(answer)
                mistakes.add(answer.mistake)
        drawn += taken
    return sorted(drawn, key=lambda a: a.name)


# --- judging a grade against what the answer must get ---------------------------------------------

GRADED = 'graded'
HAND_GRADE = 'needs a hand grade'


def wanted_points(answer):
    """``{item: points}`` the answer must get (every item), or None when it must be flagged."""
    if answer.expected == FLAGGED:
        return None
    points = collections.OrderedDict((item, maximum) for item, (maximum, _) in ITEMS.items())
    points.update(answer.expected)
    return points


def verdict(answer, record):
    """``(fair, how)``: whether the grade ``record`` (the runner's: items, status) is what the answer
    must get, and, when not, how it differs, one line.

    A correct answer must get every point, status "graded". A one-mistake answer must lose its rule's
    points only, or be flagged ("needs a hand grade"); one whose expectation is FLAGGED must be flagged.
    """
    got = collections.OrderedDict((i['id'], i['points']) for i in record.get('items', []))
    status = record.get('status')
    wanted = wanted_points(answer)
    if answer.mistake is not None and status == HAND_GRADE and answer.mistake not in JUDGED_WHEN_FLAGGED:
        return True, 'flagged: %s' % record.get('status_reason', '')
    if wanted is None:
        return False, 'not flagged (%s), %s' % (status, _points_words(got))
    diff = ['%s %g/%g (wanted %s)' % (item, got.get(item, 0.0), ITEMS[item][0], points_words(points))
            for item, points in wanted.items() if not _within(got.get(item), points)]
    if answer.mistake is None and status != GRADED:
        diff.append('status "%s": %s' % (status, record.get('status_reason', '')))
    elif status not in (GRADED, 'graded with fixes', HAND_GRADE if answer.mistake in JUDGED_WHEN_FLAGGED else GRADED):
        diff.append('status "%s": %s' % (status, record.get('status_reason', '')))
    return (not diff), '; '.join(diff) if diff else 'as wanted'


def _within(got, points):
    if isinstance(points, tuple):
        return got is not None and points[0] <= got <= points[1]
    return got == points


def points_words(points):
    """``1.5``, or ``0-1.5`` for a range."""
    return '%g-%g' % points if isinstance(points, tuple) else '%g' % points


def _points_words(got):
    return ', '.join('%s %g' % (item, points) for item, points in got.items())


# --- writing a package -------------------------------------------------------------------------------

_STATE_REF = re.compile(r'@(\w+)')
_FN_REF = re.compile(r'&(\w+)')
_ASSIGNED = re.compile(r'@(\w+)\s*(?:[-+*/]?=)(?!=)')

#: A function of a node: its name, parameters (no self), docstring and body (lines, 4-space relative
#: indents, ``@name`` for the node's state, ``&name`` for its functions).
Fn = collections.namedtuple('Fn', 'name params doc body')


class Node(object):
    """One node's program before it takes a state style: imports, constants, pure helpers, its state
    (name -> initial value), its functions, the setup run after ``init_node`` and the lines that keep
    it running."""

    def __init__(self, name, doc):
        self.name, self.doc = name, doc
        self.imports, self.constants, self.helpers = [], [], []
        self.state = collections.OrderedDict()
        self.functions, self.setup, self.run = [], [], []

    def var(self, name, initial, comment):
        self.state[name] = (initial, comment)

    def fn(self, name, params, doc, body):
        self.functions.append(Fn(name, params, doc, body))


def _indent(lines, n):
    return ['%s%s' % (' ' * n, line) if line else '' for line in lines]


def _sub(line, state_style):
    if state_style == 'class':
        line = _STATE_REF.sub(r'self.\1', line)
        return _FN_REF.sub(r'self.\1', line)
    if state_style == 'dict':
        line = _STATE_REF.sub(lambda m: "state['%s']" % m.group(1), line)
    else:
        line = _STATE_REF.sub(r'\1', line)
    return _FN_REF.sub(r'\1', line)


def _globals_of(lines):
    names = []
    for line in lines:
        for name in _ASSIGNED.findall(line):
            if name not in names:
                names.append(name)
    return names


def render(node, state_style):
    """The node's script in one state style: module globals, attributes of a class, or a dict."""
    out = ['#!/usr/bin/env python3', '# -*- coding: utf-8 -*-', '"""%s"""' % node.doc, '']
    out += node.imports + [''] + node.constants + ['']
    if state_style == 'globals':
        out.append('# The node\'s state, shared by the callbacks (module globals)')
        out += ['%s = %s  # %s' % (name, init, comment) for name, (init, comment) in node.state.items()]
        out.append('')
    elif state_style == 'dict':
        out.append('# The node\'s state, shared by the callbacks, in one dictionary')
        out.append('state = {')
        out += ["    '%s': %s,  # %s" % (name, init, comment) for name, (init, comment) in node.state.items()]
        out += ['}', '']
    out += node.helpers
    if state_style == 'class':
        out += ['', '', 'class ExamNode(object):', '    """The node: its state and its callbacks."""', '',
                '    def __init__(self):']
        out += ['        self.%s = %s  # %s' % (name, init, comment) for name, (init, comment) in node.state.items()]
        out += _indent([_sub(l, 'class') for l in node.setup], 8)
        for fn in node.functions + [Fn('spin', '', 'Keep the node running until shutdown.', node.run)]:
            out += ['', '    def %s(self%s):' % (fn.name, ', ' + fn.params if fn.params else ''),
                    '        """%s"""' % fn.doc]
            out += _indent([_sub(l, 'class') for l in fn.body], 8)
        out += ['', '', 'def main():', '    rospy.init_node(%r)  # the node, named as in the launch file' % node.name,
                '    node = ExamNode()', '    node.spin()']
    else:
        for fn in node.functions:
            out += ['', '', 'def %s(%s):' % (fn.name, fn.params), '    """%s"""' % fn.doc]
            assigned = _globals_of(fn.body) if state_style == 'globals' else []
            if assigned:
                out.append('    global %s' % ', '.join(assigned))
            out += _indent([_sub(l, state_style) for l in fn.body], 4)
        out += ['', '', 'def main():', '    """Start the node and keep it running."""']
        assigned = _globals_of(node.setup) if state_style == 'globals' else []
        if assigned:
            out.append('    global %s' % ', '.join(assigned))
        out.append('    rospy.init_node(%r)  # the node, named as in the launch file' % node.name)
        out += _indent([_sub(l, state_style) for l in node.setup + node.run], 4)
    out += ['', '', "if __name__ == '__main__':", '    try:', '        main()',
            '    except rospy.ROSInterruptException:', '        pass', '']
    return '\n'.join(out)


def _sheet_words(sheet):
    s = SHEETS[sheet]
    a, b = s.inputs
    return s, a, b


def _formula(node, sheet, mistake):
    if sheet == 'altitude':
        node.imports.append('import math  # the logarithm of equation (1)')
        node.constants += ['# Constants of equation (1)', 'P0 = 101325.0    # pressure at sea level (Pa)',
                           'MU = 0.0289644   # mean molecular mass of air (kg/mol)', 'G = 9.80665      # gravity (m/s^2)',
                           'R = 8.31432      # perfect gas constant (J/K.mol)']
        kelvin = 'temperature_c' if mistake == 'no_kelvin' else 'temperature_c + 273.15'
        node.helpers += ['', '', 'def compute(temperature_c, pressure_pa):',
                         '    """Equation (1) solved for the altitude (m): h = R*T/(mu*g) * ln(P0/P), T in K."""',
                         '    temperature_k = %s  # the temperature in Kelvin' % kelvin,
                         '    return R * temperature_k / (MU * G) * math.log(P0 / pressure_pa)']
    else:
        rho = '1000.0' if mistake == 'wrong_rho' else '1030.0'
        node.constants += ['# Constants of equation (1)', 'RHO = %s  # density of salt water (kg/m^3)' % rho,
                           'G = 9.80665  # gravity (N/kg)']
        node.helpers += ['', '', 'def compute(p_robot, p_remote):',
                         '    """Equation (1): the depth (m) from the two pressures (Pa)."""',
                         '    return (p_robot - p_remote) / (RHO * G)']


def _threshold_lines(style, sheet, mistake):
    default = SHEETS[sheet].threshold
    if mistake == 'hard_threshold':
        return ['@threshold = %.1f  # the limit (m)' % default]
    if style.threshold == 'args':
        return ['# the threshold is given as the node\'s argument in the launch file (args=)',
                'argv = rospy.myargv(argv=sys.argv)',
                '@threshold = float(argv[1]) if len(argv) > 1 else %.1f' % default]
    name = 'limit' if mistake == 'param_name' else 'threshold'
    name = ('~' if style.threshold == 'private' else '/') + name
    return ['# the threshold comes from the launch file (%.0f m when it gives none)' % default,
            '@threshold = float(rospy.get_param(%r, %.1f))' % (name, default)]


def _service_lines(sheet):
    s = SHEETS[sheet]
    module, klass = SERVICE_TYPES[sheet]
    return ['rospy.wait_for_service(%r)  # the drone\'s service must be up' % ('/' + s.service),
            '@led = rospy.ServiceProxy(%r, %s)  # the LED of the remote' % ('/' + s.service, klass)]


def _counter_n(style, sheet, mistake):
    """How many counts above make the 5 s delay, and what is counted (words)."""
    if style.delay == 'ticks' or style.nodes == 'two':
        n, what = int(round(DELAY * OUTPUT_HZ)), 'cycles of the %d Hz loop' % OUTPUT_HZ if style.delay == 'ticks' \
            else 'values of the %d Hz output' % OUTPUT_HZ
    elif style.inputs == 'sync':
        hz = min(DRONE_RATES[sheet].values())
        n, what = int(round(DELAY * hz)), 'synchronised pairs (%.3g Hz, the slower input)' % hz
    else:
        hz = DRONE_RATES[sheet][COUNTED[sheet]]
        n, what = int(round(DELAY * hz)), 'readings of /%s (%g Hz)' % (COUNTED[sheet], hz)
    if mistake == 'short_delay':
        n -= 1
    if mistake == 'no_delay':
        n = 0
    return n, what


def _led_call(status, mistake):
    if mistake == 'lowercase_request':
        status = status.lower()
    return '&set_led(%r)' % status


def _logic(node, style, sheet, mistake):
    """The warning logic: ``check(value)`` called at each new value, in the style's delay."""
    node.var('warning', 'False', 'True while the LED is red')
    node.fn('set_led', 'status', 'Call the warning service and remember the LED\'s colour.', [
        'try:',
        '    @led(status)  # change the colour of the LED',
        'except rospy.ServiceException as err:',
        '    rospy.logwarn(\'the warning service failed: %s\', err)',
        '    return',
        "@warning = status.upper() == 'WARNING'",
        "rospy.loginfo('LED: %s', status)"])
    margin = ' - 0.05 * abs(@threshold)' if mistake == 'margin' else ''
    if style.delay in ('ticks', 'counts'):
        n, what = _counter_n(style, sheet, mistake)
        node.var('count', '0', 'how many %s the value has been above' % what)
        body = ['if value > @threshold:', '    @count += 1  # one more above']
        if mistake != 'no_reset':
            body += ['else:', '    @count = 0  # below: start again']
        above = '@count > %d' % n
        if mistake == 'every_cycle':
            body += ['# %d %s = %g s' % (n, what, DELAY),
                     'if %s:' % above, '    %s' % _led_call('WARNING', mistake),
                     'else:', '    %s' % _led_call('NORMAL', mistake)]
        else:
            warned = '' if mistake == 'repeat_warning' else (' and @warning' if mistake == 'never_warns'
                                                             else ' and not @warning')
            body += ['# more than %d %s: above for more than %g s' % (n, what, DELAY),
                     'if %s%s:' % (above, warned), '    %s' % _led_call('WARNING', mistake),
                     'elif value <= @threshold%s and @warning:' % margin,
                     '    %s  # back below: green at once' % _led_call('NORMAL', mistake)]
    elif style.delay == 'stamps':
        node.var('above_since', 'None', 'when the value went above the threshold (s), None below')
        body = ['now = rospy.get_time()', 'if value > @threshold:', '    if @above_since is None:',
                '        @above_since = now  # it just went above']
        if mistake == 'normal_delayed':
            node.var('below_since', 'None', 'when the value went back below (s)')
            body = ['now = rospy.get_time()', 'if value > @threshold:', '    @below_since = None',
                    '    if @above_since is None:', '        @above_since = now  # it just went above']
        body += ['    if now - @above_since >= DELAY and not @warning:', '        %s' % _led_call('WARNING', mistake),
                 'else:', '    @above_since = None  # below: start again']
        if mistake == 'normal_delayed':
            body += ['    if @below_since is None:', '        @below_since = now',
                     '    if now - @below_since >= DELAY and @warning:', '        %s' % _led_call('NORMAL', mistake)]
        else:
            body += ['    if @warning:', '        %s  # back below: green at once' % _led_call('NORMAL', mistake)]
    else:
        node.var('delay_timer', 'None', 'the one-shot timer of the delay, None when not running')
        body = ['if value > @threshold:', '    if @delay_timer is None and not @warning:',
                '        # WARNING only if still above when the timer ends',
                '        @delay_timer = rospy.Timer(rospy.Duration(DELAY), &on_delay_over, oneshot=True)',
                'else:', '    if @delay_timer is not None:', '        @delay_timer.shutdown()  # below: no WARNING',
                '        @delay_timer = None', '    if @warning:',
                '        %s  # back below: green at once' % _led_call('NORMAL', mistake)]
        node.fn('on_delay_over', 'event', 'The value stayed above for the whole delay: WARNING.', [
            'if @delay_timer is not None and not @warning:', '    @delay_timer = None',
            '    %s' % _led_call('WARNING', mistake)])
    if style.delay in ('stamps', 'oneshot'):
        node.constants.append('DELAY = %.1f  # s above the threshold before the WARNING' % DELAY)
    node.fn('check', 'value', 'Decide the LED\'s colour from a new value, calling the service only on a change.',
            body)


def _output_topic(sheet, mistake):
    if mistake == 'wrong_topic':
        return {'altitude': '/height', 'depth': '/profondeur'}[sheet]
    return '/' + SHEETS[sheet].output


def _inputs(node, style, sheet, mistake, on_new):
    """Subscribers that keep the last readings; ``on_new(which)`` gives the lines each callback runs
    after storing (``which``: the input's name, or 'pair' for the synchroniser)."""
    _, a, b = _sheet_words(sheet)
    node.var('last_%s' % a, '15.0' if mistake == 'one_subscriber' and a == 'temperature' else 'None',
             'the last %s received' % a + (' (no sensor: 15 degC)' if mistake == 'one_subscriber' else ''))
    node.var('last_%s' % b, 'None', 'the last %s received' % b)
    if style.inputs == 'sync':
        node.imports.append('import message_filters  # to receive both inputs together')
        node.fn('on_readings', 'msg_%s, msg_%s' % (a, b), 'A reading of each input, received together.', [
            '@last_%s = msg_%s.data' % (a, a), '@last_%s = msg_%s.data' % (b, b)] + on_new('pair'))
        node.setup += ['# both inputs, synchronised on their arrival (Float32 has no header)',
                       "sub_%s = message_filters.Subscriber('/%s', Float32)" % (a, a),
                       "sub_%s = message_filters.Subscriber('/%s', Float32)" % (b, b),
                       '@sync = message_filters.ApproximateTimeSynchronizer([sub_%s, sub_%s], queue_size=10, '
                       'slop=%g, allow_headerless=True)' % (a, b, SLOP_S),
                       '@sync.registerCallback(&on_readings)']
        node.var('sync', 'None', 'the synchroniser of the two inputs')
        return
    for topic in (a, b):
        if (mistake == 'one_subscriber' and topic == 'temperature') or mistake == 'slow_loop':
            continue
        node.fn('on_%s' % topic, 'msg', 'A new reading of /%s: keep it.' % topic,
                ['@last_%s = msg.data' % topic] + on_new(topic))
        node.setup.append("rospy.Subscriber('/%s', Float32, &on_%s)  # the drone's %s" % (topic, topic, topic))


def _value_lines(sheet):
    _, a, b = _sheet_words(sheet)
    return ['if @last_%s is None or @last_%s is None:' % (a, b), '    return None  # not both readings yet',
            'return compute(@last_%s, @last_%s)' % (a, b)]


def _common_imports(node, sheet, with_service):
    node.imports += ['import rospy  # the ROS python client', 'from std_msgs.msg import Float32  # the topics\' type']
    if with_service:
        module, klass = SERVICE_TYPES[sheet]
        node.imports.append('from %s import %s  # the drone\'s warning service' % (module, klass))


def _driver(node, style, step_lines, with_publish_timer=False):
    """What runs ``step``: a Rate loop, a Timer, or (callback style) nothing but spin."""
    if style.loop == 'rate':
        node.fn('step', '', 'One cycle of the %d Hz loop.' % OUTPUT_HZ, step_lines)
        node.run += ['rate = rospy.Rate(%d)  # %d Hz' % (OUTPUT_HZ, OUTPUT_HZ), 'while not rospy.is_shutdown():',
                     '    &step()', '    rate.sleep()  # wait for the next cycle']
    elif style.loop == 'timer':
        node.fn('step', 'event', 'One tick of the %d Hz timer.' % OUTPUT_HZ, step_lines)
        node.var('timer', 'None', 'the %d Hz timer' % OUTPUT_HZ)
        node.setup.append('@timer = rospy.Timer(rospy.Duration(1.0 / %d), &step)  # %d Hz' % (OUTPUT_HZ, OUTPUT_HZ))
        node.run.append('rospy.spin()  # the callbacks do the work')
    else:
        if with_publish_timer:
            node.fn('publish', 'event', 'Publish the last value at %d Hz.' % OUTPUT_HZ,
                    ['if @value is not None:', '    @pub.publish(@value)'])
            node.var('timer', 'None', 'the %d Hz publishing timer' % OUTPUT_HZ)
            node.setup.append('@timer = rospy.Timer(rospy.Duration(1.0 / %d), &publish)  # %d Hz'
                              % (OUTPUT_HZ, OUTPUT_HZ))
        node.run.append('rospy.spin()  # the callbacks do the work')


def _slowest_first(sheet):
    """The sheet's two inputs, the slower first (the order a node that waits for each reading in turn
    follows its inputs soonest in)."""
    rates = DRONE_RATES[sheet]
    return sorted(rates, key=lambda topic: rates[topic])


def _waits(sheet, keep):
    """``rospy.wait_for_message`` for each input, the slower first; ``keep``: store each reading."""
    return ['%srospy.wait_for_message(\'/%s\', Float32)%s  # a new reading of /%s' % (
        '@last_%s = ' % topic if keep else '', topic, '.data' if keep else '', topic) for topic in _slowest_first(sheet)]


def exam_node(style, mistake=None, form='plain'):
    """The script of the node that computes (and, with one node, warns)."""
    sheet = style.sheet
    two = style.nodes == 'two'
    node = Node('exam', 'exam_node: the %s of the %s from its sensors, published on %s at %d Hz%s.' % (
        SHEETS[sheet].output, SHEETS[sheet].drone_pkg, _output_topic(sheet, mistake), OUTPUT_HZ,
        '' if two else '; the LED through %s after %g s beyond the threshold' % (SHEETS[sheet].service, DELAY)))
    _common_imports(node, sheet, not two)
    if style.threshold == 'args' and not two:
        node.imports.insert(0, 'import sys  # the node\'s arguments')
    _formula(node, sheet, mistake)
    node.var('pub', 'None', 'the publisher of the %s' % SHEETS[sheet].output)
    node.var('value', 'None', 'the last %s computed (m)' % SHEETS[sheet].output)
    if not two:
        node.var('threshold', 'None', 'the limit (m)')
        node.var('led', 'None', 'the warning service')
        node.setup += _threshold_lines(style, sheet, mistake) + _service_lines(sheet)
        _logic(node, style, sheet, mistake)
    queue = '10' if mistake == 'positional_queue' else 'queue_size=10'
    node.setup.insert(0, '@pub = rospy.Publisher(%r, Float32, %s)  # the output' % (_output_topic(sheet, mistake), queue))
    node.fn('compute_value', '', 'The %s from the last readings, None before both arrived.' % SHEETS[sheet].output,
            _value_lines(sheet))
    counted = COUNTED[sheet]
    logic_in_callback = not two and (style.loop == 'callback' or style.delay == 'counts')

    def on_new(which):
        lines = []
        if style.loop == 'callback':
            lines += ['@value = &compute_value()  # a new value at each reading']
            if mistake == 'slow_rate':
                lines += ['if @value is not None:', '    @pub.publish(@value)  # publish the new value']
        if logic_in_callback and (style.delay != 'counts' or which in (counted, 'pair')):
            lines += ['value = &compute_value()', 'if value is not None:', '    &check(value)']
        return lines

    _inputs(node, style, sheet, mistake, on_new)
    if form == 'wait_first':
        node.setup += ['# wait for the drone: a first reading of each input'] + _waits(sheet, keep=False)
    step = (_waits(sheet, keep=True) if mistake == 'slow_loop' else []) + [
        '@value = &compute_value()', 'if @value is None:', '    return'] + (
        [] if mistake == 'silent_output' else ['@pub.publish(@value)  # the output'])
    if not two and not logic_in_callback:
        step.append('&check(@value)')
    _driver(node, style, step, with_publish_timer=mistake != 'slow_rate')
    return render(node, style.state)


def warning_node(style, mistake=None):
    """The second node of a two-node answer: the warning from the first one's output."""
    sheet = style.sheet
    out = _output_topic(sheet, mistake)
    node = Node('exam_warning', 'warning_node: the %s LED from %s, after %g s beyond the threshold.' % (
        SHEETS[sheet].service, out, DELAY))
    _common_imports(node, sheet, True)
    if style.threshold == 'args':
        node.imports.insert(0, 'import sys  # the node\'s arguments')
    node.var('threshold', 'None', 'the limit (m)')
    node.var('led', 'None', 'the warning service')
    node.var('value', 'None', 'the last value of %s' % out)
    node.setup += _threshold_lines(style, sheet, mistake) + _service_lines(sheet)
    _logic(node, style, sheet, mistake)
    in_callback = style.loop == 'callback' or style.delay == 'counts'
    node.fn('on_value', 'msg', 'A new value of %s.' % out,
            ['@value = msg.data'] + (['&check(@value)'] if in_callback else []))
    node.setup.append('rospy.Subscriber(%r, Float32, &on_value)  # the exam node\'s output' % out)
    if not in_callback:
        _driver(node, style, ['if @value is not None:', '    &check(@value)'])
    else:
        node.run.append('rospy.spin()  # the callbacks do the work')
    return render(node, style.state)


def launch_file(style, mistake=None, form='plain'):
    s = SHEETS[style.sheet]
    comment = (lambda text: []) if mistake == 'launch_no_comment' else (lambda text: ['  <!-- %s -->' % text])
    value = '%g' % s.threshold
    lines = ['<?xml version="1.0"?>'] if form == 'declared' else []
    lines += [] if mistake == 'launch_no_root' else ['<launch>']
    warner = 'warning_node.py' if style.nodes == 'two' else 'exam_node.py'
    if style.threshold == 'global':
        lines += comment('the %s threshold (m) of the warning' % s.output) + [
            '  <param name="threshold" value="%s" />' % value]
    if style.threshold == 'args':
        lines += comment('the threshold (m), handed to the node as its argument') + [
            '  <arg name="threshold" default="%s" />' % value]
    if mistake != 'launch_no_drone':
        lines += comment('the drone') + ['  <node pkg="%s" type="%s" name="%s" />' % (
            s.drone_pkg, s.drone_type, 'mydrone' if style.sheet == 'altitude' else 'submarine_drone')]
    nodes = [('exam_node.py', 'exam')] + ([('warning_node.py', 'exam_warning')] if style.nodes == 'two' else [])
    for script, name in nodes:
        args = ' args="$(arg threshold)"' if style.threshold == 'args' and script == warner else ''
        lines += comment('the %s node' % ('exam' if script == 'exam_node.py' else 'warning'))
        if style.threshold == 'private' and script == warner:
            lines += ['  <node pkg="exam" type="%s" name="%s" output="screen"%s>' % (script, name, args),
                      '    <param name="threshold" value="%s" />' % value, '  </node>']
        else:
            lines.append('  <node pkg="exam" type="%s" name="%s" output="screen"%s />' % (script, name, args))
        if mistake == 'node_no_name' and script == 'exam_node.py':
            lines[-1 if lines[-1].endswith('/>') else -3] = lines[-1 if lines[-1].endswith('/>') else -3].replace(
                ' name="%s"' % name, '')
    lines += [] if mistake == 'launch_no_root' else ['</launch>']
    return '\n'.join(lines) + '\n'


PACKAGE_XML = '''<?xml version="1.0"?>
<package format="2">
  <name>exam</name>
  <version>0.0.0</version>
  <description>The exam package</description>
  <maintainer email="student@todo.todo">student</maintainer>
  <license>TODO</license>
  <buildtool_depend>catkin</buildtool_depend>
{deps}
</package>
'''

CMAKE = '''cmake_minimum_required(VERSION 3.0.2)
project(exam)

## Find catkin macros and libraries
find_package(catkin REQUIRED COMPONENTS
{components}
)

catkin_package()

## Mark executable scripts (Python etc.) for installation
catkin_install_python(PROGRAMS {scripts}
  DESTINATION ${{CATKIN_PACKAGE_BIN_DESTINATION}}
)
'''


def package_files(style, mistake=None, form='plain'):
    """``{relative path: text}`` of the answer's package (its root is the folder ``exam``), in its
    ``form`` (:data:`FORMS`)."""
    deps = [SHEETS[style.sheet].drone_pkg, 'rospy', 'std_msgs'] + (['message_filters'] if style.inputs == 'sync' else [])
    scripts = ['scripts/exam_node.py'] + (['scripts/warning_node.py'] if style.nodes == 'two' else [])
    files = collections.OrderedDict()
    files['package.xml'] = PACKAGE_XML.format(deps='\n'.join(
        '  <%s>%s</%s>' % (kind, dep, kind) for kind in ('build_depend', 'build_export_depend', 'exec_depend')
        for dep in deps))
    files['CMakeLists.txt'] = CMAKE.format(components='\n'.join('  %s' % d for d in deps), scripts=' '.join(scripts))
    files['launch/exam.launch'] = launch_file(style, mistake, form)
    files['scripts/exam_node.py'] = exam_node(style, mistake, form)
    if style.nodes == 'two':
        files['scripts/warning_node.py'] = warning_node(style, mistake)
    return files


def write_package(answer, folder):
    """Write the answer's package into ``folder/exam``; return that path."""
    root = os.path.join(folder, 'exam')
    for rel, text in package_files(answer.style, answer.mistake, answer.form).items():
        path = os.path.join(root, rel)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, 'w') as f:
            f.write(text)
        if rel.startswith('scripts/'):
            os.chmod(path, 0o755)
    return root


def write_class(answers_, klass):
    """Each answer as a student of a Moodle class download (``<name>_<n>_assignsubmission_file_/exam``)."""
    for n, answer in enumerate(answers_):
        write_package(answer, os.path.join(klass, '%s_%d_assignsubmission_file_' % (answer.name, 1000 + n)))
    return klass

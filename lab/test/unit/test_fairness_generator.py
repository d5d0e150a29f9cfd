"""The generator of student answers (issue 35 point 7): its pairwise covering sample, its matrix, and
each generated package flown without ROS: a simulated clock and a stand-in for rospy,
message_filters and the drone run the package's own scripts with its own launch file's parameters, so
every correct answer is shown to publish equation (1) at 10 Hz and warn after 5 s beyond, NORMAL at once,
and every one-mistake answer to make exactly its mistake. No master, no grader: about a second each.
"""
import collections
import heapq
import itertools
import math
import re
import sys
import threading
import types
import xml.etree.ElementTree as ET

import pytest

from exam_lab.fairness import generator
from exam_lab.grader.score.sheets import ITEMS, SHEETS

ANSWERS = generator.answers()


# --- the sample and the matrix ------------------------------------------------------------------

def test_the_sample_covers_every_pair_of_style_values_some_answer_can_hold():
    sample = generator.covering_sample(40)
    axes = list(generator.AXES)
    every = [generator.Style(*v) for v in itertools.product(*generator.AXES.values())]
    for (i, a), (j, b) in itertools.combinations(enumerate(axes), 2):
        for x, y in itertools.product(generator.AXES[a], generator.AXES[b]):
            possible = any(s[i] == x and s[j] == y and generator.valid(s) for s in every)
            held = any(s[i] == x and s[j] == y for s in sample)
            assert held == possible, (a, x, b, y)
    assert len(sample) == len(set(sample)) == 40
    assert all(generator.valid(s) for s in sample)


def test_the_sample_is_seeded_and_deterministic():
    assert generator.covering_sample(40, 3) == generator.covering_sample(40, 3)
    assert generator.covering_sample(40, 3) != generator.covering_sample(40, 4)
    assert generator.answers(40, 1) == generator.answers(40, 1)
    assert generator.sample(10, 0) == generator.sample(10, 0)


def test_the_matrix_holds_enough_answers_of_both_sheets():
    right = [a for a in ANSWERS if a.mistake is None]
    wrong = [a for a in ANSWERS if a.mistake is not None]
    assert len(right) >= 40 and len(wrong) >= 15
    assert set(a.style.sheet for a in right) == set(a.style.sheet for a in wrong) == set(SHEETS)
    assert len(set(a.name for a in ANSWERS)) == len(ANSWERS)
    assert [a.mistake for a in wrong] == [m for m in generator.MISTAKES for _ in range(2)]
    # one of each pair is the sheet's own answer (as close as the mistake allows), the other drawn
    assert all(generator.reference_style(a.style.sheet, a.mistake) == a.style for a in wrong[::2])
    assert [a.style for a in wrong[::2]] != [a.style for a in wrong[1::2]]
    for answer in wrong:
        assert generator._fits(answer.style, answer.mistake), answer.name
        if answer.expected != generator.FLAGGED:
            assert answer.expected and all(0 <= min(p if isinstance(p, tuple) else (p,)) <=
                                           max(p if isinstance(p, tuple) else (p,)) < ITEMS[i][0]
                                           for i, p in answer.expected.items()), answer.name
    drawn = generator.sample(10)
    mistakes = [a.mistake for a in drawn if a.mistake]
    assert len(drawn) == 10 and len(mistakes) == 5 and len(set(mistakes)) == 5
    assert set(a.style.sheet for a in drawn if a.mistake) == set(a.style.sheet for a in drawn if not a.mistake) \
        == set(SHEETS)


def _record(points, status='graded'):
    return {'items': [{'id': i, 'points': points.get(i, m)} for i, (m, _) in ITEMS.items()], 'status': status,
            'status_reason': 'why'}


def test_the_verdict_holds_a_grade_to_what_the_answer_must_get():
    right = next(a for a in ANSWERS if a.mistake is None)
    cycle = next(a for a in ANSWERS if a.mistake == 'every_cycle')
    never = next(a for a in ANSWERS if a.mistake == 'never_warns')
    assert generator.verdict(right, _record({}))[0]
    assert not generator.verdict(right, _record({}, 'graded with fixes'))[0]
    assert not generator.verdict(right, _record({}, 'needs a hand grade'))[0]
    fair, how = generator.verdict(right, _record({'Q14b': 1.5}))
    assert not fair and 'Q14b 1.5/3 (wanted 3)' in how
    assert generator.verdict(cycle, _record({'Q13': 2.0}))[0]
    assert not generator.verdict(cycle, _record({'Q13': 2.0, 'Q14b': 2.5}))[0]
    assert not generator.verdict(cycle, _record({}))[0]
    assert generator.verdict(cycle, _record({'Q13': 0.0}, 'needs a hand grade'))[0]
    assert generator.verdict(never, _record({'Q13': 0.0}, 'needs a hand grade'))[0]
    reset = next(a for a in ANSWERS if a.mistake == 'no_reset')  # a range: 0 to 1.5 of 14b's 3
    assert generator.verdict(reset, _record({'Q14b': 0.0}))[0] and generator.verdict(reset, _record({'Q14b': 1.5}))[0]
    fair, how = generator.verdict(reset, _record({'Q14b': 2.0}))
    assert not fair and 'Q14b 2/3 (wanted 0-1.5)' in how
    assert not generator.verdict(never, _record({'Q13': 0.0, 'Q14b': 0.0}))[0]


# --- a flight without ROS ----------------------------------------------------------------------------

class Shutdown(Exception):
    pass


class Sim(object):
    """A simulated clock and a ROS graph: topics, one warning service, timers, and node threads run one
    at a time (a node's thread runs only while the clock waits for it)."""

    def __init__(self, end):
        self.now, self.end, self.seq = 0.0, end, itertools.count()
        self.queue, self.subs, self.published, self.calls = [], collections.defaultdict(list), [], []
        self.back = threading.Semaphore(0)
        self.threads = []

    def at(self, t, fn):
        heapq.heappush(self.queue, (t, next(self.seq), fn))

    def publish(self, topic, value):
        self.published.append((self.now, topic, value))
        for callback in list(self.subs[topic]):
            callback(types.SimpleNamespace(data=value))

    def start(self, target):
        go = threading.Semaphore(0)
        state = {'go': go, 'error': None}

        def run():
            try:
                target(state)
            except Shutdown:
                pass
            except Exception as err:  # rospy.ROSInterruptException from Rate.sleep at shutdown: the end
                if type(err).__name__ != 'ROSInterruptException':
                    state['error'] = err
            finally:
                state['done'] = True
                self.back.release()
        self.threads.append(state)
        threading.Thread(target=run, daemon=True).start()
        self.back.acquire()  # until the node blocks (spin, sleep) or ends
        return state

    def block(self, state, until=None):
        """Called by a node's thread: hand the clock back; resumed at ``until`` (never for spin)."""
        if until is not None:
            self.at(until, lambda: self.resume(state))
        self.back.release()
        state['go'].acquire()
        if self.now >= self.end:
            raise Shutdown()

    def resume(self, state):
        state['go'].release()
        self.back.acquire()

    def run(self):
        while self.queue and self.queue[0][0] <= self.end:
            t, _, fn = heapq.heappop(self.queue)
            self.now = max(self.now, t)
            fn()
        self.now = self.end
        for state in self.threads:
            if not state.get('done'):
                state['go'].release()
                self.back.acquire()


def fake_modules(sim, node_params, node_state):
    """rospy, message_filters, std_msgs.msg and the drones' srv modules over ``sim``."""
    rospy = types.ModuleType('rospy')

    class ServiceException(Exception):
        pass

    class ROSInterruptException(Exception):
        pass

    def resolve(name):
        if name.startswith('~'):
            return '/%s/%s' % (node_state['name'], name[1:])
        return name if name.startswith('/') else '/' + name

    def get_param(name, default=KeyError):
        key = resolve(name)
        if key in node_params['params']:
            return node_params['params'][key]
        if default is KeyError:
            raise KeyError(key)
        return default

    class Publisher(object):
        def __init__(self, topic, msg_type, queue_size=None):
            self.topic = resolve(topic)

        def publish(self, value):
            sim.publish(self.topic, getattr(value, 'data', value))

    def subscriber(topic, msg_type, callback):
        sim.subs[resolve(topic)].append(callback)

    class Timer(object):
        def __init__(self, period, callback, oneshot=False):
            self.period, self.callback, self.oneshot, self.stopped = float(period), callback, oneshot, False
            sim.at(sim.now + self.period, self.fire)

        def fire(self):
            if self.stopped:
                return
            self.callback(types.SimpleNamespace(current_real=sim.now))
            if not self.oneshot:
                sim.at(sim.now + self.period, self.fire)

        def shutdown(self):
            self.stopped = True

    class Rate(object):
        def __init__(self, hz):
            self.period, self.last = 1.0 / hz, sim.now

        def sleep(self):
            self.last += self.period
            try:
                sim.block(node_state['thread'], self.last)
            except Shutdown:
                raise ROSInterruptException('shutdown')

    def proxy(name, srv_type):
        def call(status=None, **kwargs):
            sim.calls.append((sim.now, kwargs.get('status', status)))
        return call

    def spin():
        sim.block(node_state['thread'])

    def wait_for_message(topic, msg_type, timeout=None):
        """The next message of ``topic``: the node's thread waits for it, the clock goes on."""
        state, got, name = node_state['thread'], {}, resolve(topic)

        def once(msg):
            if 'msg' not in got:
                got['msg'] = msg
                sim.subs[name].remove(once)
                sim.at(sim.now, lambda: sim.resume(state))
        sim.subs[name].append(once)
        sim.block(state)
        return got['msg']

    rospy.ServiceException, rospy.ROSInterruptException = ServiceException, ROSInterruptException
    rospy.init_node = lambda name, **kw: node_state.update(name=name)
    rospy.get_param = get_param
    rospy.myargv = lambda argv=None: list(node_params['argv'])
    rospy.get_time = lambda: sim.now
    rospy.Time = types.SimpleNamespace(now=lambda: sim.now)
    rospy.is_shutdown = lambda: sim.now >= sim.end
    rospy.Publisher, rospy.Subscriber, rospy.Timer, rospy.Rate = Publisher, subscriber, Timer, Rate
    rospy.Duration = float
    rospy.ServiceProxy, rospy.wait_for_service, rospy.spin = proxy, (lambda name, timeout=None: None), spin
    rospy.wait_for_message = wait_for_message
    for level in ('loginfo', 'logwarn', 'logerr', 'logdebug'):
        setattr(rospy, level, lambda *a, **k: None)

    filters = types.ModuleType('message_filters')

    class FilterSubscriber(object):
        def __init__(self, topic, msg_type):
            self.topic, self.callbacks = resolve(topic), []
            sim.subs[self.topic].append(lambda msg: [cb(msg) for cb in self.callbacks])

    class Synchronizer(object):
        """The pairing of message_filters' ApproximateTimeSynchronizer for headerless messages: a new
        message pairs with the closest unused one of the other input within the slop; both are used."""

        def __init__(self, subscribers, queue_size, slop, allow_headerless=False):
            assert allow_headerless, 'Float32 has no header: without allow_headerless nothing is synchronised'
            self.queues, self.slop, self.callbacks = [[] for _ in subscribers], slop, []
            for index, sub in enumerate(subscribers):
                sub.callbacks.append(lambda msg, index=index: self.add(index, msg))

        def add(self, index, msg):
            self.queues[index].append((sim.now, msg))
            other = self.queues[1 - index]
            near = [m for m in other if abs(m[0] - sim.now) <= self.slop]
            if near:
                best = min(near, key=lambda m: abs(m[0] - sim.now))
                other.remove(best)
                self.queues[index].pop()
                pair = [None, None]
                pair[index], pair[1 - index] = msg, best[1]
                for callback in self.callbacks:
                    callback(*pair)

        def registerCallback(self, callback):
            self.callbacks.append(callback)

    filters.Subscriber, filters.ApproximateTimeSynchronizer = FilterSubscriber, Synchronizer
    std_msgs = types.ModuleType('std_msgs')
    msg = types.ModuleType('std_msgs.msg')
    msg.Float32 = object
    std_msgs.msg = msg
    mods = {'rospy': rospy, 'message_filters': filters, 'std_msgs': std_msgs, 'std_msgs.msg': msg}
    for pkg, (module, klass) in generator.SERVICE_TYPES.items():
        srv = types.ModuleType(module)
        setattr(srv, klass, object)
        mods[module.split('.')[0]] = types.ModuleType(module.split('.')[0])
        mods[module] = srv
    return mods


def launch_nodes(text, overrides=None):
    """``{script: {'params': {...}, 'argv': [...]}}`` from the package's launch file (params, args)."""
    root = ET.fromstring(text if '<launch>' in text else '<launch>%s</launch>' % text)  # read as the grader does
    args = {a.get('name'): (overrides or {}).get(a.get('name'), a.get('default')) for a in root.iter('arg')}
    sub = lambda v: re.sub(r'\$\(arg (\w+)\)', lambda m: args[m.group(1)], v or '')
    top = {'/' + p.get('name'): float(sub(p.get('value'))) for p in root.findall('param')}
    if overrides and 'threshold' in overrides:
        top = {k: float(overrides['threshold']) if k == '/threshold' else v for k, v in top.items()}
    nodes = {}
    for node in root.findall('node'):
        if node.get('pkg') != 'exam':
            continue
        params = dict(top)
        for p in node.findall('param'):
            value = overrides['threshold'] if overrides and p.get('name') == 'threshold' else sub(p.get('value'))
            params['/%s/%s' % (node.get('name'), p.get('name'))] = float(value)
        nodes[node.get('type')] = {'params': params, 'argv': [node.get('type')] + sub(node.get('args')).split()}
        if node.get('name') is None:  # named after its executable, as the grader runs it
            params = {k.replace('/None/', '/%s/' % node.get('type')[:-3]): v for k, v in params.items()}
            nodes[node.get('type')]['params'] = params
    return nodes


#: The flight, s: below, a 3 s excursion above, below, 12 s above, just below (1 % under), far below.
LEGS = [(0.0, 'lo'), (8.0, 'hi'), (11.0, 'lo'), (16.0, 'hi'), (28.0, 'near'), (34.0, 'lo')]
END = 40.0
TEMPERATURE_C = 5.0  # the air's temperature, constant (a node that assumes 15 degC is 40 m off at 1300 m)


def sheet_value(sheet, which, threshold):
    return {'lo': 0.9, 'hi': 1.1, 'near': 0.99}[which] * threshold


def inputs_at(sheet, t, threshold):
    target = sheet_value(sheet, [w for start, w in LEGS if start <= t][-1], threshold)
    if sheet == 'altitude':
        p0, mu, g, r = 101325.0, 0.0289644, 9.80665, 8.31432
        t_k = TEMPERATURE_C + 273.15
        return {'/temperature': TEMPERATURE_C, '/pressure': p0 * math.exp(-mu * g * target / (r * t_k))}
    remote = 101325.0 + 700.0
    return {'/pressure_robot': remote + 1030.0 * 9.80665 * target, '/pressure_remote': remote}


def fly(answer, threshold_override=None):
    """Run the answer's scripts in a simulated flight; return the sim (published values, calls)."""
    files = generator.package_files(answer.style, answer.mistake, answer.form)
    threshold = SHEETS[answer.style.sheet].threshold
    nodes = launch_nodes(files['launch/exam.launch'],
                         {'threshold': str(threshold_override)} if threshold_override else None)
    sim = Sim(END)
    rates = generator.DRONE_RATES[answer.style.sheet]

    def sensor(topic, period):
        def tick():
            sim.publish(topic, inputs_at(answer.style.sheet, sim.now, threshold)[topic])
            sim.at(sim.now + period, tick)
        return tick
    for n, (topic, hz) in enumerate(rates.items()):
        sim.at(0.05 + 0.13 * n, sensor('/' + topic, 1.0 / hz))
    saved = {name: sys.modules.get(name) for name in ('rospy', 'message_filters', 'std_msgs', 'std_msgs.msg',
                                                      'mydrone', 'mydrone.srv', 'submarinedrone',
                                                      'submarinedrone.srv')}
    try:
        for script in sorted(nodes, key=lambda s: s != 'exam_node.py'):
            node_state = {}
            sys.modules.update(fake_modules(sim, nodes[script], node_state))
            code = compile(files['scripts/' + script], script, 'exec')
            space = {'__name__': 'exam_script'}
            exec(code, space)

            def target(state, space=space, node_state=node_state):
                node_state['thread'] = state
                space['main']()
            state = sim.start(target)
            assert state['error'] is None, state['error']
        sim.run()
    finally:
        for name, module in saved.items():
            if module is None:
                sys.modules.pop(name, None)
            else:
                sys.modules[name] = module
    for state in sim.threads:
        assert state['error'] is None, state['error']
    return sim


def observed(answer, sim):
    """What a teacher would read off the flight: the output's rate and error, when its own value went
    above and came back, the calls."""
    sheet = answer.style.sheet
    threshold = SHEETS[sheet].threshold
    topic = '/' + SHEETS[sheet].output
    out = [(t, v) for t, name, v in sim.published if name == topic]
    crossings = [t for (t0, v0), (t, v) in zip(out, out[1:]) if (v0 > threshold) != (v > threshold)]
    steady = [(t, v) for t, v in out if 5.0 < t < 8.0]
    error = max(abs(v - sheet_value(sheet, 'lo', threshold)) for _, v in steady) if steady else None
    hz = len([1 for t, _ in out if 20.0 <= t < 30.0]) / 10.0
    return {'out': out, 'crossings': crossings, 'error': error, 'hz': hz, 'calls': sim.calls}


def input_period(answer):
    """How late a right node may act: the slower input's period when it waits for a pair of readings,
    else the fastest input's (its value changes at each reading)."""
    rates = generator.DRONE_RATES[answer.style.sheet]
    return 1.0 / (min(rates.values()) if answer.style.inputs == 'sync' else max(rates.values()))


@pytest.mark.parametrize('answer', [a for a in ANSWERS if a.mistake is None], ids=lambda a: a.name)
def test_each_correct_answer_does_what_the_sheet_asks(answer):
    seen = observed(answer, fly(answer))
    assert seen['error'] is not None and seen['error'] < 0.5, seen['error']
    assert abs(seen['hz'] - 10.0) <= 0.5, seen['hz']
    assert len(seen['crossings']) == 4, seen['crossings']  # up, down (short), up, down (near)
    up, down = seen['crossings'][2], seen['crossings'][3]
    assert [s for _, s in seen['calls']] == ['WARNING', 'NORMAL'], seen['calls']
    (warned, _), (normal, _) = seen['calls']
    # 5 s after its own value went above, no later than the next value the node computes
    assert DELAY_OK(warned - up, answer), (warned - up)
    # the crossings are read off the 10 Hz output, the calls made when the value changed: 0.1 s either way
    assert -0.15 <= normal - down <= 0.15, normal - down


def DELAY_OK(latency, answer):
    return 5.0 - 0.15 <= latency <= 5.0 + input_period(answer) + 0.15


def test_a_correct_answer_obeys_its_launch_files_threshold():
    for style in ('private', 'global', 'args'):
        answer = next(a for a in ANSWERS if a.mistake is None and a.style.threshold == style)
        lower = 0.8 * SHEETS[answer.style.sheet].threshold  # the flight's lows (90 %) are above it
        seen = observed(answer, fly(answer, threshold_override='%g' % lower))
        # above the new threshold from the start: WARNING 5 s in, before the flight's first excursion
        assert seen['calls'] and seen['calls'][0][1] == 'WARNING' and seen['calls'][0][0] < 8.0, (style, seen['calls'])


MISTAKE_SEEN = {
    'every_cycle': lambda s, a: len(s['calls']) > 20,
    'repeat_warning': lambda s, a: [c for _, c in s['calls']].count('WARNING') > 5
    and [c for _, c in s['calls']].count('NORMAL') == 1,
    'no_kelvin': lambda s, a: s['error'] > 10,
    'wrong_rho': lambda s, a: s['error'] > 1,
    'no_delay': lambda s, a: s['calls'][0][0] - s['crossings'][0] < 1.0,
    'short_delay': lambda s, a: abs(s['calls'][0][0] - s['crossings'][2] - 4.5) < 0.15,
    'no_reset': lambda s, a: s['calls'][0][0] - s['crossings'][2] < 4.0,
    'margin': lambda s, a: s['calls'][1][0] - s['crossings'][3] > 5.0,
    'normal_delayed': lambda s, a: 4.85 <= s['calls'][1][0] - s['crossings'][3] <= 5.15 + input_period(a),
    'hard_threshold': None,
    'param_name': None,
    'one_subscriber': lambda s, a: s['error'] > 20,
    'wrong_topic': lambda s, a: not s['out'],
    'slow_rate': lambda s, a: s['hz'] < 4,
    'launch_no_drone': None,
    'launch_no_comment': None,
    'lowercase_request': lambda s, a: [c for _, c in s['calls']] == ['warning', 'normal'],
    'never_warns': lambda s, a: s['calls'] == [],
    'launch_no_root': None,
    'node_no_name': None,
    # Issue 45: a value once a period of the slower input, the calls as a correct answer's.
    'slow_loop': lambda s, a: s['hz'] < 1.5 and [c for _, c in s['calls']] == ['WARNING', 'NORMAL']
    and 4.85 <= s['calls'][0][0] - s['crossings'][2] <= 5.15 + 1.0 / min(generator.DRONE_RATES[a.style.sheet].values())
    + 1.0 / max(generator.DRONE_RATES[a.style.sheet].values()),
    'silent_output': lambda s, a: not s['out'] and [c for _, c in s['calls']] == ['WARNING', 'NORMAL'],
    'positional_queue': None,
}


@pytest.mark.parametrize('answer', [a for a in ANSWERS if a.mistake is not None], ids=lambda a: a.name)
def test_each_one_mistake_answer_makes_its_mistake(answer):
    files = generator.package_files(answer.style, answer.mistake)
    correct = generator.package_files(answer.style)
    launch = files['launch/exam.launch']
    if answer.mistake in ('hard_threshold', 'param_name'):
        lower = 0.8 * SHEETS[answer.style.sheet].threshold
        assert observed(answer, fly(answer, threshold_override='%g' % lower))['calls'][0][0] > 16.0
        assert observed(answer, fly(generator.Answer('x', answer.style, None, {}), '%g' % lower))['calls'][0][0] < 8
        return
    if answer.mistake == 'positional_queue':  # rospy's third argument is subscriber_listener: nothing received
        script = files['scripts/exam_node.py']
        assert ", Float32, 10)  # the output" in script and 'Float32, queue_size=10)' not in script
        assert script.replace(', Float32, 10)', ', Float32, queue_size=10)') == correct['scripts/exam_node.py']
        seen = observed(answer, fly(answer))  # the stand-in takes 10 for the queue: the calls are a correct one's
        assert [c for _, c in seen['calls']] == ['WARNING', 'NORMAL'], seen['calls']
        return
    if answer.mistake == 'launch_no_root':
        assert '<launch>' not in launch and '</launch>' not in launch and '<launch>' in correct['launch/exam.launch']
        assert launch == correct['launch/exam.launch'].replace('<launch>\n', '').replace('</launch>\n', '')
    elif answer.mistake == 'node_no_name':
        exam = [line for line in launch.splitlines() if 'type="exam_node.py"' in line]
        assert len(exam) == 1 and 'name=' not in exam[0], exam
        assert launch.count('name=') == correct['launch/exam.launch'].count('name=') - 1
    elif answer.mistake == 'launch_no_drone':
        assert SHEETS[answer.style.sheet].drone_type not in launch
        assert SHEETS[answer.style.sheet].drone_type in correct['launch/exam.launch']
    elif answer.mistake == 'launch_no_comment':
        assert '<!--' not in launch and '<!--' in correct['launch/exam.launch']
    else:
        seen = observed(answer, fly(answer))
        assert MISTAKE_SEEN[answer.mistake](seen, answer), (seen['calls'], seen['crossings'], seen['error'], seen['hz'])
        return
    # a launch file's mistake only: the scripts are the correct answer's
    assert {k: v for k, v in files.items() if k.startswith('scripts/')} == \
        {k: v for k, v in correct.items() if k.startswith('scripts/')}


@pytest.mark.parametrize('answer', ANSWERS[::7], ids=lambda a: a.name)
def test_each_package_is_a_catkin_package_named_exam(answer):
    files = generator.package_files(answer.style, answer.mistake)
    package = ET.fromstring(files['package.xml'])
    assert package.find('name').text == 'exam'
    assert SHEETS[answer.style.sheet].drone_pkg in [d.text for d in package.iter('exec_depend')]
    for script in [k for k in files if k.startswith('scripts/')]:
        assert files[script].startswith('#!/usr/bin/env python3\n')
        assert script in files['CMakeLists.txt']
        assert 'type="%s"' % script.split('/')[1] in files['launch/exam.launch']


def test_issue_45s_kinds_are_in_the_matrix_and_a_flagged_silent_output_is_held_to_its_points():
    kinds = ('launch_no_root', 'node_no_name', 'slow_loop', 'silent_output', 'positional_queue')
    assert all(len([a for a in ANSWERS if a.mistake == kind]) == 2 for kind in kinds)
    forms = [a for a in ANSWERS if a.form != 'plain']
    assert [(a.form, a.style.sheet) for a in forms] == [(f, s) for f in generator.FORMS for s in SHEETS]
    assert all(a.mistake is None and a.expected == {} for a in forms)
    assert generator.package_files(forms[0].style, None, 'declared')['launch/exam.launch'].startswith(
        '<?xml version="1.0"?>\n<launch>')
    queue = next(a for a in ANSWERS if a.mistake == 'positional_queue')
    assert generator.verdict(queue, _record({'Q11': 1.5}, 'needs a hand grade'))[0]
    fair, how = generator.verdict(queue, _record({'Q11': 1.5, 'Q13': 0.0}, 'needs a hand grade'))
    assert not fair and 'Q13 0/4 (wanted 4)' in how, 'flagged, and still judged on its calls'
    slow = next(a for a in ANSWERS if a.mistake == 'slow_loop')
    assert generator.verdict(slow, _record({'Q11': 3.0}))[0]
    assert not generator.verdict(slow, _record({'Q11': 1.5}))[0], 'the values\' 1.5 lost too: two losses'

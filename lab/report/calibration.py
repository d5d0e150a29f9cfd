"""docs/grading.md's calibration table: each kind of mistake students make, the machine's points for it
and the sheet's note it follows, from the tested truth.

The points are never typed: they are those lab/test/grader/test_grade.py expects of each test package
(``EXPECTED``, ``FAIR_EXPECTED``, and each status), which the grader test holds the real grader to. This
file adds only words: what the mistake is, and which of the sheet's grader notes
(/work/shared/seeds/000_*.txt, "Solution: ...") the points follow, or that the notes say nothing and
the grader decided. The docs test (lab/test/docs/test_docs_quote_code.py) holds the block in
docs/grading.md to this script's output; no run is needed.

Usage::

    python3 lab/report/calibration.py          # writes the block between its markers in docs/grading.md
"""
import importlib.util
import os
import sys

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
DOC = os.path.join(REPO, 'docs', 'grading.md')
GRADE_TEST = os.path.join(REPO, 'lab', 'test', 'grader', 'test_grade.py')
BEGIN = '<!-- calibration: written by lab/report/calibration.py from lab/test/grader/test_grade.py; do not edit -->'
END = '<!-- end of calibration -->'

#: The sheet's grader notes (sheet 000, used for sheet 001 too), by item, as the sheet words them.
NOTES = {
    'runs': '"est-ce que le noeud se lance et fait ce qu\'il doit faire, selon l\'avancée de l\'étudiant ? 2 points"',
    'Q10': 'Q10: "2 points. 1 point si seulement un topic"',
    'Q11': 'Q11: "4 points, on vérifie surtout l\'algorithmie ... 1.5 points si le publisher est correctement déclaré"',
    'Q12': 'Q12: "1 point. La moitié si pas de commentaires"',
    'Q13': 'Q13: "4 points. 2 points si appel au service en boucle"',
    'Q14a': 'Q14a: "1 points. 0 si la variable n\'est pas initialisée" (the threshold in the launch file)',
    'Q14b': 'Q14b: "3 points" for "500 fois au dessus" (the 5 s delay), the counter reset below',
}

#: Each test package that shows a mistake: (the mistake in a teacher's words, the note its points
#: follow). The order is the table's. A package of test_grade.py missing here is a failure of the
#: docs test, so a new kind of mistake cannot stay out of the table.
MISTAKES = [
    ('no_kelvin', 'the temperature left in degC in equation (1)',
     NOTES['Q11'] + ': the publisher and the 10 Hz kept, the values\' 1.5 lost (the split of the other 2.5 is the grader\'s)'),
    ('one_subscriber', 'one input never subscribed (depth: no `/pressure_remote`, a constant instead)',
     NOTES['Q10'] + '; Q11\'s values then wrong too: the input the grader varies is ignored'),
    ('float64_temperature', 'an input subscribed with another type (`Float64`): rospy refuses the drone\'s `Float32`',
     NOTES['Q10'] + ': a subscription that never gets a message counts as missing; the rest judged as if fixed'),
    ('float64_pressure', 'the same on the input that moves the altitude', NOTES['Q10'] + ', as above'),
    ('wrong_topic', 'the output on another topic (`/profondeur` for `/depth`)',
     NOTES['Q11'] + ': the publisher\'s 1.5; rate and values measured on the topic it does publish'),
    ('float64_depth', 'the output as `Float64` instead of `Float32`',
     NOTES['Q11'] + ': the sheets name no type, so any numeric `std_msgs` type is "correctement déclaré"'),
    ('every_cycle', 'the warning service called every cycle, not on crossings', NOTES['Q13']),
    ('lowercase_service', 'the service called with "warning" / "normal": the drone refuses the request',
     'the notes say nothing: the grader takes half of Q13, once, and leaves the grade to you'),
    ('led_colours', 'the service called with the LED\'s colours, "RED" / "GREEN"',
     'the notes say nothing: as "warning" above (read as WARNING / NORMAL for the timing)'),
    ('no_delay', 'WARNING at the first reading above: no delay', NOTES['Q14b'] + ': no delay, none of the 3'),
    ('late_warning', 'a counter of 500 ticks at 10 Hz: WARNING after 50 s (the notes\' own "10ms" slip)',
     NOTES['Q14b'] + ': the delay\'s 1.5 lost, the short excursion and the NORMAL kept'),
    ('sleep_in_callback', '`time.sleep(5)` in a callback: the value follows late, WARNING after the short excursion',
     NOTES['Q14b'] + ': the 1 point of "no WARNING for a shorter excursion" lost'),
    ('hard_threshold', 'the launch file sets the threshold, the code uses a constant', NOTES['Q14a']),
    ('yaml_threshold', 'the threshold in a YAML file the launch file loads', NOTES['Q14a'] + ': set by the launch file, so full marks'),
    ('args_threshold', 'the threshold as a command-line argument (`args="--threshold $(arg threshold)"`, argparse)',
     NOTES['Q14a'] + ': set by the launch file, so full marks'),
    ('rosparam_threshold', 'the threshold as inline `<rosparam>` YAML in the node\'s tag', NOTES['Q14a'] + ', as above'),
    ('included_threshold', 'the threshold passed to an included launch file, read before `init_node`',
     NOTES['Q14a'] + ', as above'),
    ('never_warns', 'one line misplaced (`counter = 0` out of its `else`): the WARNING call is never reached',
     NOTES['Q13'] + ' and ' + NOTES['Q14b'] + ': no call, none of their points; Q14a\'s half from the code; '
     'read the code, the reason names the call\'s line'),
    ('fresh_readings', 'a new value published only from a fresh reading of each input (it lags up to one '
     'temperature period, 1.3 s)', NOTES['Q11'] + ': its own value is judged, so nothing lost; the lag is '
     'reported on its own'),
    ('count_messages', 'the 5 s delay counted in messages of the 2 Hz `pressure_robot` (depth)',
     NOTES['Q14b'] + ': 10 periods of the drone\'s own rate are 5 s, so full marks'),
    ('delay_minus_period', 'the delay counted one reading short: 10 readings of the 2 Hz pressure from the first '
     '(4.5 s)', NOTES['Q14b'] + ': the 1.5 of the delay lost, the rest kept'),
    ('margin_normal', 'NORMAL only once the altitude is 5 m below the threshold',
     NOTES['Q14b'] + ' ("the counter reset below": back to green at once): its half point lost'),
    ('renamed_package', 'a launch file without a single comment (and the package named `exam_pkg`)',
     NOTES['Q12'] + '; the name is question 9\'s business, in the report'),
    ('type_without_py', 'the launch file names `type="exam_node"` for `scripts/exam_node.py`',
     'the notes say nothing: half of Q12 (the file starts no executable); the node run as fixed'),
    ('duplicate_names', 'the launch file gives the exam node the drone\'s name: roslaunch refuses it',
     'the notes say nothing: Q12\'s point lost (the file does not run as handed in); the node run as fixed'),
    ('launch_no_root', 'the launch file\'s elements without their `<launch>` root: roslaunch refuses it',
     'the notes say nothing: Q12\'s point lost (the file does not run as handed in); its threshold and nodes judged '
     'as written, the file run inside a `<launch>` (the fix named)'),
    ('node_without_name', 'the exam node\'s `<node>` without its `name` (ROS 2\'s habit): roslaunch refuses it',
     'as above: Q12\'s point lost; the node run named after its executable (the fix named)'),
    ('wait_for_message', '`rospy.wait_for_message` for each input in the loop: a value about once a second',
     NOTES['Q11'] + ': the 10 Hz point lost; its values judged against the inputs it could have seen within its '
     'lag, its delay at its own pace'),
    ('positional_queue', '`rospy.Publisher(\'/altitude\', Float32, 10)` (ROS 2\'s habit: rospy\'s third argument is '
     '`subscriber_listener`): nothing is received',
     NOTES['Q11'] + ': the publisher\'s 1.5 kept, rate and values not measured; Q13, Q14a, Q14b judged from its '
     'calls against the judge\'s own value of the flight; the reason says so, and why'),
    ('crash_at_start', 'the node dies at start (`~threshold` read, `/threshold` set: KeyError)',
     NOTES['runs'] + ' and "on vérifie surtout l\'algorithmie": the build\'s point and Q12\'s (the launch file) only; read the code'),
    ('python2_prints', 'Python 2 `print` statements: SyntaxError at start', 'as the crash above'),
    ('windows_zip', 'zipped on Windows (CRLF, backslash names, no modes)', 'not a mistake the notes price: fixed, nothing lost'),
    ('workspace_tgz', 'a whole `catkin_ws` uploaded as `exam.tar.gz`', 'not a mistake the notes price: the package taken from `src/` (its Q14a is `hard_threshold`\'s, which it is made from)'),
    ('two_uploads', 'two uploads kept by Moodle (`exam.zip`, `exam_v2.zip`)', 'not a mistake the notes price: the newest graded, you told'),
    ('refused_upload', 'an archive with an entry climbing out of its folder (`../outside.txt`)', 'not graded: ask for a clean zip'),
]

#: Packages of test_grade.py that show no mistake (the reference answers).
NO_MISTAKE = ('good_student', 'ours')


def load_expectations():
    """lab/test/grader/test_grade.py as a module: EXPECTED, FAIR_EXPECTED, their statuses and FULL."""
    spec = importlib.util.spec_from_file_location('grade_expectations', GRADE_TEST)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _points(x):
    return ('%g' % x)


def rows(tested=None):
    """The table's rows: (mistake, package, points and what is lost, status, note), from the tests."""
    tested = tested or load_expectations()
    expected = dict(tested.EXPECTED, **tested.FAIR_EXPECTED)
    status = dict(tested.STATUS, **tested.FAIR_STATUS)
    described = [name for name, _, _ in MISTAKES]
    unknown = sorted(set(expected) - set(described) - set(NO_MISTAKE))
    if unknown:
        raise ValueError('test_grade.py grades %s: add its mistake to MISTAKES' % ', '.join(unknown))
    table = []
    for name, mistake, note in MISTAKES:
        if name not in expected:
            raise ValueError('%s is not graded by test_grade.py any more' % name)
        points = dict(tested.FULL, **expected[name])
        lost = ['%s %s' % (item, _points(tested.FULL[item] - points[item]))
                for item in tested.FULL if points[item] < tested.FULL[item]]
        total = _points(sum(points.values()))
        table.append((mistake, '`%s`' % name, '%s / %s%s' % (total, _points(sum(tested.FULL.values())),
                                                              ' (%s)' % ', '.join(lost) if lost else ''),
                      status.get(name, 'graded'), note))
    return table


def block(tested=None):
    """The Markdown between (and with) the markers."""
    lines = [BEGIN,
             '| the mistake | test package | the machine\'s points (lost) | status | the sheet\'s note it follows |',
             '|---|---|---|---|---|']
    lines += ['| %s |' % ' | '.join(row) for row in rows(tested)]
    return '\n'.join(lines + [END])


def main():
    sys.path.insert(0, os.path.dirname(os.path.realpath(__file__)))
    import console_excerpt
    with open(DOC, encoding='utf-8') as f:
        text = f.read()
    with open(DOC, 'w', encoding='utf-8') as f:
        f.write(console_excerpt.splice(text, block(), BEGIN, END))
    print('calibration: %d rows written into %s' % (len(rows()), os.path.relpath(DOC, REPO)))


if __name__ == '__main__':
    main()

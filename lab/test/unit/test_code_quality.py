"""Comments per function and block, and the quality signals, read from a student's code (boxed/code_quality.py).

The packages are the grader's test submissions (lab/test/grader/submissions), each written as a
student of the course writes; the few lines below that a signal needs and no submission has (a busy
wait, a name pyflakes finds undefined) are said where they are written.
"""
import os
import shutil

import pytest

from exam_lab.grader.boxed import code_quality, source

SUBMISSIONS = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), 'grader', 'submissions')


def package(name):
    folder = os.path.join(SUBMISSIONS, name)
    inner = [d for d in sorted(os.listdir(folder)) if os.path.isfile(os.path.join(folder, d, 'package.xml'))]
    return os.path.join(folder, inner[0]) if inner else folder


def signals(pkg):
    return code_quality.quality_signals(source.student_code(pkg), pkg)


def kinds(pkg):
    """The signals found, but the note that pyflakes is missing (a Python without it)."""
    return sorted({(s['kind'], s['file'], s['line']) for s in signals(pkg) if s['kind'] != 'note'})


def test_a_service_called_on_every_pass_of_the_loop():
    assert kinds(package('every_cycle')) == [('service in a loop', 'scripts/exam_node.py', 49),
                                            ('service in a loop', 'scripts/exam_node.py', 51)]


def test_a_service_called_on_crossings_only_is_no_signal():
    assert kinds(package('crash_at_start')) == []  # led() under "count == 50": a crossing, globals read by the loop


def test_a_sleep_in_a_callback():
    assert kinds(package('sleep_in_callback')) == [('blocking call in a callback', 'scripts/exam_node.py', 24)]


def copy_with(tmp_path, name, lines):
    """The submission ``name`` copied, ``lines`` appended to its node (what the signal needs)."""
    pkg = str(tmp_path / 'pkg')
    shutil.copytree(package(name), pkg)
    with open(os.path.join(pkg, 'scripts', 'exam_node.py'), 'a') as f:
        f.write('\n' + '\n'.join(lines) + '\n')
    return pkg


def test_a_busy_wait(tmp_path):
    # a student waiting for the first reading by spinning on it
    pkg = copy_with(tmp_path, 'crash_at_start', ['while pressure == 0.0:', '    pass'])
    found = [s for s in signals(pkg) if s['kind'] == 'busy wait']
    assert [s['line'] for s in found] == [len(open(os.path.join(pkg, 'scripts', 'exam_node.py')).read().splitlines()) - 1]


def test_pyflakes_and_a_global_nobody_reads(tmp_path):
    pyflakes = pytest.importorskip('pyflakes')  # python3-pyflakes, tools/install_deps.sh
    assert pyflakes
    pkg = copy_with(tmp_path, 'crash_at_start', ['def reset():', '    global last, ticks', '    last = undefined_name',
                                                 '    ticks += 1'])
    found = {(s['kind'], s['detail'].split(' in ')[0]) for s in signals(pkg)}
    assert ('pyflakes', "undefined name 'undefined_name'") in found
    assert ('global without need', 'global last') in found and ('global without need', 'global ticks') in found
    # the submission's own globals, written by the callbacks and read by the loop, are no signal
    assert {s['line'] for s in signals(pkg) if s['kind'] == 'global without need'} == {
        len(open(os.path.join(pkg, 'scripts', 'exam_node.py')).read().splitlines()) - 2}


def test_every_function_and_block_with_its_comment():
    pkg = package('crash_at_start')
    units = code_quality.comment_units(source.student_code(pkg), pkg)
    by_line = {u['line']: (u['kind'], u['name'], u['commented']) for u in units}
    assert by_line[15] == ('function', 'on_temperature', False) and by_line[20] == ('function', 'on_pressure', False)
    assert all(u['commented'] is False for u in units)
    good = package('good_student')
    units = code_quality.comment_units(source.student_code(good), good)
    assert 0 < sum(u['commented'] for u in units) < len(units)


def test_a_comment_opening_a_block_counts_and_the_main_guard_is_no_block(tmp_path):
    """"if ...:" then "# formula (1)" above its first statement is a commented block; ``if __name__ ==
    '__main__':`` is not counted (no note asks to comment it)."""
    (tmp_path / 'scripts').mkdir()
    (tmp_path / 'scripts' / 'exam_node.py').write_text('\n'.join([
        'import math', '', '', 'def main(x):', '    while x:', '        if x > 1:', '            # formula (1)',
        '            x = math.log(x)', '        else:', '            x = 0', '', '', "if __name__ == '__main__':",
        '    main(3)', '']))
    units = code_quality.comment_units([str(tmp_path / 'scripts' / 'exam_node.py')], str(tmp_path))
    assert [(u['line'], u['kind'], u['commented']) for u in units] == [
        (4, 'function', True), (5, 'while', False), (6, 'if', True)]

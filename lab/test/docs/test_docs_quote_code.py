"""Values the docs quote, read from the code: a document that disagrees with the code fails here.

The grader's time limits and the bounds of its boxes, the default JOBS rule, the number of test
packages, the rubric digest of the example grades, the module lists of the grader's folders, the
exam node's and the drones' private parameters and the launch files' arguments. Each check names the
document and the phrase it reads; a phrase that is no longer found fails too (a quoted value that
moved out of reach of its check is not a guarded one). Each check is held to a wrong value once
(the ``*_catches_*`` tests), so none of them can pass on anything. No ROS master needed.
"""
import glob
import os
import re
import xml.etree.ElementTree as ET

import pytest

from exam_lab.grader import runner
from exam_lab.grader.publish import provenance

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
GRADER = os.path.join(REPO, 'lab', 'src', 'exam_lab', 'grader')
GRADING = os.path.join(REPO, 'docs', 'grading.md')
ARCHITECTURE = os.path.join(REPO, 'docs', 'architecture.md')
README = os.path.join(REPO, 'README.md')


def read(path):
    with open(path, encoding='utf-8') as f:
        return f.read()


def prose(text):
    """Text with its line breaks and runs of spaces folded, so a phrase split across lines is found."""
    return ' '.join(text.split())


def seconds(value):
    """A limit as the docs write it: 180.0 -> '180', 0.5 -> '0.5'."""
    return ('%g' % value)


def gigabytes(value):
    return '%g GB' % (value / float(1 << 30))


# --- the grader's limits ---------------------------------------------------------------------------

def time_limits_quoted(text):
    """[(build, start, run)] of every "build N s, node start N s, each run N s" of a text."""
    return re.findall(r'build ([\d.]+) s, node start ([\d.]+) s, each run ([\d.]+) s', text)


def expected_time_limits():
    return (seconds(runner.BUILD_TIMEOUT), seconds(runner.START_TIMEOUT), seconds(runner.RUN_TIMEOUT))


def test_grading_quotes_the_runners_time_limits():
    quoted = time_limits_quoted(prose(read(GRADING)))
    assert quoted, 'docs/grading.md no longer says "build N s, node start N s, each run N s"'
    assert set(quoted) == {expected_time_limits()}


def test_the_time_limit_check_catches_a_stale_value():
    stale = 'a time limit on every step (build 180 s, node start 20 s, each run 90 s, the whole session 420 s)'
    assert time_limits_quoted(stale) == [('180', '20', '90')]
    assert ('180', '20', '90') != expected_time_limits()


def bounds_quoted(text):
    """The box bounds of the isolation table: (inspection), (intake), (similarity), each (wall, CPU, memory)."""
    match = re.search(r'inspection: ([\d.]+) s wall, ([\d.]+) s CPU, ([\d.]+ GB) address space; a class '
                      r'archive\'s intake: ([\d.]+) s, ([\d.]+) s, ([\d.]+ GB); similarity: ([\d.]+) s, '
                      r'([\d.]+) s per process, ([\d.]+ GB)', text)
    return match.groups() if match else None


def test_grading_quotes_the_bounds_of_the_boxes_that_read_student_bytes():
    expected = []
    for wall, cpu, memory in (runner.INSPECT_BOUNDS, runner.INTAKE_BOUNDS, runner.SIMILARITY_BOUNDS):
        expected += [seconds(wall), seconds(cpu), gigabytes(memory)]
    assert bounds_quoted(prose(read(GRADING))) == tuple(expected)


def test_the_bounds_check_catches_a_stale_value():
    text = ('inspection: 60 s wall, 60 s CPU, 1 GB address space; a class archive\'s intake: 300 s, 300 s, 1 GB; '
            'similarity: 900 s, 300 s per process, 2 GB')
    assert bounds_quoted(text)[-1] == '2 GB'


def test_default_jobs_is_quoted_as_the_code_computes_it():
    # "two per core" in the docs is runner.JOBS_PER_CORE; 4 on this two-core machine with its memory.
    assert runner.JOBS_PER_CORE == 2
    text = prose(read(GRADING) + read(os.path.join(REPO, 'docs', 'benchmarks.md')))
    assert 'two per core' in text or '2 per core' in text
    quoted = re.findall(r'`JOBS=(\d+)`?,? the default', text) + re.findall(r'the default JOBS=(\d+)', text)
    assert all(int(q) == runner.default_jobs(cores=2, memory=24 << 30) for q in quoted), quoted


# --- the test packages -----------------------------------------------------------------------------

def packages_quoted(text):
    return [int(n) for n in re.findall(r'`lab/test/grader/submissions/` holds (\d+) packages', text)]


def test_the_number_of_test_packages_quoted_is_the_folders():
    folder = os.path.join(REPO, 'lab', 'test', 'grader', 'submissions')
    count = len([d for d in os.listdir(folder) if os.path.isdir(os.path.join(folder, d))])
    text = prose(read(GRADING))
    assert not re.search(r'\b(?:holds|of) \d+ (?:student |test )?packages', text.replace(
        '`lab/test/grader/submissions/` holds', '')), 'a count of test packages outside the guarded phrase'
    assert all(n == count for n in packages_quoted(text)), (packages_quoted(text), count)


def test_the_package_count_check_catches_a_stale_count():
    assert packages_quoted('`lab/test/grader/submissions/` holds 13 packages') == [13]


# --- the example grades ----------------------------------------------------------------------------

def rubric_digests_quoted(text):
    return re.findall(r'Graded by the grader [0-9a-f+changes]+, rubric ([0-9a-f]{12})', text)


def test_the_example_grades_were_scored_by_todays_rubric():
    quoted = rubric_digests_quoted(read(GRADING))
    assert quoted, 'docs/grading.md shows no example grade with its provenance'
    assert set(quoted) == {provenance.rubric_version()}, (
        'the example grades were scored by another rubric: run lab/report/grading_examples.py')


# --- the grader's modules --------------------------------------------------------------------------

def grader_folders():
    """{folder: {module names}} of the grader's trust folders."""
    folders = {}
    for path in glob.glob(os.path.join(GRADER, '*', '__init__.py')):
        folder = os.path.basename(os.path.dirname(path))
        folders[folder] = {os.path.basename(p)[:-3] for p in glob.glob(os.path.join(GRADER, folder, '*.py'))
                           if not p.endswith('__init__.py')}
    return folders


def isolation_rows(text):
    """{folder: {module names}} of the isolation table's first column: "| `boxed/` (inspect, intake) |"."""
    rows = {}
    for folder, names in re.findall(r'^\| `(\w+)/` \(([\w, ]+)\)', text, re.M):
        rows[folder] = {n.strip() for n in names.split(',')}
    return rows


def test_the_isolation_table_names_every_module_of_boxed():
    rows = isolation_rows(read(GRADING))
    assert rows.get('boxed') == grader_folders()['boxed']


def test_the_module_list_check_catches_a_missing_module():
    assert isolation_rows('| `boxed/` (inspect, intake) | x |') == {'boxed': {'inspect', 'intake'}}


@pytest.mark.parametrize('path', [README, GRADING], ids=['README.md', 'docs/grading.md'])
def test_every_grader_folder_and_the_runner_are_named(path):
    text = read(path)
    for folder in grader_folders():
        assert '`%s/`' % folder in text, '%s does not name the grader folder %s/' % (os.path.relpath(path, REPO), folder)
    assert 'runner.py' in text


def test_the_package_docstring_names_every_module():
    import exam_lab.grader
    doc = exam_lab.grader.__doc__
    for folder, modules in grader_folders().items():
        for module in modules:
            assert '.%s.%s' % (folder, module) in doc, '%s/%s.py is not in the grader package docstring' % (folder, module)


# --- parameters and launch arguments ---------------------------------------------------------------

def table_parameters(text, node_words):
    """The ``~names`` of the rows of a Markdown parameter table whose first cell names one of the nodes."""
    names = set()
    for line in text.splitlines():
        cells = [c.strip() for c in line.split('|')[1:-1]]
        if len(cells) > 2 and cells[0] in node_words:
            names |= set(re.findall(r'`~(\w+)`', cells[1]))
    return names


def exam_node_parameters():
    source = read(os.path.join(REPO, 'exam', 'src', 'exam', 'node.py'))
    names = set(re.findall(r"_param\('(\w+)'", source))
    lifecycle = read(os.path.join(REPO, 'node_kit', 'src', 'node_kit', 'lifecycle.py'))
    return names | set(re.findall(r"get_param\('~(\w+)'", lifecycle))


def test_the_exam_nodes_parameters_are_all_in_architecture_and_readme():
    expected = exam_node_parameters()
    assert {'threshold', 'delay', 'diagnostic_period'} <= expected
    assert table_parameters(read(ARCHITECTURE), {'exam', 'every node'}) >= expected
    assert table_parameters(read(README), {'exam', 'every node'}) >= expected


def test_the_parameter_table_check_catches_a_missing_row():
    text = '| exam | `~threshold` | m | 1300 | limit |\n| mydrone | `~seed` | | 0 | seed |'
    assert table_parameters(text, {'exam'}) == {'threshold'}


def launch_arguments(path):
    return {arg.get('name'): arg.get('default') for arg in ET.parse(path).getroot().iter('arg')}


def test_the_launch_arguments_quoted_in_architecture_are_the_files():
    text = read(ARCHITECTURE)
    declared = launch_arguments(os.path.join(REPO, 'exam', 'launch', 'exam.launch'))
    sentence = re.search(r'`exam/launch/exam\.launch` has (.*?);', text, re.S).group(1)
    quoted = dict(re.findall(r'`(\w+)` \(`?([\w.]+)`?\)', sentence))
    assert quoted == declared


# --- console excerpts ------------------------------------------------------------------------------

def console_block_problems(text):
    """What is wrong with the console block of lab/report/console_excerpt.py in a document: [] when it
    is whole (lines A to B, B - A + 1 lines, unedited: nothing cut with "..."), dated and at a commit."""
    begin = text.find('<!-- console: written by lab/report/console_excerpt.py')
    end = text.find('<!-- end of console -->')
    if begin < 0 or end < begin:
        return ['no console block between its markers']
    block = text[begin:end]
    head = re.search(r'Lines (\d+) to (\d+) of the launch\'s console, unedited, in the run of '
                     r'(\d{4}-\d\d-\d\d \d\d:\d\d UTC) at commit ([0-9a-f]{7,40})', block)
    if head is None:
        return ['the block does not say which lines, which run and which commit']
    lines = block.split('```')[1].strip('\n').splitlines() if block.count('```') >= 2 else []
    problems = []
    if len(lines) != int(head.group(2)) - int(head.group(1)) + 1:
        problems.append('lines %s to %s are %d lines, the block shows %d'
                        % (head.group(1), head.group(2), int(head.group(2)) - int(head.group(1)) + 1, len(lines)))
    problems += ['a line is cut: %s' % line for line in lines if line.rstrip().endswith('...')]
    problems += ['not a log line: %s' % line for line in lines if not re.match(r'\[(INFO|WARN|ERROR)\] \[\d+\.\d+\]: ', line)]
    return problems


def test_the_master_restart_console_is_a_whole_run_of_its_test():
    assert console_block_problems(read(os.path.join(REPO, 'docs', 'operations.md'))) == []


def test_the_console_check_catches_a_cut_or_typed_excerpt():
    head = ("<!-- console: written by lab/report/console_excerpt.py x -->\nLines 3 to 4 of the launch's console, "
            "unedited, in the run of 2026-11-26 18:22 UTC at commit 08d9b3cb88dd:\n\n```\n")
    whole = head + '[INFO] [1.5]: a\n[WARN] [2.5]: b\n```\n<!-- end of console -->'
    assert console_block_problems(whole) == []
    assert console_block_problems(whole.replace('[WARN] [2.5]: b', '[WARN] [2.5]: b; ...')) == [
        'a line is cut: [WARN] [2.5]: b; ...']
    assert len(console_block_problems(whole.replace('[INFO] [1.5]: a\n', ''))) == 1
    assert console_block_problems('no block') == ['no console block between its markers']


# --- the PDF a student copies from -----------------------------------------------------------------

#: DejaVu Sans Mono's advance width, in em (1233 of 2048 units): every character of a code line.
MONO_EM = 1233 / 2048.0
#: A CSS px in pt.
PX = 0.75


def code_columns(css):
    """How many characters of a code line fit across an answer box of the PDF, from report.css: the
    A4 page less its margins, the block quote's border and padding, the box's padding and border."""
    def number(pattern):
        return float(re.search(pattern, css, re.S).group(1))
    margins = re.search(r'@page \{ size: A4; margin: [\d.]+mm ([\d.]+)mm [\d.]+mm ([\d.]+)mm', css).groups()
    width_pt = (210.0 - float(margins[0]) - float(margins[1])) / 25.4 * 72.0
    quote = number(r'blockquote \{ border-left: (\d+)px') + 2 * number(r'blockquote \{[^}]*padding: \d+px (\d+)px')
    box = 2 * number(r'\npre \{[^}]*padding: \d+px (\d+)px') + 2 * number(r'\npre \{[^}]*border: (\d+)px')
    font = number(r'pre code \{ font-size: ([\d.]+)pt')
    return int((width_pt - (quote + box) * PX) / (font * MONO_EM))


def code_lines(markdown):
    """Every line of the code fences (python, xml, cmake) of a Markdown text, quote marks removed."""
    lines, language = [], None
    for line in markdown.splitlines():
        bare = re.sub(r'^(> ?)+', '', line)
        fence = re.match(r'```(\w*)', bare)
        if fence:
            language = None if language is not None else fence.group(1)
            continue
        if language in ('python', 'xml', 'cmake'):
            lines.append(bare)
    return lines


def test_no_code_line_of_the_report_is_wider_than_its_box():
    css = read(os.path.join(REPO, 'lab', 'report', 'report.css'))
    assert re.search(r'pre\.python[^{]*\{ white-space: pre;', css), 'report.css wraps code'
    columns = code_columns(css)
    assert 100 <= columns <= 200, columns
    report = read(os.path.join(REPO, 'docs', 'report.md'))
    wide = [line for line in code_lines(report) if len(line) > columns]
    assert wide == [], '%d code lines wider than the %d columns of a box' % (len(wide), columns)


def test_no_code_is_set_side_by_side():
    # A code box in a half-width column wraps: render.py stacks the two sheets' code.
    report = read(os.path.join(REPO, 'docs', 'report.md'))
    for cell in re.findall(r'<td>(.*?)</td>', report, re.S):
        assert not re.search(r'```(python|xml|cmake)', cell), cell[:200]


def test_the_code_width_check_catches_a_long_line():
    assert code_lines('> ```python\n> x = 1\n> ```\n```console\n$ y\n```') == ['x = 1']
    assert code_columns(read(os.path.join(REPO, 'lab', 'report', 'report.css'))) < len('#' * 200)


def test_the_report_prints_the_whole_simple_answer():
    report = read(os.path.join(REPO, 'docs', 'report.md'))
    appendix = report[report.index('## E. The simple answer, whole'):]
    for path in ('package.xml', 'CMakeLists.txt', 'scripts/exam_node.py', 'scripts/exam_submarine_node.py',
                 'launch/exam.launch', 'launch/exam_submarine.launch'):
        body = read(os.path.join(REPO, 'docs', 'simple_answer', 'exam', path)).rstrip()
        assert body in appendix, path

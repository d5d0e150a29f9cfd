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
import sys
import xml.etree.ElementTree as ET

import pytest

from exam_lab.grader import class_run, runner
from exam_lab.grader.host import boxed_run
from exam_lab.grader.publish import provenance

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
sys.path.insert(0, os.path.join(REPO, 'lab', 'report'))

import calibration  # noqa: E402  (lab/report is a script folder, not a package)
import screenshots  # noqa: E402

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
    for wall, cpu, memory in (boxed_run.INSPECT_BOUNDS, boxed_run.INTAKE_BOUNDS, boxed_run.SIMILARITY_BOUNDS):
        expected += [seconds(wall), seconds(cpu), gigabytes(memory)]
    assert bounds_quoted(prose(read(GRADING))) == tuple(expected)


def test_the_bounds_check_catches_a_stale_value():
    text = ('inspection: 60 s wall, 60 s CPU, 1 GB address space; a class archive\'s intake: 300 s, 300 s, 1 GB; '
            'similarity: 900 s, 300 s per process, 2 GB')
    assert bounds_quoted(text)[-1] == '2 GB'


def probe_waits_quoted(text):
    """The probe's waits for the node as the Isolation step lists them: (roslaunch's start, the
    registration, the second input, an input's connection or refusal, a re-typed input's first try, its
    bound, the output publisher), or None."""
    match = re.search(r"roslaunch's own start on the master \(([\d.]+) s\), the node's registration \(([\d.]+) s "
                      r"from then\), its second input's subscription \(([\d.]+) s\), each input's connection or "
                      r"rospy's refusal of it \(([\d.]+) s\), an input re-typed for the node \(registered anew "
                      r"until it connects, each try twice as long as the last from ([\d.]+) s, ([\d.]+) s in all\), "
                      r"its output publisher \(([\d.]+) s\)", text)
    return match.groups() if match else None


def expected_probe_waits():
    pytest.importorskip('rospy')
    from exam_lab.grader.judge import node
    return tuple(seconds(v) for v in (node.LAUNCH_START_S, runner.START_TIMEOUT, node.SUBSCRIBE_S, node.SETTLE_S,
                                      node.RETYPE_S, node.ADAPT_S, node.OUTPUT_S))


def test_grading_quotes_the_probes_waits_for_the_node():
    assert probe_waits_quoted(prose(read(GRADING))) == expected_probe_waits()


def test_the_probe_waits_check_catches_a_stale_bound():
    text = ("roslaunch's own start on the master (60 s), the node's registration (20 s from then), its second "
            "input's subscription (6 s), each input's connection or rospy's refusal of it (3 s), an input re-typed "
            "for the node (registered anew until it connects, each try twice as long as the last from 1 s, 15 s "
            "in all), its output publisher (3 s)")
    assert probe_waits_quoted(text)[3] == '3' != expected_probe_waits()[3]


def test_default_jobs_is_quoted_as_the_code_computes_it():
    # The docs quote default_jobs's measured CPU of a grading and its share of the cores.
    text = prose(read(GRADING) + read(os.path.join(REPO, 'docs', 'benchmarks.md')))
    said = '%g %% of the cores at the CPU one grading was measured to take, %g s in %g s' % (
        class_run.CPU_SHARE * 100, class_run.GRADING_CPU_S, class_run.GRADING_WALL_S)
    assert said in text, said
    quoted = re.findall(r'`JOBS=(\d+)`?,? the default', text) + re.findall(r'the default JOBS=(\d+)', text)
    assert all(int(q) == class_run.default_jobs(cores=2, memory=24 << 30) for q in quoted), quoted


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


# --- the page figures -----------------------------------------------------------------------------

def test_the_feedback_figure_is_a_screenshot_of_the_example_page_beside_it():
    """docs/figures/feedback_page.png is taken of docs/feedback_example.html by grading_examples.py."""
    assert screenshots.tag(screenshots.FEEDBACK_PNG) == screenshots.digest(
        os.path.join(REPO, 'docs', 'feedback_example.html')), (
        'docs/figures/feedback_page.png is not of docs/feedback_example.html: run lab/report/grading_examples.py')


def test_the_class_page_figure_was_taken_with_todays_page_code():
    assert screenshots.tag(screenshots.PAGE_PNG) == screenshots.page_code_digest(), (
        'the code that draws the class page changed since docs/figures/grader_page.png was taken: '
        'GRADER_PAGE_SCREENSHOT=docs/figures/grader_page.png python3 -m pytest lab/test/grader/test_page_browser.py')


def test_the_figure_tag_check_catches_an_untagged_and_a_retagged_png(tmp_path):
    with open(screenshots.PAGE_PNG, 'rb') as f:
        data = f.read()
    plain = tmp_path / 'plain.png'
    plain.write_bytes(data.replace(screenshots.KEY, b'other-sourcekey'))
    assert screenshots.tag(str(plain)) is None
    other = tmp_path / 'other.png'
    other.write_bytes(screenshots.tagged(plain.read_bytes(), 'a stale digest'))
    assert screenshots.tag(str(other)) == 'a stale digest' != screenshots.page_code_digest()


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


@pytest.mark.parametrize('folder', ['boxed', 'judge'])
def test_the_isolation_table_names_every_module_of(folder):
    rows = isolation_rows(read(GRADING))
    assert rows.get(folder) == grader_folders()[folder]


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
    appendix = report[report.index('## D. The simple answer, whole'):report.index("## E. This project's node")]
    for path in ('package.xml', 'CMakeLists.txt', 'scripts/exam_node.py', 'scripts/exam_submarine_node.py',
                 'launch/exam.launch', 'launch/exam_submarine.launch'):
        body = read(os.path.join(REPO, 'docs', 'simple_answer', 'exam', path)).rstrip()
        assert body in appendix, path


# --- the benchmarks' hand-written analysis ---------------------------------------------------------

BENCH = os.path.join(REPO, 'lab', 'bench')


def bench_results():
    import json
    with open(os.path.join(BENCH, 'results.json')) as f:
        return json.load(f)


def per_node_cpu_quoted(text):
    """(low, high, cpu of 20, each of 20, cpu of 100, each of 100) of "CPU at L to H % of a core per exam
    node (A % for 20: a % each; B % for 100: b % each)"."""
    found = re.search(r'CPU at ([\d.]+) to ([\d.]+) % of a core per exam node \(([\d.]+) % for 20: ([\d.]+) % '
                      r'each; ([\d.]+) % for 100: ([\d.]+) % each\)', text)
    return found.groups() if found else None


def per_node_cpu_expected(results):
    fleet = results['ours']['fleet']
    twenty, hundred = fleet['20']['cpu_percent']['exam'], fleet['100']['cpu_percent']['exam']
    each = sorted([twenty / 20, hundred / 100])
    return ('%.2f' % each[0], '%.2f' % each[1], '%.1f' % twenty, '%.2f' % (twenty / 20), '%.1f' % hundred,
            '%.2f' % (hundred / 100))


def test_the_analysis_per_node_cpu_is_the_fleet_tables_divided():
    quoted = per_node_cpu_quoted(prose(read(os.path.join(BENCH, 'analysis.md'))))
    assert quoted is not None, 'lab/bench/analysis.md no longer says "CPU at L to H % of a core per exam node (...)"'
    assert quoted == per_node_cpu_expected(bench_results())


def test_the_per_node_cpu_check_catches_a_rounded_range():
    stale = 'CPU at 0.5 to 0.6 % of a core per exam node (11.7 % for 20: 0.6 % each; 48.1 % for 100: 0.5 % each)'
    assert per_node_cpu_quoted(stale) != per_node_cpu_expected(bench_results())


def history_figures_quoted(text):
    """[(file, [figures])] of every "a / b / c / d (`fleet-master-*.json`)" of a text."""
    return [(name, figures.split(' / ')) for figures, name in
            re.findall(r'((?:[\d.]+ / )+[\d.]+)\*{0,2} \(`(fleet-master-[\w-]+\.json)`\)', text)]


def history_master_cpu(name):
    import json
    with open(os.path.join(BENCH, 'history', name)) as f:
        fleet = json.load(f)['ours']['fleet']
    return ['%.1f' % fleet[n]['master_cpu_percent'] for n in sorted(fleet, key=int)]


def test_the_masters_cpu_figures_are_their_history_files():
    quoted = history_figures_quoted(prose(read(os.path.join(BENCH, 'analysis.md'))))
    assert len(quoted) >= 4, quoted
    for name, figures in quoted:
        assert figures == history_master_cpu(name), name


def test_the_history_check_catches_a_figure_of_another_file():
    swapped = '0.4 / 1.0 / 1.5 / 3.2 (`fleet-master-0551.json`)'
    (name, figures), = history_figures_quoted(swapped)
    assert figures != history_master_cpu(name)


def test_the_analysis_explains_the_delay_the_latency_stage_used():
    delay = bench_results()['config']['delay']
    text = prose(read(os.path.join(BENCH, 'analysis.md')))
    quoted = re.findall(r"with the stage's `~delay` of ([\d.]+) s it counts `delay_ticks` = (\d+) ticks", text)
    assert quoted == [('%g' % delay, '%d' % round(delay * 10))], quoted


# --- the grader's speed, quoted from the benchmark's grader section --------------------------------

def grader_bench_quoted(section):
    """What lab/bench/grader.md measured: {'date', 'commit', 'alone': (n, wall, low, high, cpu),
    'classes': {jobs: (students, wall)}, 'packages': {name: seconds}}."""
    head = re.search(r'on (\d{4}-\d\d-\d\d \d\d:\d\d) \(UTC\).*? at commit ([0-9a-f]+)', section)
    alone = re.search(r'\| each of (\d+) packages alone \(JOBS=1\) \| (\d+) s \| (\d+)-(\d+) s \| (\d+) s \|', section)
    return {'date': head.group(1), 'commit': head.group(2), 'alone': alone.groups(),
            'classes': {jobs: (n, wall) for n, jobs, wall in
                        re.findall(r'^\| class of (\d+), JOBS=(\d+) \| (\d+) s \|', section, re.M)},
            'packages': dict(re.findall(r'^\| (\w+) \| [\d.]+ \| (\d+) s \|$', section, re.M))}


def speed_problems(speed, measured):
    """What the Speed paragraph of docs/grading.md says that the grader section did not measure."""
    problems = []
    for name, seconds in re.findall(r'`(\w+)`: (\d+) s', speed):
        if measured['packages'].get(name) != seconds:
            problems.append('%s: %s s quoted, %s s measured' % (name, seconds, measured['packages'].get(name)))
    run = re.search(r'on (\d{4}-\d\d-\d\d \d\d:\d\d) UTC \(commit ([0-9a-f]+)\)', speed)
    if run is None or run.groups() != (measured['date'], measured['commit']):
        problems.append('the run quoted is not the grader section\'s (%s at %s)' % (measured['date'], measured['commit']))
    alone = re.search(r'the (\d+) packages of that day .*? took (\d+) to (\d+) s each \((\d+) s in all; (\d+) s of CPU', speed)
    n, wall, low, high, cpu = measured['alone']
    if alone is None or alone.groups() != (n, low, high, wall, cpu):
        problems.append('the packages graded alone: %s' % (alone.groups() if alone else 'not quoted'))
    classes = re.findall(r'(\d+) s (?:\([\d.]+ minutes\) )?with `JOBS=(\d+)`', speed)
    if not classes or any(measured['classes'].get(jobs, (None, None))[1] != wall for wall, jobs in classes):
        problems.append('the classes: %s quoted, %s measured' % (classes, measured['classes']))
    for wall, minutes, jobs in re.findall(r'(\d+) s \(([\d.]+) minutes\) with `JOBS=(\d+)`', speed):
        if '%.1f' % (int(wall) / 60.0) != minutes:
            problems.append('%s s is not %s minutes' % (wall, minutes))
    return problems


def speed_paragraph():
    text = prose(read(GRADING))
    return text[text.index('## Speed'):text.index('The sandbox costs nothing')]


def test_the_speed_paragraph_quotes_the_benchmarks_grader_section():
    measured = grader_bench_quoted(read(os.path.join(BENCH, 'grader.md')))
    assert len(measured['packages']) == int(measured['alone'][0])
    speed = speed_paragraph()
    assert len(re.findall(r'`(\w+)`: (\d+) s', speed)) >= 5
    assert speed_problems(speed, measured) == []


def test_the_speed_check_catches_a_typed_time():
    """Each kind of figure, typed one off from what the grader section measured, is caught."""
    measured = grader_bench_quoted(read(os.path.join(BENCH, 'grader.md')))
    speed = speed_paragraph()
    late = measured['packages']['late_warning']
    typed = '`late_warning`: %d s' % (int(late) + 2)
    assert speed_problems(speed.replace('`late_warning`: %s s' % late, typed), measured) == [
        'late_warning: %d s quoted, %s s measured' % (int(late) + 2, late)]
    for jobs, (_, wall) in measured['classes'].items():
        quoted = re.search(r'%s s (\([\d.]+ minutes\) )?with `JOBS=%s`' % (wall, jobs), speed)
        assert quoted, 'the class at JOBS=%s is not quoted' % jobs
        assert len(speed_problems(speed.replace(quoted.group(0), quoted.group(0).replace(wall, str(int(wall) + 5), 1)),
                                  measured)) >= 1
        if quoted.group(1):
            minutes = quoted.group(1)[1:].split()[0]
            rounded = speed.replace(quoted.group(1), '(%.1f minutes) ' % (float(minutes) + 0.1))
            assert len(speed_problems(rounded, measured)) == 1


# --- the test packages' table ----------------------------------------------------------------------

SUBMISSIONS = os.path.join(REPO, 'lab', 'test', 'grader', 'submissions')


def package_table_rows(text):
    """The packages named by the first cell of the rows of the test-package tables of docs/grading.md's
    Tests section ("| `no_kelvin` | ..." or "| `wrong_topic` (depth) | ..."); rows made by the test from
    another package ("made from") are not folders and are left out."""
    tests = text[text.index('\n## Tests'):]
    tests = tests[:tests.index('\n## ', 1)]
    names = []
    for line in tests.splitlines():
        cell = re.match(r'^\| `(\w+)`([^|]*)\|', line)
        if cell and 'made from' not in cell.group(2):
            names.append(cell.group(1))
    return names


def test_every_test_package_has_a_row_and_every_row_a_package():
    folders = sorted(d for d in os.listdir(SUBMISSIONS) if os.path.isdir(os.path.join(SUBMISSIONS, d)))
    rows = package_table_rows(read(GRADING))
    assert len(rows) == len(set(rows)), 'a package has two rows'
    assert sorted(rows) == folders, ('no row for %s; a row without a folder: %s'
                                     % (sorted(set(folders) - set(rows)), sorted(set(rows) - set(folders))))


def test_the_package_table_check_catches_a_missing_row():
    text = ('\n## Tests\n\n| package | flaw |\n|---|---|\n| `no_kelvin` | degC |\n| `wrong_topic` (depth) | x |\n'
            '| `windows_zip` (made from `good_student`) | CRLF |\n\n## Determinism\n| `not_here` | x |\n')
    assert package_table_rows(text) == ['no_kelvin', 'wrong_topic']


def grade_test_expectations():
    """{package: its total} of lab/test/grader/test_grade.py's EXPECTED and FAIR_EXPECTED (the tested
    truth): full marks less what each package loses."""
    module = calibration.load_expectations()
    totals = {}
    for expected in (module.EXPECTED, module.FAIR_EXPECTED):
        for name, points in expected.items():
            totals[name] = sum(dict(module.FULL, **points).values())
    return totals


def package_table_points(text):
    """{package: points} of the test-package tables' rows."""
    tests = text[text.index('\n## Tests'):]
    tests = tests[:tests.index('\n## ', 1)]
    return {name: float(points) for name, points in
            re.findall(r'^\| `(\w+)`[^|]*\|[^|]*\| ([\d.]+) \|', tests, re.M)}


def test_the_package_tables_points_are_the_grader_tests_expectations():
    totals = grade_test_expectations()
    quoted = package_table_points(read(GRADING))
    assert set(quoted) <= set(totals), set(quoted) - set(totals)
    assert {name: totals[name] for name in quoted} == quoted


def test_the_points_check_catches_a_typed_total():
    totals = grade_test_expectations()
    assert package_table_points('\n## Tests\n| `no_kelvin` | degC | 15 | Q11 |\n\n## Next\n') == {'no_kelvin': 15.0}
    assert totals['no_kelvin'] == 15.5


# --- outputs the docs quote, made again by the code that prints them --------------------------------

def quoted_output(pattern, text=None):
    """The one output of docs/grading.md that ``pattern`` finds (its first group), line breaks folded."""
    found = re.findall(pattern, prose(read(GRADING)) if text is None else text)
    assert len(found) == 1, 'docs/grading.md no longer quotes %r once: %s' % (pattern, found)
    return found[0]


def no_grade_yet_problems(text=None):
    """The line make grade prints before any hand point is given, as docs/grading.md quotes it."""
    from exam_lab.grader.publish import moodle
    quote = quoted_output(r'`(worksheet: no whole grade yet[^`]+)`', text)
    lines = moodle.summary_lines({'graded': [], 'maxima': [], 'kept': [], 'unmatched': [], 'no_submission': []},
                                 moodle.UPLOAD)
    return [] if quote in lines else ['not printed: %s' % quote]


def test_the_no_grade_yet_line_is_the_worksheets():
    assert no_grade_yet_problems() == []


def test_the_no_grade_yet_check_catches_a_reworded_line():
    text = prose(read(GRADING)).replace('alone are no grade', 'are no grade')
    assert len(no_grade_yet_problems(text)) == 1


def synthetic_grade(total_before=None):
    from exam_lab.grader.publish import report
    from exam_lab.grader.score.sheets import ITEMS
    record = report.grade_record('late', 'altitude', [{'id': i, 'points': p, 'max': p, 'evidence': 'ok'}
                                                      for i, (p, _) in ITEMS.items()], [])
    if total_before is not None:
        record = dict(record, provenance={'how': 'rescore', 'grader': 'abc', 'rubric': 'def', 'machine': 'vm', 'date': 'd'},
                      previous={'total': total_before, 'status': 'graded'})
    return record


def feedback_problems(text=None):
    import html
    from exam_lab.grader.publish import hand, moodle
    quote = quoted_output(r'\("(The grade is these points scaled to [^"]+)"\)', text)
    maximum = float(re.search(r'scaled to ([\d.]+)', quote).group(1))
    whole = hand.combine(synthetic_grade(), None)
    return [] if quote in html.unescape(moodle.feedback(whole, maximum=maximum)) else [
        'not in the feedback comment: %s' % quote]


def test_the_feedback_comment_quoted_is_moodles():
    assert feedback_problems() == []


def test_the_feedback_check_catches_a_reworded_comment():
    text = prose(read(GRADING)).replace("scaled to 20 (x 20/30)", "scaled to 20 (x 20/17)")
    assert len(feedback_problems(text)) == 1


def rescored_problems(text=None):
    from exam_lab.grader.publish import report
    quote = quoted_output(r'\("Rescored \.\.\. (Before: [^"]+)"\)', text)
    before = float(re.match(r'Before: ([\d.]+)', quote).group(1))
    line = [l for l in report.markdown(synthetic_grade(before)).splitlines() if l.startswith('Rescored')]
    return [] if line and quote in line[0] else ['grade.md does not say %r: %s' % (quote, line)]


def test_the_rescored_line_is_grade_mds():
    assert rescored_problems() == []


def test_the_rescored_check_catches_a_typed_line():
    assert len(rescored_problems(prose(read(GRADING)).replace('Before: 15.5 / 17', 'Before: 15.5 of 17'))) == 1


def format_literal(path, literal):
    """``literal`` (a format string) as the code has it, or a failure naming where it was looked for."""
    assert literal in read(os.path.join(REPO, path)), '%s no longer formats its line with %s' % (path, literal)
    return literal


def rescore_change_problems(text=None):
    """The rescore's line quoted (``late: 17 -> 15.5 (Q14b 3 -> 1.5)``) against grades.rescore's
    two formats, and its arithmetic: the total moves by what the items moved."""
    quote = quoted_output(r'`(\w+: [\d.]+ -> [\d.]+ \([^`]*\))`', text)
    line = format_literal('lab/src/exam_lab/grader/publish/grades.py', "'%s: %s -> %s (%s)'").strip("'")
    item = format_literal('lab/src/exam_lab/grader/publish/grades.py', "'%s %s -> %s'").strip("'")
    student, old, new, moved = re.match(r'(\w+): ([\d.]+) -> ([\d.]+) \((.*)\)$', quote).groups()
    items = [re.match(r'(\w+) ([\d.]+) -> ([\d.]+)$', m).groups() for m in moved.split('; ')]
    problems = []
    if line % (student, old, new, '; '.join(item % i for i in items)) != quote:
        problems.append('not the runner\'s form: %s' % quote)
    if abs((float(new) - float(old)) - sum(float(b) - float(a) for _, a, b in items)) > 1e-9:
        problems.append('the total moves by %s, its items by another amount' % quote)
    return problems


def test_the_rescore_change_line_is_the_runners():
    assert rescore_change_problems() == []


def test_the_rescore_change_check_catches_wrong_arithmetic():
    text = prose(read(GRADING)).replace('Q14b 3 -> 1.5', 'Q14b 3 -> 2')
    assert rescore_change_problems(text) == ['the total moves by late: 17 -> 15.5 (Q14b 3 -> 2), its items by another amount']


def missing_hand_points_problems(text=None):
    """The worksheet's line for a student without all hand points (``Paul Martin (hand points not
    given yet in hand.csv: Q5, Q6, ...)``): publish/moodle.py's format, hand items of score/sheets.py
    in their order."""
    from exam_lab.grader.score.sheets import HAND_ITEMS
    format_literal('lab/src/exam_lab/grader/publish/moodle.py', "'  left blank in %s: %s (%s)'")
    literal = format_literal('lab/src/exam_lab/grader/publish/moodle.py', "'hand points not given yet in hand.csv: %s'")
    quote = quoted_output(r'`([A-Z][\w ]+ \(hand points not given yet in hand\.csv: (?:\w+, )+\.\.\.\))`', text)
    if literal.strip("'").split('%s')[0] not in quote:
        return ['not the worksheet\'s words: %s' % quote]
    named = quote.split(': ', 1)[1].rstrip(')').split(', ')[:-1]
    if not named or not set(named) <= set(HAND_ITEMS):
        return ['not hand items: %s' % named]
    return [] if named == [i for i in HAND_ITEMS if i in named] else ['not in the order the worksheet lists them']


def test_the_worksheets_missing_hand_points_line_is_the_scripts():
    assert missing_hand_points_problems() == []


def test_the_missing_hand_points_check_catches_a_wrong_item():
    assert missing_hand_points_problems(prose(read(GRADING)).replace('Q5, Q6, ...', 'Q11, Q6, ...')) == [
        "not hand items: ['Q11', 'Q6']"]
    assert missing_hand_points_problems(prose(read(GRADING)).replace('Q5, Q6, ...', 'Q6, Q5, ...')) == [
        'not in the order the worksheet lists them']


def slurm_problems(text=None):
    from exam_lab.grader.publish import grades
    from exam_lab.grader.engine import slurm
    problems = []
    state = quoted_output(r'`(slurm job [^`]+)`', text)
    counts = re.match(r'slurm job (\d+): (\d+) pending, (\d+) running, (\d+) done of (\d+)$', state)
    if counts is None:
        return ['not the engine\'s state line: %s' % state]
    job, pending, running, done, total = counts.groups()
    tasks = dict(enumerate([('PENDING', 0)] * int(pending) + [('RUNNING', 0)] * int(running)))
    if slurm.state_line([job], tasks, int(done), 0, int(total)) != state:
        problems.append('not the engine\'s state line: %s' % state)
    said = quoted_output(r'`(could not grade: Slurm said: [^`]+)`', text)
    words = re.match(r'could not grade: Slurm said: (\w+)(?: on node ([\w.-]+))?, exit code ([\d:]+)$', said)
    if words is None:
        return problems + ['not the engine\'s reason: %s' % said]
    fields = {'JobState': words.group(1), 'NodeList': words.group(2) or '(null)', 'ExitCode': words.group(3)}
    reason = grades.could_not_grade('x', 'altitude', 'Slurm said: %s' % slurm.slurm_said(fields))['status_reason']
    if reason != said:
        problems.append('not the engine\'s reason: %s (it says %s)' % (said, reason))
    return problems


def test_the_slurm_lines_quoted_are_the_engines():
    assert slurm_problems() == []


def test_the_slurm_check_catches_a_typed_line():
    text = prose(read(GRADING)).replace('0 done of 3', '0 of 3 done')
    assert len(slurm_problems(text)) == 1


# --- the teacher's quick start and its calibration table -------------------------------------------

def calibration_block(text):
    begin, end = text.find(calibration.BEGIN), text.find(calibration.END)
    assert 0 <= begin < end, 'docs/grading.md has no calibration block between its markers'
    return text[begin:end + len(calibration.END)]


def test_the_calibration_table_is_the_grader_tests_truth():
    assert calibration_block(read(GRADING)) == calibration.block(), 'run python3 lab/report/calibration.py'


def test_the_calibration_check_catches_a_typed_point_and_a_package_left_out():
    block = calibration.block()
    assert calibration_block(block.replace('15.5 / 17 (Q11 1.5)', '16 / 17 (Q11 1)')) != block
    tested = calibration.load_expectations()
    tested.EXPECTED = dict(tested.EXPECTED, new_mistake={'Q10': 1.0})
    with pytest.raises(ValueError, match='new_mistake'):
        calibration.rows(tested)


def class_of_60_problems(quick):
    """What the quick start's "a class of 60 took N s (M minutes) at the default JOBS=J ... run of DATE"
    says that the benchmark's grader section did not measure."""
    measured = grader_bench_quoted(read(os.path.join(BENCH, 'grader.md')))
    default = str(class_run.default_jobs(cores=2, memory=24 << 30))
    wall = measured['classes'][default][1]
    quoted = re.search(r'a class of 60 took (\d+) s \(([\d.]+) minutes\) at the default JOBS=(\d+) .*?run of '
                       r'(\d{4}-\d\d-\d\d \d\d:\d\d) UTC', quick)
    if quoted is None:
        return ['the quick start no longer quotes the class of 60']
    expected = (wall, '%.1f' % (int(wall) / 60.0), default, measured['date'])
    return [] if quoted.groups() == expected else ['%s quoted, %s measured' % (quoted.groups(), expected)]


def quick_start():
    text = read(GRADING)
    first = re.findall(r'^## .*$', text, re.M)[0]
    assert first == "## A teacher's quick start", 'the quick start does not open docs/grading.md'
    return prose(text[text.index(first):text.index(calibration.BEGIN)])


def test_the_quick_start_opens_the_page_and_quotes_the_class_of_60():
    quick = quick_start()
    assert class_of_60_problems(quick) == []
    for status in ('graded', 'graded with fixes', 'needs a hand grade', 'not graded'):
        assert '| `%s` |' % status in quick


def test_the_class_of_60_check_catches_a_rounded_time():
    quick = quick_start()
    wall, minutes = re.search(r'a class of 60 took (\d+) s \(([\d.]+) minutes\)', quick).groups()
    rounded = quick.replace('%s s (%s minutes)' % (wall, minutes), '%s s (%.0f minutes)' % (wall, float(minutes)))
    assert len(class_of_60_problems(rounded)) == 1
    date = grader_bench_quoted(read(os.path.join(BENCH, 'grader.md')))['date']
    assert len(class_of_60_problems(quick.replace(date, '2026-01-01 00:00'))) == 1


# --- README's make run timings ---------------------------------------------------------------------

def run_timing_problems(readme, banner_script):
    """What is wrong with README's block of lab/report/run_timing.py: [] when it is there, dated, at a
    commit of this repository, and its times keep the banner's promises (tools/run_launch.sh: "RED
    about N s from now, GREEN again about M s later") within 5 s."""
    import subprocess
    import run_timing
    begin, end = readme.find(run_timing.BEGIN), readme.find(run_timing.END)
    if not 0 <= begin < end:
        return ['no run timing block between its markers']
    found = re.search(r'on (\d{4}-\d\d-\d\d \d\d:\d\d) UTC at commit ([0-9a-f]{7,40})(\+changes)?: `data: "RED"` '
                      r'([\d.]+) s after that banner, `data: "GREEN"` ([\d.]+) s after it\..*?RED ([\d.]+) s, GREEN '
                      r'([\d.]+) s after the banner', prose(readme[begin:end]))
    if found is None:
        return ['the block does not say which run, which commit and both launches\' times']
    problems = []
    if subprocess.run(['git', '-C', REPO, 'cat-file', '-e', found.group(2) + '^{commit}'],
                      stderr=subprocess.DEVNULL).returncode != 0:
        problems.append('commit %s is not in this repository' % found.group(2))
    red_in, green_after = (float(x) for x in re.search(r'RED about (\d+) s from now, GREEN again about (\d+) s later',
                                                       banner_script).groups())
    for red, green in ((found.group(4), found.group(5)), (found.group(6), found.group(7))):
        if abs(float(red) - red_in) > 5 or abs(float(green) - float(red) - green_after) > 5:
            problems.append('the banner promises RED about %g s, GREEN %g s later; measured %s and %s'
                            % (red_in, green_after, red, green))
    return problems


def test_readmes_run_timings_are_a_dated_run_keeping_the_banners_promises():
    banner = read(os.path.join(REPO, 'tools', 'run_launch.sh'))
    assert run_timing_problems(read(README), banner) == []


def test_the_run_timing_check_catches_a_broken_promise():
    readme, banner = read(README), read(os.path.join(REPO, 'tools', 'run_launch.sh'))
    assert len(run_timing_problems(readme, banner.replace('RED about 50 s', 'RED about 40 s'))) == 2
    assert run_timing_problems(readme.replace('at commit ', 'at commit 0000000'), banner) != []


def rendered_benchmarks(analysis=None):
    """docs/benchmarks.md as `BENCH_RENDER_ONLY=1 make bench` renders it from lab/bench/results.json,
    lab/bench/analysis.md and lab/bench/grader.md (lab/bench/report.py; nothing measured)."""
    sys.path.insert(0, BENCH)
    import report
    results = bench_results()
    results['analysis'] = read(os.path.join(BENCH, 'analysis.md')) if analysis is None else analysis
    return report.render(results, os.path.join('figures', 'bench_fleet.png'))


def test_benchmarks_md_is_the_render_of_its_results_never_edited_by_hand():
    assert read(os.path.join(REPO, 'docs', 'benchmarks.md')) == rendered_benchmarks(), (
        'docs/benchmarks.md differs from its sources: edit lab/bench/analysis.md or report.py, then '
        'BENCH_RENDER_ONLY=1 make bench')


def test_the_render_check_catches_an_edit():
    analysis = read(os.path.join(BENCH, 'analysis.md'))
    low, high = per_node_cpu_quoted(prose(analysis))[:2]
    edited = analysis.replace('%s to %s' % (low, high), '%s to %s' % (high, low), 1)
    assert edited != analysis
    assert rendered_benchmarks(edited) != read(os.path.join(REPO, 'docs', 'benchmarks.md'))


def scripts_not_named(text, folder):
    """The Python files of ``folder`` that ``text`` does not name (as `name.py`)."""
    return sorted(os.path.basename(p) for p in glob.glob(os.path.join(folder, '*.py'))
                  if '`%s`' % os.path.basename(p) not in text)


def test_architecture_names_every_script_of_lab_report():
    assert scripts_not_named(read(ARCHITECTURE), os.path.join(REPO, 'lab', 'report')) == []


def test_the_script_list_check_catches_a_script_left_out():
    text = read(ARCHITECTURE).replace('`run_timing.py`', 'run_timing')
    assert scripts_not_named(text, os.path.join(REPO, 'lab', 'report')) == ['run_timing.py']

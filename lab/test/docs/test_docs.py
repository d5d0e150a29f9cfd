"""The docs against the code: the report's commands still name things that exist, and every parameter
the docs name is one the code reads, with exactly that name.

- The commands are those of lab/report/command_list.py, the list `make report` runs; the template uses
  every one of them, and the committed docs/report.md shows exactly those lines, in the template's order.
- Each command parses (shlex), starts an installed program, and names packages, scripts, launch files
  and launch arguments, nodes, topics, services, message and service types and parameters that exist
  in this repository's code (or in ROS itself, for /rosout and std_msgs).
- Every ``~name`` and ``name:=`` in docs/*.md and README.md is a private parameter (or private topic) the
  code reads, a launch argument, or a topic being remapped.

Run by `make test` (lab/CMakeLists.txt registers it); no ROS master needed.
"""
import glob
import importlib
import os
import re
import shlex
import shutil
import sys
import xml.etree.ElementTree as ET

import pytest
import yaml

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
sys.path.insert(0, os.path.join(REPO, 'lab', 'report'))

import command_list  # noqa: E402  (lab/report is a script folder, not a package)

from mydrone.simulator import SPEC as MYDRONE  # noqa: E402
from submarinedrone.simulator import SPEC as SUBMARINE  # noqa: E402
from exam.modes import MODES  # noqa: E402

TEMPLATE = os.path.join(REPO, 'lab', 'report', 'report_template.md')
REPORT = os.path.join(REPO, 'docs', 'report.md')
PROGRAMS = {'rosnode', 'rostopic', 'rosmsg', 'rossrv', 'rosservice', 'rosparam', 'rosrun', 'roslaunch',
            'rosbag', 'catkin_create_pkg', 'catkin_make'}
#: Node names the launch files give (name="...") and ROS's own logging node.
ROS_TOPICS = {'/rosout', '/rosout_agg'}
#: Private services rospy gives every node (``~get_loggers``), named in the docs like parameters.
ROS_PRIVATE_NAMES = {'get_loggers', 'set_logger_level'}
#: Special arguments every ROS node understands (remapping of its name, namespace, log file...).
SPECIAL_ARGS = {'__name', '__ns', '__log', '__ip', '__hostname', '__master'}
#: How a parameter or launch argument is named in prose: `~threshold`, `threshold:=1500`.
PRIVATE_NAME = re.compile(r'(?<![\w/.])~([A-Za-z_]\w*)')
ASSIGNED_NAME = re.compile(r'(?<![\w/:.-])(/?[A-Za-z_]\w*)(?=:=)')
#: How the code reads a private parameter: rospy.get_param('~x'), _param('x', ...).
READ_PARAM = re.compile(r'\b(?:get_param|_param)\(\s*[\'"]~?(\w+)[\'"]')
#: drone_sim reads one parameter per sensor: _param(sensor.topic + '_rate', ...).
READ_SENSOR_PARAM = re.compile(r'\b_param\(\s*\w+\.topic\s*\+\s*[\'"](\w+)[\'"]')


def code_files():
    """The Python files of the nodes: every package's src/ and scripts/, and the bench nodes."""
    patterns = ['*/src/*/*.py', '*/scripts/*.py', 'lab/bench/*.py']
    return sorted(f for p in patterns for f in glob.glob(os.path.join(REPO, p)))


def read(path):
    with open(path) as f:
        return f.read()


def private_names_in_code():
    """Every private parameter some node reads, the drones' private topics (``~true_altitude``), and the
    private services of every rospy node."""
    names = set(ROS_PRIVATE_NAMES)
    sensor_suffixes = set()
    for path in code_files():
        text = read(path)
        names.update(READ_PARAM.findall(text))
        sensor_suffixes.update(READ_SENSOR_PARAM.findall(text))
    for spec in (MYDRONE, SUBMARINE):
        names.update(sensor.topic + suffix for sensor in spec.sensors for suffix in sensor_suffixes)
        names.add(spec.truth_topic)
    return names


def launch_files():
    return sorted(glob.glob(os.path.join(REPO, '*', 'launch', '*.launch')))


def launch_args(path):
    return {arg.get('name') for arg in ET.parse(path).getroot().iter('arg')}


def launch_node_names():
    names = set()
    for path in launch_files():
        names.update('/' + node.get('name') for node in ET.parse(path).getroot().iter('node'))
    return names


def graph_names():
    """Topics, services and nodes the code creates, as they resolve in the root namespace."""
    names = set(ROS_TOPICS) | launch_node_names()
    for spec in (MYDRONE, SUBMARINE):
        node = '/' + spec.node_name
        names.update([node, node + '/' + spec.truth_topic, '/' + spec.service_name, '/' + spec.led_topic])
        names.update('/' + sensor.topic for sensor in spec.sensors)
    for mode in MODES.values():
        names.update('/' + topic for topic in [mode.output, mode.service, mode.led_topic]
                     + [spec.topic for spec in mode.inputs])
    return names


def unknown_names(text, private_names, args, topics):
    """The ``~name`` and ``name:=`` of ``text`` that no code reads and no launch file declares."""
    unknown = set()
    for name in PRIVATE_NAME.findall(text):
        if name not in private_names:
            unknown.add('~' + name)
    for name in ASSIGNED_NAME.findall(text):
        if name in SPECIAL_ARGS or name in args:
            continue
        if name.startswith('_') and name[1:] in private_names:  # rosrun's _param:=value
            continue
        if name.startswith('/') and name in topics:  # a remapping: /altitude:=/elsewhere
            continue
        unknown.add(name + ':=')
    return unknown


def template_keys():
    """Keys of {{run KEY}} and {{line KEY}} placeholders, in the template's order."""
    return re.findall(r'\{\{(run|line) ([^ }]+)\}\}', read(TEMPLATE))


def argv(command):
    """The command's words, without a leading ``timeout -s INT <s>``."""
    words = shlex.split(command.line)
    if words[0] == 'timeout':
        assert words[1:3] == ['-s', 'INT'] and float(words[3]) > 0, command.line
        words = words[4:]
    return words


def package_dir(name):
    """The folder of the catkin package ``name`` in this repository (lab/ holds exam_lab), or None."""
    for manifest in glob.glob(os.path.join(REPO, '*', 'package.xml')):
        if ET.parse(manifest).getroot().findtext('name') == name:
            return os.path.dirname(manifest)
    return None


# --- the command list and the report ---------------------------------------------------------------

def test_template_uses_every_command_and_only_known_ones():
    used = {key for _, key in template_keys()}
    assert used - set(command_list.BY_KEY) == set(), 'the template names commands that command_list.py does not run'
    assert set(command_list.BY_KEY) - used == set(), 'commands run by make report that the report never shows'


def test_committed_report_shows_exactly_the_commands_of_the_list():
    # A console block holds one command or several (each line that starts with "$ " is a command).
    shown = [line[2:] for block in re.findall(r'```console\n(.*?)```', read(REPORT), re.S)
             for line in block.splitlines() if line.startswith('$ ')]
    expected = [command_list.BY_KEY[key].line for kind, key in template_keys() if kind == 'run']
    assert shown == expected, 'docs/report.md is out of date: run make report'


def test_commands_are_unique_per_key_and_bounded():
    assert len(command_list.BY_KEY) == len(command_list.ALL)
    for command in command_list.FOREGROUND:
        assert command.limit is not None and command.limit > 0, command.key


@pytest.mark.parametrize('command', command_list.ALL, ids=lambda c: c.key)
def test_command_starts_an_installed_ros_program(command):
    words = argv(command)
    assert words[0] in PROGRAMS, command.line
    assert shutil.which(words[0]) is not None, '%s is not installed' % words[0]
    if command.line.startswith('rostopic hz') or command.line.startswith('rostopic echo /'):
        pytest.fail('%s would run forever: bound it with timeout -s INT or -n' % command.line)


@pytest.mark.parametrize('command', command_list.ALL, ids=lambda c: c.key)
def test_command_names_what_exists(command):
    words = argv(command)
    program, args = words[0], words[1:]
    names = graph_names()
    if program == 'rosrun':
        # rosrun finds an executable of that name anywhere in the package's folder.
        scripts = [path for path in glob.glob(os.path.join(package_dir(args[0]), '**', args[1]), recursive=True)
                   if os.access(path, os.X_OK)]
        assert len(scripts) == 1, '%s: %d executables named %s in %s' % (command.line, len(scripts), args[1], args[0])
    elif program == 'roslaunch':
        path = os.path.join(package_dir(args[0]), 'launch', args[1])
        declared = launch_args(path)
        for assignment in args[2:]:
            assert assignment.split(':=')[0] in declared, '%s: %s declares no such arg' % (assignment, path)
    elif program == 'catkin_create_pkg':
        assert args[0] == 'exam' and package_dir('exam')
        for dependency in args[1:]:
            assert package_dir(dependency) or dependency in ('rospy', 'std_msgs'), dependency
    elif program == 'rosparam':
        assert args[0] == 'get'
        node, name = args[1].rsplit('/', 1)
        assert node in names and name in private_names_in_code(), args[1]
    elif program in ('rosmsg', 'rossrv'):
        package, name = args[1].split('/')
        module = importlib.import_module('%s.%s' % (package, 'msg' if program == 'rosmsg' else 'srv'))
        assert hasattr(module, name), args[1]
    elif program == 'rosservice' and args[0] == 'call':
        assert args[1] in names, args[1]
        request = yaml.safe_load(args[2])
        service_type = [m.service_type for m in MODES.values() if '/' + m.service == args[1]][0]
        assert set(request) == set(service_type._request_class.__slots__), command.line
    else:
        # rosnode/rostopic/rosbag/rosservice list: every graph name given must exist in the code.
        for word in args:
            if word.startswith('/'):
                assert word in names, '%s names %s, which no node creates' % (command.line, word)


# --- parameters named in the docs -----------------------------------------------------------------

def doc_files():
    files = sorted(glob.glob(os.path.join(REPO, 'docs', '*.md'))) + [TEMPLATE]
    readme = os.path.join(REPO, 'README.md')
    return files + ([readme] if os.path.exists(readme) else [])


@pytest.mark.parametrize('path', doc_files(), ids=lambda p: os.path.relpath(p, REPO))
def test_every_parameter_named_in_the_docs_is_read_by_the_code(path):
    args = set().union(*(launch_args(p) for p in launch_files()))
    assert unknown_names(read(path), private_names_in_code(), args, graph_names()) == set()


@pytest.mark.parametrize('module', ['exam.node', 'mydrone.simulator', 'submarinedrone.simulator',
                                    'drone_sim.simulator'])
def test_node_docstrings_name_only_parameters_the_code_reads(module):
    text = importlib.import_module(module).__doc__
    assert unknown_names(text, private_names_in_code(), set(), set()) == set()


def test_the_check_catches_a_parameter_the_code_does_not_read():
    # The checker itself must be able to fail: misspelt names, in both notations, are reported.
    text = 'Set `~thresold` or run `roslaunch exam exam.launch thresold:=1500`; `~threshold` is fine.'
    args = set().union(*(launch_args(p) for p in launch_files()))
    assert unknown_names(text, private_names_in_code(), args, graph_names()) == {'~thresold', 'thresold:='}


def test_code_scan_finds_the_parameters_of_both_nodes():
    names = private_names_in_code()
    for expected in ('mode', 'threshold', 'delay', 'rate', 'timeout', 'profile', 'seed',
                     'temperature_rate', 'pressure_noise', 'pressure_robot_rate', 'true_depth'):
        assert expected in names


# --- commands and paths named in the docs -----------------------------------------------------------

#: `rosrun PKG SCRIPT`, `roslaunch PKG FILE`, `rostest PKG FILE` as a user types them.
ROS_COMMAND = re.compile(r'\b(rosrun|roslaunch|rostest)\s+(?:--\S+\s+)*([a-z_]+)\s+([\w.-]+\.(?:py|launch|test))\b')
#: `$(find PKG)/path` in a launch file quoted by the docs.
FIND = re.compile(r'\$\(find (\w+)\)/([\w/.-]+)')
#: A path inside this repository, in backticks or a Markdown link: `lab/test/ops/replay.test`.
REPO_PATH = re.compile(r'[`(]((?:exam|mydrone|submarinedrone|drone_sim|node_kit|lab|tools|docs)/[\w./-]*)[`)#]')


def named_things(text):
    """(what, exists) for each ROS command, $(find) path and repository path the text names."""
    found = []
    for program, package, name in ROS_COMMAND.findall(text):
        folder = package_dir(package)
        if program == 'roslaunch':
            ok = folder is not None and os.path.isfile(os.path.join(folder, 'launch', name))
        else:  # rosrun and rostest find the file anywhere in the package
            ok = folder is not None and bool(glob.glob(os.path.join(folder, '**', name), recursive=True))
        found.append(('%s %s %s' % (program, package, name), ok))
    for package, path in FIND.findall(text):
        folder = package_dir(package)
        found.append(('$(find %s)/%s' % (package, path),
                      folder is not None and os.path.exists(os.path.join(folder, path))))
    for path in REPO_PATH.findall(text):
        path = path.rstrip('.')
        if path.count('/') == 1 and path.split('/')[0] not in ('docs', 'tools', 'lab'):
            continue  # `mydrone/AltitudeWarning`, `exam/exam_node.py`: ROS's package/resource names
        found.append((path, os.path.exists(os.path.join(REPO, path))))
    return found


@pytest.mark.parametrize('path', doc_files(), ids=lambda p: os.path.relpath(p, REPO))
def test_every_command_and_path_named_in_the_docs_exists(path):
    assert [what for what, ok in named_things(read(path)) if not ok] == []


def test_the_check_catches_a_command_or_path_that_moved():
    text = ('`roslaunch exam drone_pair.launch ns:=d1`, `rosrun exam fleet_launch.py 2`, '
            '`exam/test/ops/replay.test`, `$(find exam)/launch/drone_pair.launch`; fine: '
            '`roslaunch exam exam.launch`, `lab/test/ops/replay.test`.')
    assert [what for what, ok in named_things(text) if not ok] == [
        'roslaunch exam drone_pair.launch', 'rosrun exam fleet_launch.py',
        '$(find exam)/launch/drone_pair.launch', 'exam/test/ops/replay.test']


# --- the report's PDF: the questions part, then the appendices ---------------------------------------

#: The questions part of docs/report.pdf: at most this many pages before the appendices (issue 28).
QUESTION_PAGES = 10
PDF = os.path.join(REPO, 'docs', 'report.pdf')


def pdf_outline(path):
    """The PDF's outline (bookmarks) as [(depth, page, title)], read with poppler's pdftohtml."""
    import subprocess
    xml = subprocess.run(['pdftohtml', '-xml', '-i', '-stdout', path], stdout=subprocess.PIPE,
                         stderr=subprocess.DEVNULL, check=True).stdout.decode('utf-8', 'replace')
    outline, depth = [], 0
    for tag, page, title in re.findall(r'(<outline>|</outline>|<item page="(\d+)">(.*?)</item>)', xml):
        if tag == '<outline>':
            depth += 1
        elif tag == '</outline>':
            depth -= 1
        else:
            outline.append((depth, int(page), title))
    return outline


def questions_and_appendices(outline):
    """(last page of the questions part, the top-level titles) of an outline."""
    top = [(page, title) for depth, page, title in outline if depth == 1]
    appendices = [page for page, title in top if title == 'Appendices']
    assert appendices, 'no top-level "Appendices" in the outline: %s' % top
    return appendices[0] - 1, [title for _, title in top]


@pytest.mark.skipif(shutil.which('pdftohtml') is None, reason='pdftohtml (poppler-utils) is not installed')
def test_report_pdf_has_at_most_ten_pages_of_questions_then_the_appendices_in_its_outline():
    outline = pdf_outline(PDF)
    last_question_page, top = questions_and_appendices(outline)
    assert 'Questions 1 to 14' in top and top.index('Questions 1 to 14') < top.index('Appendices'), top
    assert last_question_page <= QUESTION_PAGES, 'the questions part runs to page %d' % last_question_page
    titles = [title for _, _, title in outline]
    for expected in ['14b. The 5 s delay', 'E. This project\'s node, and what it does differently',
                     'C. Corrections to the exam sheets and the grader\'s notes']:
        assert any(t.replace('&#39;', "'").replace('&apos;', "'") == expected for t in titles), (expected, titles)


def test_the_page_check_catches_a_questions_part_too_long():
    # An outline whose appendices start on page 12: 11 pages of questions.
    outline = [(1, 1, 'Model report'), (1, 1, 'Questions 1 to 14'), (2, 11, '14b. The 5 s delay'),
               (1, 12, 'Appendices')]
    last, top = questions_and_appendices(outline)
    assert last == 11 and last > QUESTION_PAGES and top == ['Model report', 'Questions 1 to 14', 'Appendices']


# --- docs/grading.md: its example grades are a grader's output, not typed ---------------------------

def test_grading_examples_are_the_generators_output_with_every_item_of_the_rubric():
    import grading_examples  # lab/report/grading_examples.py
    from exam_lab.grader.score.sheets import ITEMS
    text = read(grading_examples.GRADING)
    for name, submission in grading_examples.EXAMPLES:
        assert os.path.isdir(os.path.join(REPO, submission)), submission
        found = re.search(r'%s\n```markdown\n(.*?)\n```\n%s' % (re.escape(grading_examples.BEGIN % name),
                                                               re.escape(grading_examples.END % name)), text, re.S)
        assert found, 'docs/grading.md: no generated example %r between its markers' % name
        grade = found.group(1)
        assert grade.startswith('# %s: ' % name), grade[:80]  # graded as the student named like its example
        for item, (points, _) in ITEMS.items():
            assert re.search(r'^\| %s \| .* \| [0-9.]+ / %g \|' % (item, points), grade, re.M), item


def test_grading_examples_splice_replaces_only_the_block_between_its_markers():
    import grading_examples
    text = 'before\n%s\nold\n%s\nafter\n' % (grading_examples.BEGIN % 'x', grading_examples.END % 'x')
    assert grading_examples.splice(text, 'x', '# x: 17 / 17\n') == (
        'before\n%s\n```markdown\n# x: 17 / 17\n```\n%s\nafter\n' % (grading_examples.BEGIN % 'x',
                                                                    grading_examples.END % 'x'))
    with pytest.raises(ValueError):
        grading_examples.splice(text, 'y', '')


# --- docs/grading.md: the worst case is the code's --------------------------------------------------

def test_the_worst_case_in_the_docs_is_the_codes():
    """"The worst case" paragraph states the budget, the steps' limits and the class's worst case with
    the runner's constants: a change of one is a change of the docs."""
    from exam_lab.grader import class_run, runner
    from exam_lab.grader.host import boxed_run
    text = ' '.join(read(os.path.join(REPO, 'docs', 'grading.md')).split())
    paragraph = re.search(r'\*\*The worst case\.\*\*(.*?)nothing was run"', text).group(1)
    jobs = class_run.default_jobs(cores=2, memory=64 << 30)
    student = runner.STUDENT_BUDGET + runner.AFTER_BUDGET_S
    said = ['`STUDENT_BUDGET` = %g s' % runner.STUDENT_BUDGET, '`AFTER_BUDGET_S` = %g s' % runner.AFTER_BUDGET_S,
            'build %g s' % runner.BUILD_TIMEOUT, 'node start %g s' % runner.START_TIMEOUT,
            'a run %g s' % runner.RUN_TIMEOUT, 'the inspection %g s' % boxed_run.INSPECT_BOUNDS[0],
            '%g s a student' % student, 'JOBS` on two cores (%d)' % jobs,
            'ceil(60 / %d) × %g s = %g s (%g minutes)' % (jobs, student, class_run.worst_case(60, jobs),
                                                         class_run.worst_case(60, jobs) / 60),
            'intake %g s' % boxed_run.INTAKE_BOUNDS[0], 'similarity check %g s' % boxed_run.SIMILARITY_BOUNDS[0],
            'budget of %g s' % runner.STUDENT_BUDGET]
    assert [words for words in said if words not in paragraph] == []
    assert class_run.worst_case(60, jobs) <= 75 * 60

"""The layering rules of docs/architecture.md ("Layout: two wings"), read from the source with ast.

- The answer (exam, mydrone, submarinedrone, drone_sim) never imports the lab (exam_lab), in its
  code, its scripts or its tests.
- Pure modules import neither rospy nor any module that does (their unit tests run without a master,
  and the logic they hold is readable without ROS).
- No import cycle among the project's modules.
- The harness's oracle imports nothing of the answer: an oracle that reuses the code it checks cannot
  catch a wrong constant.
"""
import ast
import glob
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
ANSWER = ('exam', 'mydrone', 'submarinedrone', 'drone_sim')
#: The modules that hold logic without ROS (module name -> its file).
PURE = ['exam.formulas', 'exam.inputs', 'exam.debounce', 'exam.warning_link', 'drone_sim.params',
        'drone_sim.led', 'drone_sim.noise', 'drone_sim.profile', 'drone_sim.outage', 'drone_sim.master_line',
        'mydrone.atmosphere', 'mydrone.flights', 'submarinedrone.hydrostatics', 'submarinedrone.dives',
        'exam_lab.harness.oracle', 'exam_lab.harness.wait']
#: Modules that talk to ROS (besides rospy itself); a pure module must not import them either.
ROS = ('rospy', 'rosgraph', 'roslaunch', 'rosbag', 'diagnostic_updater')


def source_modules():
    """{module name: file} of every module under <package>/src of this repository."""
    modules = {}
    for path in glob.glob(os.path.join(REPO, '*', 'src', '**', '*.py'), recursive=True):
        src = path.split(os.sep + 'src' + os.sep, 1)[1]
        name = src[:-3].replace(os.sep, '.')
        if name.endswith('.__init__'):
            name = name[:-len('.__init__')]
        modules[name] = path
    return modules


def imports(path):
    """Every module name a file imports (absolute imports; `from a.b import c` gives a.b and a.b.c)."""
    with open(path) as f:
        tree = ast.parse(f.read(), path)
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names.add(node.module)
            names.update('%s.%s' % (node.module, alias.name) for alias in node.names)
    return names


def answer_files():
    files = []
    for package in ANSWER:
        files += glob.glob(os.path.join(REPO, package, '**', '*.py'), recursive=True)
    return sorted(files)


@pytest.mark.parametrize('path', answer_files(), ids=lambda p: os.path.relpath(p, REPO))
def test_the_answer_never_imports_the_lab(path):
    lab = sorted(name for name in imports(path) if name.split('.')[0] == 'exam_lab')
    assert lab == []


def project_graph():
    """{module: set of project modules it imports}."""
    modules = source_modules()
    return {name: {m for m in imports(path) if m in modules and m != name} for name, path in modules.items()}


@pytest.mark.parametrize('module', PURE)
def test_pure_modules_import_no_ros(module):
    graph = project_graph()
    assert module in graph, 'no such module: %s (update PURE)' % module
    seen, todo, offending = set(), [module], []
    while todo:
        current = todo.pop()
        if current in seen:
            continue
        seen.add(current)
        path = source_modules()[current]
        offending += ['%s imports %s' % (current, m) for m in sorted(imports(path))
                      if m.split('.')[0] in ROS]
        todo.extend(graph[current])
    assert offending == []


def test_no_import_cycles():
    graph = project_graph()
    cycles = []

    def visit(node, stack, done):
        if node in stack:
            cycles.append(stack[stack.index(node):] + [node])
            return
        if node in done:
            return
        for child in sorted(graph[node]):
            visit(child, stack + [node], done)
        done.add(node)

    done = set()
    for node in sorted(graph):
        visit(node, [], done)
    assert cycles == []


def test_the_oracle_is_independent_of_the_answer():
    path = source_modules()['exam_lab.harness.oracle']
    assert sorted(m for m in imports(path) if m.split('.')[0] in ANSWER) == []

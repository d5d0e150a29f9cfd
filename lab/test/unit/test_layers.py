"""The layering rules of docs/architecture.md ("Layout: two wings"), read from the source with ast.

- The answer (exam, mydrone, submarinedrone, drone_sim, node_kit) never imports the lab (exam_lab), in its
  code, its scripts or its tests.
- Pure modules import neither rospy nor any module that does (their unit tests run without a master,
  and the logic they hold is readable without ROS).
- No import cycle among the project's modules.
- The harness's oracle imports nothing of the answer: an oracle that reuses the code it checks cannot
  catch a wrong constant.
- The node kit (node_kit) is below the simulators and the exam node: it imports none of them.
- rospy's private names (``rospy.impl``, ``rospy.core``, a name with a leading underscore) are used
  in one module only, node_kit.rospy_private, and its tests.
"""
import ast
import glob
import os

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
ANSWER = ('exam', 'mydrone', 'submarinedrone', 'drone_sim', 'node_kit')
#: The modules that hold logic without ROS (module name -> its file).
PURE = ['exam.formulas', 'exam.inputs', 'exam.debounce', 'exam.warning_link', 'drone_sim.led',
        'drone_sim.noise', 'drone_sim.profile', 'node_kit.params', 'node_kit.gate', 'node_kit.outage',
        'node_kit.master_line', 'mydrone.atmosphere', 'mydrone.flights', 'submarinedrone.hydrostatics',
        'submarinedrone.dives', 'exam_lab.harness.oracle', 'exam_lab.harness.wait',
        'exam_lab.grader.judge.legs']
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


def nodes(path):
    """Every node of a file's syntax tree."""
    with open(path) as f:
        return ast.walk(ast.parse(f.read(), path))


def imports(path):
    """Every module name a file imports (absolute imports; `from a.b import c` gives a.b and a.b.c)."""
    names = set()
    for node in nodes(path):
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


#: The grader's folders by trust level (exam_lab.grader's docstring). Each folder may import only the
#: folders named here (and itself, and nothing of the grader beyond them), relative imports included:
#: what runs as a box's uid on the student's bytes (boxed) leans on pure records only; the judge (a
#: judge uid, never root) the same; root's side (host, the runner, class_run, engine) never imports
#: boxed/ nor judge/: root never runs box code, it runs a box (``python -m`` in it) and reads its record
#: through the contract (the one reader of foreign files, the one writer in OUT); score and publish
#: are pure; the runner is one submission's pipeline; class_run lists a class's students and grades
#: each by the runner; engine/ is the host as the teacher, submitting classes elsewhere, each student
#: by class_run.
GRADER = 'exam_lab.grader'
MAY_IMPORT = {
    'boxed': ('score',),
    'judge': ('score',),
    'contract': ('score',),
    'host': ('contract', 'score'),
    'score': (),
    'publish': ('contract', 'score'),
    'runner': ('contract', 'host', 'score', 'publish'),
    'class_run': ('runner', 'contract', 'host', 'score', 'publish'),
    'engine': ('class_run', 'contract', 'host', 'score', 'publish'),
}
#: Root's side: none of these may import boxed/ (nor judge/), whatever MAY_IMPORT is changed to.
ROOT_SIDE = ('host', 'runner', 'class_run', 'engine')
#: The package itself (``exam_lab.grader``: ``workspace()``) is plain configuration, open to every folder.
PACKAGE_ITSELF = (GRADER,)


def grader_modules(folder):
    prefix = '%s.%s' % (GRADER, folder)
    return sorted(name for name in source_modules() if name == prefix or name.startswith(prefix + '.'))


def resolved_imports(name, path):
    """Every module name a file imports, relative imports resolved against the module ``name``."""
    names = imports(path)
    package = name.split('.') if path.endswith('__init__.py') else name.split('.')[:-1]
    for node in nodes(path):
        if isinstance(node, ast.ImportFrom) and node.level > 0:
            base = package[:len(package) - (node.level - 1)]
            module = '.'.join(base + ([node.module] if node.module else []))
            names.add(module)
            names.update('%s.%s' % (module, alias.name) for alias in node.names)
    return names


def trust_violations(folder, modules):
    """["<module> imports <module>"] of every import of ``modules`` (name -> path) that leaves what the
    folder may import."""
    allowed = tuple('%s.%s' % (GRADER, f) for f in (folder,) + MAY_IMPORT[folder])
    offending = []
    for name, path in sorted(modules.items()):
        for module in sorted(resolved_imports(name, path)):
            if not module.startswith(GRADER + '.') or module in PACKAGE_ITSELF:
                continue
            if module == '%s.workspace' % GRADER:
                continue  # ``from exam_lab.grader import workspace``: the package's own function
            if not any(module == a or module.startswith(a + '.') for a in allowed):
                offending.append('%s imports %s' % (name, module))
    return offending


@pytest.mark.parametrize('folder', sorted(MAY_IMPORT))
def test_the_grader_folders_keep_to_their_trust_level(folder):
    modules = {name: source_modules()[name] for name in grader_modules(folder)}
    assert modules, 'no modules under %s.%s' % (GRADER, folder)
    assert trust_violations(folder, modules) == []


def test_root_side_may_not_import_box_code():
    assert [f for f in ROOT_SIDE if {'boxed', 'judge'} & set(MAY_IMPORT[f])] == []


@pytest.mark.parametrize('folder', ROOT_SIDE)
def test_the_trust_check_sees_root_importing_box_code(tmp_path, folder):
    # A planted module of root's side that imports box code, absolutely and relatively: the check
    # must fail on each.
    planted = tmp_path / 'planted.py'
    planted.write_text('from exam_lab.grader.boxed import similarity\nimport exam_lab.grader.boxed.classlist\n'
                       'from exam_lab.grader.judge import probe\n')
    name = '%s.%s' % (GRADER, folder) if folder in ('runner', 'class_run') else '%s.%s.planted' % (GRADER, folder)
    offending = trust_violations(folder, {name: str(planted)})
    assert '%s imports %s.boxed.similarity' % (name, GRADER) in offending
    assert '%s imports %s.boxed.classlist' % (name, GRADER) in offending
    assert '%s imports %s.judge.probe' % (name, GRADER) in offending
    relative = tmp_path / 'relative.py'
    relative.write_text('from ..boxed import archives\n' if folder not in ('runner', 'class_run') else
                        'from .boxed import archives\n')
    assert '%s imports %s.boxed.archives' % (name, GRADER) in trust_violations(folder, {name: str(relative)})


#: Where root (or the teacher's publish step) reads what it did not write in this process: only
#: through the contract's reader (exam_lab.grader.contract.read_record), never a record type's own.
CONTRACT_READERS = ROOT_SIDE + ('publish',)


def own_record_reads(path):
    """["<file>:<line> <Type>.<read|from_json>"] of every call in ``path`` of a record type's own reader
    (``XRecord.read(...)``, ``XRecord.from_json(...)``): a file read past the contract."""
    found = []
    for node in nodes(path):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and \
                node.func.attr in ('read', 'from_json'):
            owner = node.func.value
            name = owner.id if isinstance(owner, ast.Name) else owner.attr if isinstance(owner, ast.Attribute) else ''
            if name.endswith('Record'):
                found.append('%s:%d %s.%s' % (os.path.basename(path), node.lineno, name, node.func.attr))
    return found


@pytest.mark.parametrize('folder', CONTRACT_READERS + ('scripts',))
def test_root_reads_records_only_through_the_contract(folder):
    """Root's side, publish, and the lab's scripts (make grade, rescore, worksheet, review, check)."""
    paths = glob.glob(os.path.join(REPO, 'lab', 'scripts', '*.py')) if folder == 'scripts' else \
        [source_modules()[name] for name in grader_modules(folder)]
    assert paths
    offending = []
    for path in paths:
        offending += own_record_reads(path)
    assert offending == []


def test_the_contract_check_sees_a_record_read_past_it(tmp_path):
    planted = tmp_path / 'planted.py'
    planted.write_text('from exam_lab.grader.score import kept, records\n'
                       'grade = kept.GradeRecord.read("OUT/ann/grade.json")\n'
                       'job = records.JobRecord.from_json(open("job.json", "rb").read())\n'
                       'text = open("notes.txt").read()\n')
    assert own_record_reads(str(planted)) == ['planted.py:2 GradeRecord.read', 'planted.py:3 JobRecord.from_json']


def test_the_trust_check_sees_a_forbidden_import_absolute_or_relative(tmp_path):
    # A planted module of boxed/ that imports root's side, both ways: the check must fail on each.
    planted = tmp_path / 'planted.py'
    planted.write_text('from exam_lab.grader.host import sandbox\nfrom ..publish import moodle\n'
                       'from . import unpack\nfrom exam_lab.grader.score import records\n')
    name = '%s.boxed.planted' % GRADER
    assert trust_violations('boxed', {name: str(planted)}) == [
        '%s imports %s.host' % (name, GRADER), '%s imports %s.host.sandbox' % (name, GRADER),
        '%s imports %s.publish' % (name, GRADER), '%s imports %s.publish.moodle' % (name, GRADER)]


@pytest.mark.parametrize('folder', ['score', 'publish'])
def test_the_pure_grader_folders_import_no_ros(folder):
    graph = project_graph()
    offending = []
    for module in grader_modules(folder):
        seen, todo = set(), [module]
        while todo:
            current = todo.pop()
            if current in seen:
                continue
            seen.add(current)
            offending += ['%s (from %s) imports %s' % (current, module, m)
                          for m in sorted(imports(source_modules()[current])) if m.split('.')[0] in ROS]
            todo.extend(graph[current])
    assert offending == []


def test_every_grader_module_lives_in_a_trust_folder():
    """Only the package itself, the runner (one submission's pipeline), class_run (a class) and the
    contract (the one reader of foreign files, the one writer in OUT) sit at the grader's top level;
    every other module is in a folder of MAY_IMPORT."""
    top = [name for name in source_modules() if name.startswith(GRADER + '.') and name.count('.') == 2]
    assert sorted(top) == ['%s.%s' % (GRADER, f) for f in sorted(MAY_IMPORT)]


def test_the_node_kit_imports_no_simulator_nor_the_exam_node():
    kit = [name for name in source_modules() if name.split('.')[0] == 'node_kit']
    assert kit, 'no node_kit modules'
    above = ('drone_sim', 'mydrone', 'submarinedrone', 'exam')
    offending = ['%s imports %s' % (name, m) for name in kit for m in sorted(imports(source_modules()[name]))
                 if m.split('.')[0] in above]
    assert offending == []


#: The one module that may use rospy's private names, and the tests that hold it to the installed rospy.
ROSPY_PRIVATE = ('node_kit/src/node_kit/rospy_private.py', 'node_kit/test/unit/test_rospy_private.py')


def attribute_chains(path):
    """Every dotted name a file reads from a name (``rospy.core._shutdown_flag``, and its prefixes)."""
    chains = set()
    for node in nodes(path):
        if isinstance(node, ast.Attribute):
            parts = [node.attr]
            value = node.value
            while isinstance(value, ast.Attribute):
                parts.append(value.attr)
                value = value.value
            if isinstance(value, ast.Name):
                chains.add('.'.join([value.id] + parts[::-1]))
    return chains


def rospy_private_names(path):
    """The rospy names ``path`` uses that rospy does not export: ``rospy.impl``, ``rospy.core``, or any
    name with a leading underscore, in an import or an attribute chain starting at ``rospy``."""
    def private(name):
        parts = name.split('.')
        return parts[0] == 'rospy' and len(parts) > 1 and (
            parts[1] in ('impl', 'core') or any(p.startswith('_') for p in parts[1:]))
    return sorted(name for name in imports(path) | attribute_chains(path) if private(name))


def python_files():
    """Every Python file of this repository's own packages, with neither the students' packages the
    grader's tests and the report hold (a package.xml below the top level) nor the workspace .ws."""
    files = []
    for dirpath, dirnames, filenames in os.walk(REPO):
        if os.path.dirname(dirpath) != REPO and dirpath != REPO and 'package.xml' in filenames:
            dirnames[:] = []
            continue
        dirnames[:] = [d for d in dirnames if not d.startswith('.')]
        files += [os.path.join(dirpath, f) for f in filenames if f.endswith('.py')]
    return sorted(files)


def test_rospy_private_names_are_used_in_node_kit_rospy_private_only():
    offending = ['%s: %s' % (os.path.relpath(path, REPO), ', '.join(names)) for path in python_files()
                 if os.path.relpath(path, REPO) not in ROSPY_PRIVATE
                 for names in [rospy_private_names(path)] if names]
    assert offending == []


def test_the_private_name_check_finds_each_kind_of_use(tmp_path):
    # The check itself must be able to fail.
    sample = tmp_path / 'sample.py'
    sample.write_text('import rospy\nfrom rospy.impl import registration\nimport rospy.core\n'
                      'rospy.core._shutdown_flag = True\nrospy.get_param("~a")\nrospy._private()\n')
    assert rospy_private_names(str(sample)) == ['rospy._private', 'rospy.core', 'rospy.core._shutdown_flag',
                                                'rospy.impl', 'rospy.impl.registration']

"""Reading students' launch files: the drone, the exam node, the threshold however it is set; the
derived copies the grader runs."""
import dataclasses
import os
import shutil
import xml.etree.ElementTree as ET

import pytest

from exam_lab.grader.boxed import derive, launch
from exam_lab.grader.score.inspection import InspectRecord

HERE = os.path.dirname(os.path.realpath(__file__))
SUBMISSIONS = os.path.join(HERE, '..', 'grader', 'submissions')
REPO = os.path.join(HERE, '..', '..', '..')


def package(tmp_path, files):
    """A package folder with ``files`` {relative path: text}."""
    root = tmp_path / 'exam'
    for rel, text in files.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return str(root)


def copy_submission(tmp_path, name):
    target = str(tmp_path / name)
    shutil.copytree(os.path.join(SUBMISSIONS, name, 'exam'), target)
    return target


def in_box(path, pkg):
    """A derived file's ``$(find exam)/...`` path, resolved as roslaunch does (the package at ``pkg``)."""
    assert path.startswith('$(find exam)/'), path
    return os.path.join(pkg, path[len('$(find exam)/'):])


@pytest.mark.parametrize('name, sheet, param, value', [
    ('good_student', 'altitude', '/threshold', 1300),           # global <param>, as the sheet's notes
    ('every_cycle', 'altitude', '/exam/threshold', '1300'),     # private, through an <arg>
    ('no_kelvin', 'altitude', '/exam/seuil', 1300),             # inline <rosparam>, a French name
    ('no_delay', 'altitude', '/altitude_max', 1300),            # another name
    ('one_subscriber', 'depth', '/exam/depth_limit', 150),      # <rosparam param> with subst_value
])
def test_threshold_found_however_it_is_set(tmp_path, name, sheet, param, value):
    pkg = copy_submission(tmp_path, name)
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert analysis.problems == []
    assert analysis.starts_drone(sheet)
    assert [n.pkg for n in analysis.exam_nodes] == ['exam']
    found, _ = derive.threshold_param(analysis, sheet)
    assert found is not None and found.name == param
    assert launch.as_number(found.value) == float(value)


@pytest.mark.parametrize('name', ['good_student', 'every_cycle', 'no_kelvin', 'no_delay', 'one_subscriber'])
def test_derived_launch_has_no_drone_and_the_new_threshold(tmp_path, name):
    pkg = copy_submission(tmp_path, name)
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    found, _ = derive.threshold_param(analysis, 'depth' if name == 'one_subscriber' else 'altitude')
    derived = derive.derive(analysis, 'threshold', {found.origin: 1040.0})
    again = launch.analyse(derived, pkg)
    assert [n.pkg for n in again.nodes] == ['exam'], 'only the exam node runs'
    assert [launch.as_number(p.value) for p in again.params if p.name == found.name] == [1040.0]
    # The student's own file is untouched, and a second derivation starts from it.
    assert launch.as_number(derive.threshold_param(launch.analyse(analysis.path, pkg), 'altitude')[0].value) != 1040.0
    main = launch.analyse(derive.derive(analysis, 'main'), pkg)
    assert [launch.as_number(p.value) for p in main.params if p.name == found.name] != [1040.0]


def test_our_exam_package_per_sheet():
    pkg = os.path.abspath(os.path.join(REPO, 'exam'))
    analyses = [launch.analyse(p, pkg) for p in derive.launch_files(pkg)]
    for sheet, expected in (('altitude', 'exam.launch'), ('depth', 'exam_submarine.launch')):
        chosen = derive.choose(analyses, sheet)
        assert os.path.basename(chosen.path) == expected
        found, _ = derive.threshold_param(chosen, sheet)
        assert found.name == '/exam/threshold'
        assert found.origin.element.tag == 'arg', 'the value lives in the <arg> default'


def test_group_namespace_include_and_yaml_file(tmp_path):
    pkg = package(tmp_path, {
        'launch/exam.launch': '''<launch>
  <arg name="use_drone" default="true"/>
  <group ns="drone1">
    <include file="$(find mydrone)/launch/mydrone.launch" if="$(arg use_drone)"/>
    <include file="$(dirname)/node.launch"><arg name="seuil" value="1400"/></include>
  </group>
</launch>''',
        'launch/node.launch': '''<launch>
  <arg name="seuil"/>
  <node pkg="exam" type="exam_node.py" name="exam" launch-prefix="xterm -e">
    <param name="threshold" value="$(arg seuil)"/>
    <rosparam command="load" file="$(find exam)/config/params.yaml"/>
  </node>
</launch>''',
        'config/params.yaml': 'limits:\n  max_altitude: 1300\nrate: 10\n'})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert analysis.problems == []
    assert analysis.included_drones == ['mydrone'] and analysis.starts_drone('altitude')
    assert analysis.exam_nodes[0].ns == '/drone1'
    names = {p.name: p.value for p in analysis.params}
    assert names == {'/drone1/exam/threshold': 1400, '/drone1/exam/limits/max_altitude': 1300,
                     '/drone1/exam/rate': 10}
    found, _ = derive.threshold_param(analysis, 'altitude')
    assert found.name == '/drone1/exam/threshold'
    assert found.origin.path.endswith('exam.launch'), 'followed to the <include>\'s <arg value>'
    derived = derive.derive(analysis, 'x', {found.origin: 999})
    tree = ET.parse(derived)
    include = tree.getroot().find('group/include')
    assert include.get('file') == '$(find exam)/launch/.grader-x-node.launch', 'a path the run box resolves'
    assert include.find('arg').get('value') == '999'
    assert tree.getroot().find('group').findall('include') == [include], 'the drone include is dropped'
    node = ET.parse(in_box(include.get('file'), pkg)).getroot().find('node')
    assert node.get('launch-prefix') is None and node.get('output') == 'screen'
    # A YAML file's value is changed in a copy of the file.
    yaml_param = [p for p in analysis.params if p.name.endswith('max_altitude')][0]
    derived = derive.derive(analysis, 'y', {yaml_param.origin: 1111})
    node = ET.parse(os.path.join(pkg, 'launch', '.grader-y-node.launch')).getroot().find('node')
    loaded = node.find('rosparam').get('file')
    assert loaded == '$(find exam)/config/.grader-y-params.yaml'
    assert 'max_altitude: 1111' in open(in_box(loaded, pkg)).read()
    assert 'max_altitude: 1300' in open(os.path.join(pkg, 'config', 'params.yaml')).read()


def test_no_threshold_and_broken_files(tmp_path):
    pkg = package(tmp_path, {
        'launch/a.launch': '<launch><node pkg="exam" type="n.py" name="exam"><param name="rate" value="10"/>'
                           '</node></launch>',
        'launch/b.launch': '<launch><node pkg="exam"',
        'launch/c.launch': '<launch><param name="x" value="$(eval 1+1)"/></launch>'})
    a, b, c = [launch.analyse(p, pkg) for p in derive.launch_files(pkg)]
    found, why = derive.threshold_param(a, 'altitude')
    assert found is None and '/exam/rate' in why, 'a rate is never taken for a threshold'
    assert b.problems and 'not valid XML' in b.problems[0]
    assert c.problems and 'eval' in c.problems[0]
    assert derive.choose([b, c], 'altitude') is None
    assert derive.choose([b, a, c], 'altitude') is a


def test_value_alone_identifies_a_threshold(tmp_path):
    pkg = package(tmp_path, {'launch/exam.launch': '<launch><node pkg="exam" type="n.py" name="exam">'
                                                   '<param name="h" value="150"/><param name="k" value="3"/>'
                                                   '</node></launch>'})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert derive.threshold_param(analysis, 'depth')[0].name == '/exam/h'
    assert derive.threshold_param(analysis, 'altitude')[0] is None


# --- what the analysis reads: the student's package and the box's environment only (issue 26) ------

def test_env_substitutions_see_the_box_never_the_grader(tmp_path, monkeypatch):
    from exam_lab.grader.score import boxenv
    monkeypatch.setenv('EXAM_TEACHER_SECRET', 'hunter2-teacher-only')
    pkg = package(tmp_path, {'launch/exam.launch': '''<launch>
  <node pkg="exam" type="exam_node.py" name="exam">
    <param name="threshold" value="$(optenv EXAM_TEACHER_SECRET 1300)"/>
    <param name="token" value="$(env EXAM_TEACHER_SECRET)"/>
    <param name="home" value="$(env HOME)"/>
  </node>
</launch>'''})
    path = os.path.join(pkg, 'launch', 'exam.launch')
    for env in (None, boxenv.box_env({'PATH': '/usr/bin'})):
        analysis = launch.analyse(path, pkg) if env is None else launch.analyse(path, pkg, 'exam', env)
        seen = repr([(p.name, p.value) for p in analysis.params]) + repr(analysis.problems)
        assert 'hunter2' not in seen
        assert derive.threshold_param(analysis, 'altitude')[0].value == 1300, 'the default: unset in the box'
    assert {p.name: p.value for p in analysis.params}['/exam/home'] == boxenv.BOX_HOME


def test_files_outside_the_package_are_never_read(tmp_path):
    """``..``, a sibling folder whose name starts like the package's (a string prefix check took it),
    a link out of the package and an absolute path: each refused with a problem, nothing read, and no
    derived file written outside the package."""
    outside = tmp_path / 'outside'
    outside.mkdir()
    (outside / 'secret.yaml').write_text('root_only_key: 1300\n')
    (outside / 'other.launch').write_text('<launch><param name="from_outside" value="1300"/></launch>')
    sibling = tmp_path / 'exam-evil'
    sibling.mkdir()
    (sibling / 'x.yaml').write_text('sibling_key: 1300\n')
    pkg = package(tmp_path, {'launch/exam.launch': '''<launch>
  <include file="$(find mydrone)/launch/mydrone.launch"/>
  <include file="$(find exam)/../outside/other.launch"/>
  <include file="%s"/>
  <node pkg="exam" type="exam_node.py" name="exam">
    <param name="threshold" value="1300"/>
    <rosparam command="load" file="$(find exam)/../outside/secret.yaml"/>
    <rosparam command="load" file="$(find exam)/../../%s/outside/secret.yaml"/>
    <rosparam command="load" file="$(find exam)-evil/x.yaml"/>
    <rosparam command="load" file="$(find exam)/config/link.yaml"/>
  </node>
</launch>''' % (outside / 'other.launch', tmp_path.name)})
    os.mkdir(os.path.join(pkg, 'config'))
    os.symlink(str(outside / 'secret.yaml'), os.path.join(pkg, 'config', 'link.yaml'))
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert [p.name for p in analysis.params] == ['/exam/threshold'], 'nothing from outside'
    outside_problems = [p for p in analysis.problems if p.startswith('file outside the package: ')]
    assert len(outside_problems) == 6 and all(p.endswith(' not read') for p in outside_problems), analysis.problems
    assert analysis.starts_drone('altitude'), 'the drone\'s own launch file still counts, unread'
    found, _ = derive.threshold_param(analysis, 'altitude')
    for tag, changes in (('main', None), ('threshold', {found.origin: 1000})):
        derive.derive(analysis, tag, changes)
    assert sorted(os.listdir(str(outside))) == ['other.launch', 'secret.yaml']
    assert os.listdir(str(sibling)) == ['x.yaml']


def test_derived_files_name_paths_the_run_box_sees(tmp_path):
    """Issue 27's case: the threshold in a YAML loaded inside the node's tag, beside an include of the
    drone's launch file; the derived files name no path of the grader's side (the box sees the package
    at another path), and they are written in the package only."""
    pkg = package(tmp_path, {
        'launch/exam.launch': '''<launch>
  <include file="$(find mydrone)/launch/mydrone.launch"/>
  <include file="$(dirname)/node.launch"/>
</launch>''',
        'launch/node.launch': '''<launch>
  <node pkg="exam" type="exam_node.py" name="exam">
    <rosparam command="load" file="$(find exam)/config/params.yaml"/>
  </node>
</launch>''',
        'config/params.yaml': 'threshold: 1300\n'})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    found, _ = derive.threshold_param(analysis, 'altitude')
    assert found.name == '/exam/threshold' and analysis.starts_drone('altitude')
    derived = derive.derive(analysis, 'threshold', {found.origin: 1040.0})
    written = [os.path.join(d, f) for d, _, files in os.walk(str(tmp_path)) for f in files if f.startswith('.grader-')]
    assert sorted(os.path.relpath(p, pkg) for p in written) == [
        'config/.grader-threshold-params.yaml', 'launch/.grader-threshold-exam.launch',
        'launch/.grader-threshold-node.launch']
    for path in written:
        with open(path) as f:
            assert str(tmp_path) not in f.read(), '%s names a path of the grader\'s side' % path
    include = ET.parse(derived).getroot().find('include')
    assert include.get('file') == '$(find exam)/launch/.grader-threshold-node.launch'
    node = ET.parse(in_box(include.get('file'), pkg)).getroot().find('node')
    assert node.find('rosparam').get('file') == '$(find exam)/config/.grader-threshold-params.yaml'
    again = launch.analyse(derived, pkg)
    assert [(p.name, p.value) for p in again.params] == [('/exam/threshold', 1040.0)]


def test_derived_file_is_never_written_through_a_link(tmp_path):
    pkg = package(tmp_path, {'launch/exam.launch': '<launch><node pkg="exam" type="n.py" name="exam"/></launch>'})
    victim = tmp_path / 'victim.txt'
    victim.write_text('untouched')
    os.symlink(str(victim), os.path.join(pkg, 'launch', '.grader-main-exam.launch'))
    derived = derive.derive(launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg), 'main')
    assert victim.read_text() == 'untouched'
    assert not os.path.islink(derived) and ET.parse(derived).getroot().find('node').get('pkg') == 'exam'


def alias_bomb(levels=9, width=9):
    """The "billion laughs" of YAML: ``width ** levels`` parameters (nested mappings) from 0.6 KB."""
    keys = 'abcdefghijklmnopqrstuvwxyz'[:width]
    lines = ['l0: &l0 {%s}' % ', '.join('%s: 1' % k for k in keys)]
    for level in range(1, levels):
        lines.append('l%d: &l%d {%s}' % (level, level, ', '.join('%s: *l%d' % (k, level - 1) for k in keys)))
    return '\n'.join(lines) + '\n'


def test_yaml_alias_bomb_is_refused_at_once(tmp_path):
    import time
    import tracemalloc
    from xml.sax.saxutils import escape
    bomb = alias_bomb()
    assert len(bomb) < 800
    pkg = package(tmp_path, {
        'launch/exam.launch': '<launch><node pkg="exam" type="n.py" name="exam">'
                              '<rosparam command="load" file="$(find exam)/config/params.yaml"/>'
                              '<rosparam>%s</rosparam><param name="threshold" value="1300"/></node></launch>' % escape(bomb),
        'config/params.yaml': bomb})
    tracemalloc.start()
    try:
        started = time.monotonic()
        analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
        seconds = time.monotonic() - started
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert seconds < 1.0 and peak < 10 << 20, (seconds, peak)
    assert [p.name for p in analysis.params] == ['/exam/threshold']
    refused = [p for p in analysis.problems if launch.ALIASES_REFUSED in p]
    assert len(refused) == 2 and 'config/params.yaml' in refused[0] and '(line 1)' in refused[0], analysis.problems
    # A plain YAML still reads, and a merge key (an alias) is refused too.
    assert launch.load_yaml('a: {b: 1}\nc: [1, 2]\n') == {'a': {'b': 1}, 'c': [1, 2]}
    with pytest.raises(launch.yaml.YAMLError):
        launch.load_yaml('base: &b {x: 1}\nd:\n  <<: *b\n')


def roslaunch_sees(path, search, monkeypatch):
    """What roslaunch's own loader makes of ``path`` (the exam package found below ``search``): each
    node's args, and the parameters it sets (rospy's ``_name:=value`` words among them, as
    ``init_node`` sets them)."""
    import roslaunch.config
    monkeypatch.setenv('ROS_PACKAGE_PATH', search)
    config = roslaunch.config.load_config_default([path], None, verbose=False)
    params = {name: p.value for name, p in config.params.items() if name not in ('/rosdistro', '/rosversion')}
    args = {}
    for node in config.nodes:
        full = '/'.join([node.namespace.rstrip('/'), node.name])
        args[full] = node.args
        for word in node.args.split():
            if word.startswith('_') and not word.startswith('__') and ':=' in word:
                name, value = word[1:].split(':=', 1)
                params['%s/%s' % (full, name)] = launch._yaml_value(value)
    return args, params


PACKAGE_XML = ('<package format="2"><name>exam</name><version>0.0.0</version><description>x</description>'
               '<maintainer email="a@b.c">a</maintainer><license>x</license></package>')


@pytest.mark.parametrize('files, found_name, how', [
    # args= read with rospy.myargv / argparse: an option and its value
    ({'launch/exam.launch': '<launch><node pkg="exam" type="n.py" name="exam" args="--threshold 1300"/></launch>'},
     '--threshold', 'args'),
    # the whole args a $(arg) with a default: myargv()[1]
    ({'launch/exam.launch': '<launch><arg name="threshold" default="1300"/>'
                            '<node pkg="exam" type="n.py" name="exam" args="$(arg threshold)"/></launch>'},
     'argv[1]', 'args'),
    # --name=$(arg) in an included file that gets every arg (pass_all_args), set by <arg value>
    ({'launch/exam.launch': '<launch><arg name="alt_max" value="1300"/><arg name="rate" default="10"/>'
                            '<include file="$(dirname)/node.launch" pass_all_args="true"/></launch>',
      'launch/node.launch': '<launch><arg name="alt_max" default="1"/><arg name="rate"/>'
                            '<node pkg="exam" type="n.py" name="exam" args="--rate $(arg rate) '
                            '--limit=$(arg alt_max)"/></launch>'},
     '--limit', 'args'),
    # rospy's private parameter on the command line
    ({'launch/exam.launch': '<launch><node pkg="exam" type="n.py" name="exam" args="_seuil:=1300 __log:=x"/></launch>'},
     '/exam/seuil', 'param'),
    # inline <rosparam> with subst_value, in the node
    ({'launch/exam.launch': '<launch><arg name="t" default="1300"/><node pkg="exam" type="n.py" name="exam">'
                            '<rosparam subst_value="true">threshold: $(arg t)\nrate: 10</rosparam></node></launch>'},
     '/exam/threshold', 'param'),
    # a relative <param> in a <group ns>, read by a node of the group as "threshold"
    ({'launch/exam.launch': '<launch><group ns="drone"><param name="threshold" type="double" value="1300"/>'
                            '<node pkg="exam" type="n.py" name="exam"/></group></launch>'},
     '/drone/threshold', 'param'),
])
def test_every_way_a_launch_file_hands_over_the_threshold(tmp_path, monkeypatch, files, found_name, how):
    """Issue 35 point 4: the threshold found however the launch file hands it to the node, and the
    derived file changes it where it is set: roslaunch's own loader sees 1040 where it saw 1300, and
    nothing else moved."""
    pkg = package(tmp_path, dict(files, **{'package.xml': PACKAGE_XML}))
    path = os.path.join(pkg, 'launch', 'exam.launch')
    analysis = launch.analyse(path, pkg)
    assert analysis.problems == []
    found, why = derive.threshold_param(analysis, 'altitude')
    assert found is not None and found.name == found_name, why
    assert isinstance(found, launch.NodeArg) == (how == 'args')
    assert launch.as_number(found.value) == 1300.0
    args, params = roslaunch_sees(path, str(tmp_path), monkeypatch)
    derived = derive.derive(analysis, 'threshold', {found.origin: 1040.0})
    args2, params2 = roslaunch_sees(derived, str(tmp_path), monkeypatch)
    changed = lambda before, after: {k: (before.get(k), after.get(k)) for k in set(before) | set(after)
                                     if before.get(k) != after.get(k)}
    if how == 'param':
        assert changed(params, params2) == {found.name: (1300, 1040.0)}
        assert args == args2 or found.origin.kind == 'args', 'only rospy\'s _name:= word changes the args'
    else:
        assert params == params2
        (node, (before, after)), = changed(args, args2).items()
        assert before.replace('1300', '1040.0') == after, (before, after)
    again = derive.threshold_param(launch.analyse(derived, pkg), 'altitude')[0]
    assert (again.name, launch.as_number(again.value)) == (found_name, 1040.0)


@pytest.mark.parametrize('draw', [0.0, 0.5, 0.999])
def test_the_threshold_run_value_is_drawn_once_written_and_planned(tmp_path, draw):
    """Issue 36 point 7: the threshold run's value comes from a draw made at grading time, is computed
    once (sheets.threshold_run_value, in the inspection), written into the derived launch file where
    the student set the threshold (here an <arg> given to args=), kept in the record's static facts (the
    measurements), and planned by the runner as it is, with the main run's margin."""
    from exam_lab.grader import runner
    from exam_lab.grader.boxed import inspect
    from exam_lab.grader.score import records, sheets
    ws = tmp_path / 'ws'
    (ws / 'src').mkdir(parents=True)
    found = inspect.inspect(os.path.join(SUBMISSIONS, 'args_threshold', 'exam'), str(ws), str(tmp_path / 'out'),
                            None, draw)
    value = sheets.threshold_run_value(1300.0, draw)
    assert 1300 - 4 * 130 <= value <= 1300 - 2.5 * 130
    assert found['threshold_run_value'] == found['static']['threshold']['run_value'] == value
    assert found['static']['threshold']['how'] == 'args' and found['static']['args_in_code'] == ['--threshold']
    derived = os.path.join(str(ws), found['threshold_launch'])
    again = derive.threshold_param(launch.analyse(derived, os.path.join(str(ws), 'src', 'exam')), 'altitude')[0]
    assert (again.name, launch.as_number(again.value)) == ('--threshold', value)
    job = runner.plan_job(InspectRecord.make(found))
    main, threshold = [run.plan for run in job.runs]
    assert threshold == dataclasses.replace(main, kind='threshold', threshold=value), 'the main run\'s plan around the new value'
    with pytest.raises(ValueError):
        sheets.threshold_run_value(1300.0, 1.0)


@pytest.mark.parametrize('text, words', [
    # The elements side by side at the top, an XML declaration first (issue 45's fifth class).
    ('<?xml version="1.0"?>\n<!-- the threshold -->\n<param name="threshold" value="1300" />\n'
     '<node pkg="mydrone" name="mydrone" type="mydrone_node.py"/>\n'
     '<node pkg="exam" name="exam" type="exam_node.py"/>\n', 'its elements are not inside one <launch>'),
    # Another name for the root: its children are the launch file's elements.
    ('<roslaunch>\n  <param name="threshold" value="1300" />\n  <node pkg="mydrone" name="mydrone" '
     'type="mydrone_node.py"/>\n  <node pkg="exam" name="exam" type="exam_node.py"/>\n</roslaunch>\n',
     'its root element is <roslaunch>'),
    # One node as the whole file, its threshold inside it.
    ('<node pkg="exam" name="exam" type="exam_node.py">\n  <param name="threshold" value="1300" />\n</node>\n',
     'its root element is <node>'),
])
def test_a_launch_file_without_its_launch_root_is_read_and_run_as_written(tmp_path, text, words):
    """roslaunch refuses it (Q12's loss, its verdict's); the grader reads what it starts and sets,
    says the repair, and runs a derived copy rooted in <launch> with the threshold changed."""
    pkg = package(tmp_path, {'launch/exam.launch': text})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert analysis.problems == []
    assert [n.pkg for n in analysis.exam_nodes] == ['exam']
    assert len(analysis.repairs) == 1 and words in analysis.repairs[0], analysis.repairs
    assert 'launch/exam.launch: roslaunch refuses it (no root <launch> tag' in analysis.repairs[0]
    found, _ = derive.threshold_param(analysis, 'altitude')
    assert found is not None and launch.as_number(found.value) == 1300.0
    derived = derive.derive(analysis, 'threshold', {found.origin: 900.0})
    root = ET.parse(derived).getroot()
    assert root.tag == 'launch'
    assert [n.get('pkg') for n in root.iter('node')] == ['exam']
    assert [p.get('value') for p in root.iter('param')] == ['900.0']


def test_a_node_without_its_name_is_named_after_its_executable(tmp_path):
    """ROS 2's habit: <node> without name; roslaunch requires one. Read and run named after its
    script, said as a repair; its private parameter belongs to that name."""
    pkg = package(tmp_path, {'launch/exam.launch': (
        '<launch>\n  <node pkg="mydrone" name="mydrone" type="mydrone_node.py"/>\n'
        '  <node pkg="exam" type="exam_node.py">\n    <param name="threshold" value="1300" />\n  </node>\n</launch>\n')})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert analysis.problems == []
    assert [(n.pkg, n.name) for n in analysis.exam_nodes] == [('exam', 'exam_node')]
    assert analysis.repairs == ['launch/exam.launch: roslaunch refuses <node pkg="exam" type="exam_node.py"> without '
                                'a name (required in ROS 1, optional in ROS 2); the grader read and ran it named '
                                '"exam_node", after its executable']
    found, _ = derive.threshold_param(analysis, 'altitude')
    assert found.name == '/exam_node/threshold'
    root = ET.parse(derive.derive(analysis, 'main')).getroot()
    assert [n.get('name') for n in root.iter('node')] == ['exam_node']


def test_a_launch_file_that_is_not_xml_even_inside_a_launch_is_not_repaired(tmp_path):
    pkg = package(tmp_path, {'launch/exam.launch': '<launch>\n  <node pkg="exam" name="exam" type="n.py">\n</launch>\n'})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert analysis.repairs == [] and analysis.exam_nodes == []
    assert analysis.problems and 'launch/exam.launch is not valid XML: mismatched tag' in analysis.problems[0]


def test_the_inspection_reads_a_refused_launch_file_as_written_and_names_the_repair(tmp_path):
    """Issue 45: launch_no_root's threshold is found and rewritten for the threshold run, its repair a
    fix; a launch file that is not XML even inside a <launch> is the record's launch_unread, and
    roslaunch's check still gets the file as handed in."""
    from exam_lab.grader.boxed import inspect
    ws = tmp_path / 'ws'
    (ws / 'src').mkdir(parents=True)
    found = inspect.inspect(os.path.join(SUBMISSIONS, 'launch_no_root', 'exam'), str(ws), str(tmp_path / 'out'),
                            None, 0.5)
    assert found['static']['threshold']['name'] == '/threshold' and found['threshold_launch'] is not None
    assert found['static']['launch']['repairs'] == [f for f in found['fixes'] if 'roslaunch refuses it' in f]
    assert len(found['static']['launch']['repairs']) == 1
    assert found['handed_in_launch'] == 'exam/launch/exam.launch'
    broken = tmp_path / 'broken'
    shutil.copytree(os.path.join(SUBMISSIONS, 'good_student', 'exam'), str(broken / 'exam'))
    (broken / 'exam' / 'launch' / 'exam.launch').write_text('<launch>\n  <node pkg="exam" name="exam" type="exam_node.py">\n</launch>\n')
    ws2 = tmp_path / 'ws2'
    (ws2 / 'src').mkdir(parents=True)
    found = inspect.inspect(str(broken / 'exam'), str(ws2), str(tmp_path / 'out2'), None, 0.5)
    assert found['static']['launch'] is None and found['threshold_launch'] is None
    assert found['static']['launch_unread'].startswith('launch/exam.launch cannot be read, by roslaunch nor by the '
                                                       'grader (mismatched tag: line 3'), found['static']
    assert found['handed_in_launch'] == 'exam/launch/exam.launch'

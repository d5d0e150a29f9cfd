"""Reading students' launch files: the drone, the exam node, the threshold however it is set; the
derived copies the grader runs."""
import os
import shutil
import xml.etree.ElementTree as ET

import pytest

from exam_lab.grader.boxed import launch

HERE = os.path.dirname(os.path.abspath(__file__))
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
    found, _ = launch.threshold_param(analysis, sheet)
    assert found is not None and found.name == param
    assert launch.as_number(found.value) == float(value)


@pytest.mark.parametrize('name', ['good_student', 'every_cycle', 'no_kelvin', 'no_delay', 'one_subscriber'])
def test_derived_launch_has_no_drone_and_the_new_threshold(tmp_path, name):
    pkg = copy_submission(tmp_path, name)
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    found, _ = launch.threshold_param(analysis, 'depth' if name == 'one_subscriber' else 'altitude')
    derived = launch.derive(analysis, 'threshold', {found.origin: 1040.0})
    again = launch.analyse(derived, pkg)
    assert [n.pkg for n in again.nodes] == ['exam'], 'only the exam node runs'
    assert [launch.as_number(p.value) for p in again.params if p.name == found.name] == [1040.0]
    # The student's own file is untouched, and a second derivation starts from it.
    assert launch.as_number(launch.threshold_param(launch.analyse(analysis.path, pkg), 'altitude')[0].value) != 1040.0
    main = launch.analyse(launch.derive(analysis, 'main'), pkg)
    assert [launch.as_number(p.value) for p in main.params if p.name == found.name] != [1040.0]


def test_our_exam_package_per_sheet():
    pkg = os.path.abspath(os.path.join(REPO, 'exam'))
    analyses = [launch.analyse(p, pkg) for p in launch.launch_files(pkg)]
    for sheet, expected in (('altitude', 'exam.launch'), ('depth', 'exam_submarine.launch')):
        chosen = launch.choose(analyses, sheet)
        assert os.path.basename(chosen.path) == expected
        found, _ = launch.threshold_param(chosen, sheet)
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
    found, _ = launch.threshold_param(analysis, 'altitude')
    assert found.name == '/drone1/exam/threshold'
    assert found.origin.path.endswith('exam.launch'), 'followed to the <include>\'s <arg value>'
    derived = launch.derive(analysis, 'x', {found.origin: 999})
    tree = ET.parse(derived)
    include = tree.getroot().find('group/include')
    assert include.get('file').endswith('.grader-x-node.launch') and include.find('arg').get('value') == '999'
    assert tree.getroot().find('group').findall('include') == [include], 'the drone include is dropped'
    node = ET.parse(include.get('file')).getroot().find('node')
    assert node.get('launch-prefix') is None and node.get('output') == 'screen'
    # A YAML file's value is changed in a copy of the file.
    yaml_param = [p for p in analysis.params if p.name.endswith('max_altitude')][0]
    derived = launch.derive(analysis, 'y', {yaml_param.origin: 1111})
    node = ET.parse(os.path.join(pkg, 'launch', '.grader-y-node.launch')).getroot().find('node')
    loaded = node.find('rosparam').get('file')
    assert loaded.endswith('.grader-y-params.yaml') and 'max_altitude: 1111' in open(loaded).read()
    assert 'max_altitude: 1300' in open(os.path.join(pkg, 'config', 'params.yaml')).read()


def test_no_threshold_and_broken_files(tmp_path):
    pkg = package(tmp_path, {
        'launch/a.launch': '<launch><node pkg="exam" type="n.py" name="exam"><param name="rate" value="10"/>'
                           '</node></launch>',
        'launch/b.launch': '<launch><node pkg="exam"',
        'launch/c.launch': '<launch><param name="x" value="$(eval 1+1)"/></launch>'})
    a, b, c = [launch.analyse(p, pkg) for p in launch.launch_files(pkg)]
    found, why = launch.threshold_param(a, 'altitude')
    assert found is None and '/exam/rate' in why, 'a rate is never taken for a threshold'
    assert b.problems and 'not valid XML' in b.problems[0]
    assert c.problems and 'eval' in c.problems[0]
    assert launch.choose([b, c], 'altitude') is None
    assert launch.choose([b, a, c], 'altitude') is a


def test_value_alone_identifies_a_threshold(tmp_path):
    pkg = package(tmp_path, {'launch/exam.launch': '<launch><node pkg="exam" type="n.py" name="exam">'
                                                   '<param name="h" value="150"/><param name="k" value="3"/>'
                                                   '</node></launch>'})
    analysis = launch.analyse(os.path.join(pkg, 'launch', 'exam.launch'), pkg)
    assert launch.threshold_param(analysis, 'depth')[0].name == '/exam/h'
    assert launch.threshold_param(analysis, 'altitude')[0] is None

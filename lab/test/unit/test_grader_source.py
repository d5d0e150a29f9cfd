"""What the grader reads in the sources, and the teacher's fixes before running them."""
import os
import stat

from exam_lab.grader.boxed import source

from exam_lab.grader.publish import report


def write(path, text, mode=0o644):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    os.chmod(str(path), mode)
    return path


def test_comment_ratio_counts_comments_and_docstrings(tmp_path):
    script = write(tmp_path / 'n.py', '#!/usr/bin/env python3\n"""Doc\nstring."""\nimport rospy  # ROS\n\n'
                                      '# a comment\nx = 1\ns = "# not a comment"\n')
    comments, code = source.comment_ratio([str(script)])
    assert (comments, code) == (4, 3)  # docstring (2), the trailing comment, the comment line; no shebang


def test_make_runnable_does_what_a_teacher_does(tmp_path):
    pkg = tmp_path / 'exam'
    node = write(pkg / 'scripts' / 'exam_node.py', '#!/usr/bin/env python3\nimport rospy\nrospy.init_node("x")\n')
    bare = write(pkg / 'scripts' / 'other_node.py', 'import rospy\nrospy.init_node("y")\n')
    module = write(pkg / 'src' / 'exam' / 'lib.py', 'x = 1\n')
    notes = source.make_runnable(str(pkg), launched=['other_node.py'])
    assert os.stat(str(node)).st_mode & stat.S_IXUSR
    assert bare.read_text().startswith('#!/usr/bin/env python3\n') and os.stat(str(bare)).st_mode & stat.S_IXUSR
    assert not os.stat(str(module)).st_mode & stat.S_IXUSR, 'a module is not a script'
    assert len(notes) == 3 and any('chmod +x' in n for n in notes)
    assert source.make_runnable(str(pkg), launched=['other_node.py']) == [], 'nothing left to fix'


def test_node_scripts_params_and_sheets(tmp_path):
    pkg = tmp_path / 'exam'
    write(pkg / 'scripts' / 'helper.py', 'import rospy\nrospy.init_node("h")\n')
    write(pkg / 'scripts' / 'exam_node.py', 'import rospy\nrospy.init_node("e")\nt = rospy.get_param("~seuil")\n'
                                            'rospy.Subscriber("/pressure_robot", F, f)\n'
                                            'rospy.Subscriber("pressure_remote", F, g)\n')
    write(pkg / 'package.xml', '<package><name>exam</name><depend>rospy</depend>'
                               '<exec_depend>submarinedrone</exec_depend></package>')
    assert [os.path.basename(p) for p in source.node_scripts(str(pkg))] == ['exam_node.py', 'helper.py']
    assert source.param_names(str(pkg)) == ['~seuil']
    assert source.dependencies(str(pkg)) == ['rospy', 'submarinedrone']
    assert source.sheets_in_code(str(pkg)) == ['depth']


def test_reports(tmp_path):
    items = [{'id': 'runs', 'points': 2.0, 'max': 2.0, 'evidence': 'builds'},
             {'id': 'Q10', 'points': 1.0, 'max': 2.0, 'evidence': 'subscribes to /pressure | x\ndetail line'}]
    record = report.grade_record('Ann', 'altitude', items, ['hint'])
    assert (record['total'], record['max']) == (3.0, 4.0)
    text = report.markdown(record)
    assert '| Q10 |' in text and '1 / 2' in text and '\\|' in text and 'detail line' in text
    report.write_grade(str(tmp_path), record)
    report.write_csv(str(tmp_path / 'grades.csv'), [record])
    rows = (tmp_path / 'grades.csv').read_text().splitlines()
    assert rows[0].startswith('student,participant,sheet,status,runs,Q10,Q11') and \
        rows[1].startswith('Ann,,altitude,graded,2,1,0')
    assert 'Ann' in report.table([record]) and report.evidence_lines(record)[0].startswith('Q10 1/2')


def test_a_launched_type_without_its_py_is_run_as_the_script(tmp_path):
    """``type="exam_node"`` beside ``scripts/exam_node.py``: the derived launch file runs the script,
    the fix is named, the student's launch file is left as handed in (question 12 judges it)."""
    import xml.etree.ElementTree as ET
    from exam_lab.grader.boxed import launch
    pkg = tmp_path / 'exam'
    write(pkg / 'scripts' / 'exam_node.py', '#!/usr/bin/env python3\nimport rospy\nrospy.init_node("e")\n')
    write(pkg / 'scripts' / 'helper.py', 'x = 1\n')
    text = ('<launch><node pkg="exam" type="exam_node" name="exam"/><node pkg="exam" type="helper.py" name="h"/>'
            '<node pkg="exam" type="nothing" name="n"/></launch>')
    path = write(pkg / 'launch' / 'exam.launch', text)
    analysis = launch.analyse(str(path), str(pkg))
    changes, notes = source.node_type_fixes(str(pkg), analysis.exam_nodes)
    assert sorted(changes.values()) == ['exam_node.py'], 'a type that names a file, or no script, is left'
    assert notes == ['the launch file starts type="exam_node", which is no file of the package: run as '
                     '"exam_node.py" (scripts/exam_node.py), as a teacher would fix it']
    derived = ET.parse(launch.derive(analysis, 'main', changes)).getroot()
    assert [n.get('type') for n in derived.findall('node')] == ['exam_node.py', 'helper.py', 'nothing']
    assert path.read_text() == text

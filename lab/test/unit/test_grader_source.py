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
    from exam_lab.grader.boxed import derive, launch
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
    derived = ET.parse(derive.derive(analysis, 'main', changes)).getroot()
    assert [n.get('type') for n in derived.findall('node')] == ['exam_node.py', 'helper.py', 'nothing']
    assert path.read_text() == text


#: A node that does everything the checks look for, each in a comment and a string only.
MENTIONS = '''#!/usr/bin/env python3
"""Docstring: rospy.init_node('x'), rospy.get_param('~threshold'), rospy.ServiceProxy('w', W),
led('WARNING'), pub.publish(1.0), rospy.Timer(d, f), '/temperature', '/pressure', argv[1]."""
# rospy.init_node('x'); t = rospy.get_param('~threshold'); led = rospy.ServiceProxy('w', W); led('WARNING')
# pub.publish(1.0); rospy.Rate(10); parser.add_argument('--threshold'); rospy.myargv()[1]
text = "rospy.init_node('x') rospy.get_param('~threshold') rospy.ServiceProxy('w', W) wait_for_service"
more = "pub.publish(x) rospy.Timer(d, f) rospy.myargv()[1] add_argument('--threshold') sys.argv[2]"
'''
#: The same calls in code, with the lines they are on.
CODE = '''#!/usr/bin/env python3
import argparse, sys, rospy
def main():
    argv = rospy.myargv(argv=sys.argv)
    parser = argparse.ArgumentParser()
    parser.add_argument('--threshold', type=float)
    rospy.init_node('exam')
    limit = rospy.get_param(param_name='~seuil')
    led = rospy.ServiceProxy('/altitude_warning', W)
    rospy.Subscriber('/temperature', F, f)
    rospy.Subscriber('pressure', F, g)
    pub = rospy.Publisher('/altitude', F, queue_size=1)
    rate = rospy.Rate(10)
    pub.publish(float(argv[1]))
    led('WARNING')
    led.call('NORMAL')
    rospy.ServiceProxy('/altitude_warning', W)('NORMAL')
'''


def test_code_is_read_as_code_never_comments_or_strings(tmp_path):
    """Issue 36 point 5: each check that reads the code holds against a comment and a string (a
    docstring too) that mention what it looks for; the same calls as code are found, with their lines."""
    pkg = tmp_path / 'exam'
    write(pkg / 'scripts' / 'exam_node.py', MENTIONS)
    assert source.node_scripts(str(pkg)) == []
    assert source.param_names(str(pkg)) == []
    assert source.args_read(str(pkg)) == []
    assert not source.calls_a_service(str(pkg))
    assert source.code_evidence(str(pkg)) == {'service_calls': [], 'publishes': [], 'timers': []}
    assert source.sheets_in_code(str(pkg)) == [], 'a docstring names no topic the node uses'
    write(pkg / 'scripts' / 'exam_node.py', MENTIONS + CODE.split('\n', 1)[1])
    assert [os.path.basename(p) for p in source.node_scripts(str(pkg))] == ['exam_node.py']
    assert source.param_names(str(pkg)) == ['~seuil']
    assert source.args_read(str(pkg)) == ['--threshold', 'argv[1]']
    assert source.calls_a_service(str(pkg))
    offset = len(MENTIONS.splitlines()) - 1
    found = source.code_evidence(str(pkg))
    assert found == {'service_calls': ['scripts/exam_node.py:%d' % (n + offset) for n in (15, 16, 17)],
                     'publishes': ['scripts/exam_node.py:%d' % (14 + offset)],
                     'timers': ['scripts/exam_node.py:%d' % (13 + offset)]}
    assert source.sheets_in_code(str(pkg)) == ['altitude']
    assert source.private_before_init(str(pkg)) == [], 'the comment\'s ~threshold above init_node is no read'
    assert source.unparsed(str(pkg)) == []


def test_a_file_that_does_not_parse_is_read_as_text_and_said_so(tmp_path):
    pkg = tmp_path / 'exam'
    write(pkg / 'scripts' / 'exam_node.py', '#!/usr/bin/env python\nimport rospy\n# rospy.ServiceProxy\n'
                                            'rospy.init_node("e")\nt = rospy.get_param("~seuil")\nprint "x"\n')
    assert source.unparsed(str(pkg)) == ['scripts/exam_node.py does not parse as Python 3 (SyntaxError at line 6): '
                                         'what it does was read from its text, comments dropped']
    assert [os.path.basename(p) for p in source.node_scripts(str(pkg))] == ['exam_node.py']
    assert source.param_names(str(pkg)) == ['~seuil']
    assert not source.calls_a_service(str(pkg)), 'the comment is dropped before the text is read'
    assert source.code_evidence(str(pkg))['service_calls'] == []


def test_a_private_parameter_read_before_init_node_is_named(tmp_path):
    """Before ``init_node`` rospy's caller id is ``<ns>/unnamed`` (rospy/names.py), so ``~threshold``
    then reads ``/unnamed/threshold``, never the node's: named with its line, and so is one read when
    the module is imported (before ``main()`` starts the node). A relative or global name read then, a
    private one read after, and one in a function of its own are not."""
    pkg = tmp_path / 'exam'
    write(pkg / 'scripts' / 'exam_node.py', 'import rospy\nLIMIT = rospy.get_param("~early", 1)\n'
                                            'def helper():\n    return rospy.get_param("~later")\n'
                                            'def main():\n    t = rospy.get_param("~threshold", 1300)\n'
                                            '    g = rospy.get_param("threshold")\n    rospy.init_node("exam")\n'
                                            '    r = rospy.get_param("~rate")\n'
                                            'if __name__ == "__main__":\n    main()\n')
    assert source.private_before_init(str(pkg)) == ['scripts/exam_node.py:2: ~early', 'scripts/exam_node.py:6: ~threshold']
    write(pkg / 'scripts' / 'exam_node.py', 'import rospy\nt = rospy.get_param("~threshold")\nrospy.init_node("e")\n')
    assert source.private_before_init(str(pkg)) == ['scripts/exam_node.py:2: ~threshold']

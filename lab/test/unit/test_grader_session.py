"""What the session reads in roslaunch's output, and which sheet it grades."""
from exam_lab.grader.host import run as host_run

DIED = ('\x1b[1mprocess[exam-1]: started with pid [17908]\x1b[0m\n'
        'Traceback (most recent call last):\n'
        '  File "/tmp/w/ws/src/exam/scripts/exam_node.py", line 26, in <module>\n'
        "KeyError: '~threshold'\n"
        '\x1b[31m================REQUIRED process [exam-1] has died!\n'
        'process has died [pid 17908, exit code 1, cmd /tmp/w/ws/devel/lib/exam/exam_node.py].\n'
        'Initiating shutdown!\n==========\x1b[0m\n[exam-1] killing on exit\n')


def test_a_required_node_that_died():
    outcome = host_run.launch_outcome(DIED, '/tmp/w/ws')
    assert outcome['ended'] == [{'node': 'exam-1', 'how': 'died', 'detail': 'exit code 1'}]
    assert 'exam/scripts/exam_node.py' in outcome['tail'] and '/tmp/w' not in outcome['tail']
    assert 'killing on exit' not in outcome['tail'] and '\x1b' not in outcome['tail']


def test_a_plain_node_that_finished_and_one_not_found():
    text = ('[exam-2] process has finished cleanly\n'
            'ERROR: cannot launch node of type [exam/exam_nod.py]: Cannot locate node of type [exam_nod.py]\n')
    outcome = host_run.launch_outcome(text)
    assert outcome['ended'] == [{'node': 'exam-2', 'how': 'finished cleanly', 'detail': ''}]
    assert outcome['not_started'][0].startswith('ERROR: cannot launch node')
    assert host_run.launch_outcome('[exam-1] killing on exit\n')['ended'] == []


def test_sheet_detection(tmp_path):
    from exam_lab.grader import runner
    from exam_lab.grader.boxed import derive, inspect, launch
    pkg = tmp_path / 'exam'
    (pkg / 'launch').mkdir(parents=True)
    (pkg / 'package.xml').write_text('<package><name>exam</name><depend>mydrone</depend>'
                                     '<depend>submarinedrone</depend></package>')
    assert inspect.detect_sheet('depth', str(pkg), [])[0] == 'depth'
    assert inspect.detect_sheet(None, str(pkg), [])[0] == 'altitude'
    assert 'SHEET=depth' in inspect.detect_sheet(None, str(pkg), [])[1], 'an ambiguous package says how to choose'
    (pkg / 'launch' / 'exam.launch').write_text('<launch><node pkg="submarinedrone" type="submarine_drone_node.py" '
                                                'name="d"/><node pkg="exam" type="n.py" name="exam"/></launch>')
    analyses = [launch.analyse(p, str(pkg)) for p in derive.launch_files(str(pkg))]
    assert inspect.detect_sheet(None, str(pkg), analyses)[0] == 'depth'
    (pkg / 'package.xml').write_text('<package><name>exam</name><exec_depend>mydrone</exec_depend></package>')
    assert inspect.detect_sheet(None, str(pkg), analyses)[0] == 'altitude', 'package.xml first'
    assert runner.margin_of(1300.0) == 130.0 and runner.margin_of(50.0) == 10.0



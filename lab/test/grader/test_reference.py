"""The reference outputs of the report's questions come from running the project's own drones
(host/reference.py, issue 47 point 3): a master and the drone in a network namespace, the course's
commands run against them, nothing typed into the grader."""
import pytest

from exam_lab.grader.host import reference
from exam_lab.grader.host.underlay import default_underlay, ensure_underlay
from exam_lab.grader.score.reference import facts


@pytest.mark.parametrize('sheet, node, topics, rate', [
    ('altitude', '/mydrone', ['/pressure', '/rosout', '/temperature'], 0.778),
    ('depth', '/submarine_drone', ['/pressure_remote', '/pressure_robot', '/rosout'], 2.0)])
def test_the_capture_runs_the_drone_and_finds_its_node_and_topics(sheet, node, topics, rate):
    record = reference.captured(sheet, ensure_underlay(default_underlay()))
    found = facts(record)
    assert found['nodes'] == sorted(['/rosout', node]) and found['node'] == node
    assert found['topics'] == topics
    assert found['type'] == 'std_msgs/Float32' and found['fields'] == ['float32 data']
    assert found['rate'] == rate and found['measured'] == pytest.approx(rate, rel=0.05)
    assert 'Pid:' in record.commands['rosnode_info'].output
    assert 'transport: TCPROS' in record.commands['rosnode_info'].output
    assert record.commands['rostopic_echo'].output.count('data:') == 3
    assert found['created'] == ['exam/CMakeLists.txt', 'exam/package.xml']

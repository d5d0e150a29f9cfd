"""Similarity: two renamed copies of one node are flagged, an independent solution is not, and the
boilerplate every student shares (catkin_create_pkg's files, the launch skeleton) counts for nothing.

Runs copydetect in its own virtual environment ($EXAM_WS/similarity-venv, installed from PyPI on
first use: about 20 s once, then 2 s a run).
"""
import json
import os
import re
import shutil
import subprocess

import pytest

from exam_lab.grader.boxed import similarity
from exam_lab.grader.host import similarity_setup


def root_check(subs, out, scratch):
    """The check as the class run makes it: root's venv and boilerplate (host.similarity_setup), then
    the box's comparison."""
    return similarity.check(subs, out, similarity_setup.ensure_venv(),
                            similarity_setup.boilerplate(os.path.join(str(scratch), 'boilerplate')))

HERE = os.path.dirname(os.path.realpath(__file__))
ORIGINAL = os.path.join(HERE, '..', 'grader', 'submissions', 'good_student', 'exam')

#: An independent solution of sheet 000: a class, time stamps instead of a counter, no globals.
INDEPENDENT = '''#!/usr/bin/env python3
"""Altitude of the drone and its warning LED."""
import math
import threading

import rospy
from std_msgs.msg import Float32
from mydrone.srv import AltitudeWarning


class AltitudeWatch(object):
    def __init__(self):
        self.limit = float(rospy.get_param('~threshold'))
        self.lock = threading.Lock()
        self.readings = {}
        self.above_since = None
        self.led = None
        self.out = rospy.Publisher('altitude', Float32, queue_size=1)
        self.warn = rospy.ServiceProxy('altitude_warning', AltitudeWarning)
        for topic in ('temperature', 'pressure'):
            rospy.Subscriber(topic, Float32, self.keep, callback_args=topic)
        rospy.Timer(rospy.Duration(0.1), self.tick)

    def keep(self, msg, topic):
        with self.lock:
            self.readings[topic] = msg.data

    def tick(self, _event):
        with self.lock:
            if len(self.readings) < 2:
                return
            kelvin = self.readings['temperature'] + 273.15
            ratio = 101325.0 / self.readings['pressure']
        h = 8.31432 * kelvin / (0.0289644 * 9.80665) * math.log(ratio)
        self.out.publish(Float32(h))
        now = rospy.get_time()
        if h <= self.limit:
            self.above_since = None
            wanted = 'NORMAL'
        else:
            self.above_since = self.above_since or now
            wanted = 'WARNING' if now - self.above_since >= 5.0 else self.led
        if wanted is not None and wanted != self.led:
            self.warn(wanted)
            self.led = wanted


if __name__ == '__main__':
    rospy.init_node('exam')
    AltitudeWatch()
    rospy.spin()
'''

RENAMES = {'temperature': 'temp_c', 'pressure': 'press_pa', 'callback_temperature': 'on_temp',
           'callback_pressure': 'on_press', 'compute_altitude': 'altitude_of', 'counter': 'ticks_above',
           'warning': 'is_red', 'set_led': 'led_service', 'pub': 'publisher', 'threshold': 'limit',
           'altitude': 'alt_m', 't_kelvin': 'tk', 't_celsius': 'tc'}


def renamed(code):
    """The original with every name changed, comments reworded and blank lines moved: a copy that
    hides itself as a student would."""
    names = [n for n in RENAMES if n not in ('temperature', 'pressure', 'altitude', 'threshold')]
    for old in names:
        code = re.sub(r'\b%s\b' % old, RENAMES[old], code)
    code = re.sub(r'^(temperature|pressure) = None', lambda m: RENAMES[m.group(1)] + ' = None', code, flags=re.M)
    code = re.sub(r'\bglobal (temperature|pressure)\b', lambda m: 'global ' + RENAMES[m.group(1)], code)
    code = re.sub(r'^(\s*)(temperature|pressure) = msg.data', lambda m: m.group(1) + RENAMES[m.group(2)] + ' = msg.data',
                  code, flags=re.M)
    code = re.sub(r'\bif temperature is not None and pressure is not None',
                  'if temp_c is not None and press_pa is not None', code)
    code = code.replace('altitude_of(temperature, pressure)', 'altitude_of(temp_c, press_pa)')
    code = re.sub(r'#.*$', '# my own comment', code, flags=re.M)
    return code.replace('\n\n\n', '\n\n')


@pytest.fixture(scope='module')
def result(tmp_path_factory):
    root = tmp_path_factory.mktemp('similarity')
    subs = []
    for name, node in (('alice', None), ('bob', 'renamed'), ('carol', 'independent')):
        package = root / name / 'exam'
        shutil.copytree(ORIGINAL, str(package))
        script = package / 'scripts' / 'exam_node.py'
        if node == 'renamed':
            script.write_text(renamed(script.read_text()))
        elif node == 'independent':
            script.write_text(INDEPENDENT)
        subs.append((name, str(root / name)))
    out = root / 'out'
    out.mkdir()
    got = root_check(subs, str(out), root)
    assert 'error' not in got, got.get('error')
    with open(str(out / 'similarity.json')) as f:
        assert json.load(f)['pairs'] == got['pairs']
    return got


def test_renamed_copies_are_flagged(result):
    pairs = {(p['a'], p['b']): p for p in result['pairs']}
    assert ('alice', 'bob') in pairs, result
    pair = pairs[('alice', 'bob')]
    assert min(pair['score_a'], pair['score_b']) >= 0.8
    assert pair['files'][0]['file_a'] == 'scripts/exam_node.py'
    assert "<span class='highlight-red'>" in pair['files'][0]['html_a']
    assert "<span class='highlight-green'>" in pair['files'][0]['html_b']


def test_an_independent_solution_is_not(result):
    flagged = {name for p in result['pairs'] for name in (p['a'], p['b'])}
    assert 'carol' not in flagged, result['pairs']
    assert result['students'] == 3


def test_the_shared_boilerplate_counts_for_nothing(tmp_path):
    """Two packages that hold nothing but catkin_create_pkg's files and the launch skeleton."""
    subs = []
    for name in ('dan', 'erin'):
        where = tmp_path / name
        where.mkdir()
        subprocess.run(['catkin_create_pkg', 'exam', 'rospy', 'std_msgs', 'mydrone'], cwd=str(where), check=True,
                       stdout=subprocess.DEVNULL)
        (where / 'exam' / 'launch').mkdir()
        (where / 'exam' / 'launch' / 'exam.launch').write_text(
            '<launch>\n  <node pkg="mydrone" name="mydrone" type="mydrone_node.py" output="screen"/>\n'
            '  <node pkg="exam" name="exam" type="exam_node.py" output="screen">\n'
            '    <param name="threshold" value="1300" />\n  </node>\n</launch>\n')
        subs.append((name, str(where)))
    got = root_check(subs, str(tmp_path), tmp_path)
    assert got.get('pairs') == [], got


def test_code_files_are_the_package_code(tmp_path):
    for relative in ('scripts/a.py', 'launch/x.launch', 'CMakeLists.txt', 'package.xml', 'README.md',
                     'build/junk.py', '.git/x.py', 'report.pdf'):
        os.makedirs(os.path.dirname(str(tmp_path / relative)) or str(tmp_path), exist_ok=True)
        (tmp_path / relative).write_text('x = 1\n')
    assert similarity.code_files(str(tmp_path)) == ['CMakeLists.txt', 'launch/x.launch', 'package.xml', 'scripts/a.py']


def test_what_is_read_of_a_student_is_its_code_bounded(tmp_path, monkeypatch):
    """Issue 36 point 3: a student's data (YAML, logs) is never read, and of its code at most
    MAX_STUDENT_FILES / MAX_STUDENT_BYTES, programs first: no student can make the check too slow for
    the class. What was left out is said."""
    package = tmp_path / 'up' / 'exam'
    for relative, size in (('scripts/exam_node.py', 100), ('src/helper.cpp', 100), ('launch/a.launch', 100),
                           ('package.xml', 100), ('config/big.yaml', 1000), ('config/more.yml', 1000)):
        os.makedirs(os.path.dirname(str(package / relative)), exist_ok=True)
        (package / relative).write_text('x' * size)
    assert similarity.code_files(str(package)) == ['launch/a.launch', 'package.xml', 'scripts/exam_node.py',
                                                   'src/helper.cpp']
    monkeypatch.setattr(similarity, 'MAX_STUDENT_FILES', 3)
    monkeypatch.setattr(similarity, 'MAX_STUDENT_BYTES', 250)
    assert similarity.student_code(str(package)) == (['scripts/exam_node.py', 'src/helper.cpp'],
                                                     ['launch/a.launch', 'package.xml'])
    staged, notes = similarity.stage([('dee', str(tmp_path / 'up'))], str(tmp_path / 'staged'))
    assert sorted(os.listdir(os.path.join(staged['dee'], 'scripts'))) == ['exam_node.py']
    assert not os.path.exists(os.path.join(staged['dee'], 'config'))
    assert notes == ["dee: 2 code file(s) compared, 2 left out (at most 3 files and 250 bytes of a student): "
                     "'launch/a.launch', 'package.xml'"]

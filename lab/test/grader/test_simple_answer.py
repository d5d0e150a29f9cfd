"""The simple answer of docs/report.md (docs/simple_answer/exam, what a student can write in three
hours) gets full marks on both sheets from the grader, stays out of every catkin build of this
repository (it is a second package named ``exam``), and `make run-simple` builds and runs it on its own
for both sheets. About 45 s per sheet graded, and a build of five packages (node_kit, drone_sim, mydrone,
submarinedrone and the simple answer's exam).
"""
import os
import re
import shutil
import subprocess

import pytest
from catkin_pkg.packages import find_packages

from exam_lab.grader.score.sheets import ITEMS, SHEETS
from exam_lab.harness.supervisor import Supervisor
from exam_lab.harness.wait import wait_until

REPO = os.path.realpath(os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', '..'))
SIMPLE = os.path.join(REPO, 'docs', 'simple_answer', 'exam')
#: What `make run-simple` runs.
RUN_SIMPLE = os.path.join(REPO, 'docs', 'simple_answer', 'run.sh')


@pytest.mark.parametrize('sheet', ['altitude', 'depth'])
def test_the_simple_answer_gets_full_marks(singles, sheet):
    record = singles['simple_' + sheet]  # graded alone on the sheet (conftest.py ``singles``, class_runs.py)
    got = {i['id']: i['points'] for i in record['items']}
    evidence = '\n'.join('%s %s/%s: %s' % (i['id'], i['points'], i['max'], i['evidence']) for i in record['items'])
    assert got == {item: points for item, (points, _) in ITEMS.items()}, evidence
    assert record['total'] == record['max'] == 17.0


#: Python files of :func:`many_files`: one over what the inspection's record lists (records.MAX_ITEMS).
MANY_FILES = 501


def many_files(target):
    """The simple answer and tiny modules beside it (``src/exam_parts/m000.py``: ``x = 0``), MANY_FILES
    Python files in all, written as ``target/exam``; returns that folder."""
    package = os.path.join(target, 'exam')
    shutil.copytree(SIMPLE, package)
    own = sum(name.endswith('.py') for _, _, names in os.walk(package) for name in names)
    os.makedirs(os.path.join(package, 'src', 'exam_parts'))
    for index in range(MANY_FILES - own):
        with open(os.path.join(package, 'src', 'exam_parts', 'm%03d.py' % index), 'w') as f:
            f.write('x = %d\n' % index)
    return package


def test_501_python_files_are_graded_on_what_fits_with_a_sentence(singles):
    """Issue 36 point 6: a package of 501 Python files, one more than inspect.json lists, was "not
    graded" (its record failed its schema). Graded on what fits, it keeps every machine point, and the
    teacher reads the cap and the value."""
    record = singles['simple_many_files']  # graded alone (class_runs.py SINGLES)
    got = {i['id']: i['points'] for i in record['items']}
    evidence = '\n'.join('%s %s/%s: %s' % (i['id'], i['points'], i['max'], i['evidence']) for i in record['items'])
    assert got == {item: points for item, (points, _) in ITEMS.items()}, evidence
    assert record['status'] in ('graded', 'graded with fixes'), record['status_reason']
    assert '%d Python files (at most 500): the first 500 are read for comments' % MANY_FILES in record['for_the_teacher']


def test_the_simple_answer_is_no_package_of_the_repository():
    # catkin_make in a workspace holding this repository (README: "In your own catkin workspace")
    # finds packages the way catkin_pkg does: the simple answer's CATKIN_IGNORE keeps it out.
    names = [package.name for package in find_packages(REPO).values()]
    assert names.count('exam') == 1, names
    assert os.path.isfile(os.path.join(SIMPLE, 'package.xml'))


def test_run_simple_builds_the_simple_answer_alone_and_runs_both_sheets(tmp_path):
    # The build first, bounded (four packages; minutes on a loaded machine), then each sheet's launch
    # on a master of its own: its node must be the simple answer's (its first line is "threshold
    # 1300.0 m"; ours starts with its mode) and publish the sheet's output, and Ctrl-C must end it.
    build = subprocess.run([RUN_SIMPLE, '--build-only', 'altitude'], stdout=subprocess.PIPE,
                           stderr=subprocess.STDOUT, timeout=900)
    assert build.returncode == 0, build.stdout.decode(errors='replace')[-3000:]
    with Supervisor(str(tmp_path)) as supervisor:
        for name, sheet in SHEETS.items():
            master = supervisor.start_master(name + '.master')
            launch = supervisor.start(name, [RUN_SIMPLE, name], master.env)
            published = wait_until(lambda: master.publishers('/' + sheet.output), 60.0,
                                   alive=lambda: launch.poll() is None)
            assert published, supervisor.output(name)[-3000:]
            status, echoed, _ = supervisor.run(name + '.echo', ['rostopic', 'echo', '-n', '1', '/' + sheet.output],
                                               30.0, master.env)
            assert status == 0 and 'data: ' in echoed, echoed
            own_line = re.compile(r'\]: threshold %.1f m$' % sheet.threshold, re.M)
            assert wait_until(lambda: own_line.search(supervisor.output(name)), 10.0), supervisor.output(name)[-3000:]
            assert supervisor.stop(launch) == 0, supervisor.output(name)[-3000:]
            supervisor.stop(master.proc)

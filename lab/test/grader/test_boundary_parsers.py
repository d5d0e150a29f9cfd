"""The grader's parsers against hostile students (issue 26 point 1): one class run with ``JOBS=2``.

The class: ``a_leaker`` (its launch file names a variable of the grader's, the drone's launch file
through a path of the grader's workspace, an include and a root-only YAML outside the package) and
``b_bomber`` (a second launch file loads a YAML alias bomb; a crafted PDF report of 2 MB beside the
package). Each is the good student's package with the files of lab/test/grader/hostile/leaker or
bomber copied over it: nothing of theirs runs as root, the grader only reads them. The class is graded in a child
process with a deadline, so that a parser that never ends fails the test instead of hanging it.
About 2 minutes on two cores.
"""
import json
import os
import secrets
import shutil
import subprocess
import sys

import pytest

from test_sandbox import VICTIM, files_under

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
HOSTILE = os.path.join(HERE, 'hostile')
#: Where the leaker's launch file points outside its package (its launch file names this folder).
OUTSIDE = '/tmp/exam-hostile-parsers'
CLASS = [('a_leaker', os.path.join(HOSTILE, 'leaker', 'exam')), ('b_bomber', os.path.join(HOSTILE, 'bomber', 'exam'))]
#: The whole class's deadline: about 2 minutes when nothing hangs (a backtracking PDF reader took hours).
CLASS_TIMEOUT = 900
#: Folders of the grader's side where a derived ``.grader-*`` copy was written beside an included file.
GRADER_FOLDERS = (OUTSIDE, os.path.join(REPO, 'mydrone'), os.path.join(REPO, 'submarinedrone'), HOSTILE)


def crafted_pdf(path, size=2 << 20):
    """A PDF made for a backtracking reader: page tree nodes that never close, then ``stream`` lines
    with nothing to inflate; no real page tree, so its page count is unknown."""
    half = size // 2
    with open(path, 'wb') as f:
        f.write(b'%PDF-1.5\n<< /Type /Pages ' + b'/Type /Pages /Count 1 ' * (half // 22) + b'\n'
                + b'stream\n' * (half // 7))


def derived_files(folders):
    return sorted(os.path.join(dirpath, name) for folder in folders for dirpath, _, names in os.walk(folder)
                  for name in names if name.startswith('.grader-'))


@pytest.fixture(scope='module')
def parsed_class(tmp_path_factory):
    """Grade the class once, with a secret variable of the grader's and a root-only YAML and launch
    file outside the packages in place; clean everything up."""
    if os.geteuid() != 0:
        pytest.skip('the sandbox is made by root (docs/grading.md, "Isolation")')
    root = tmp_path_factory.mktemp('parsers')
    klass = root / 'class'
    for name, hostile in CLASS:
        shutil.copytree(VICTIM, str(klass / name / 'exam'), ignore=shutil.ignore_patterns('__pycache__'))
        shutil.copytree(hostile, str(klass / name / 'exam'), dirs_exist_ok=True)
    crafted_pdf(str(klass / 'b_bomber' / 'report.pdf'))
    token = secrets.token_hex(8)
    shutil.rmtree(OUTSIDE, ignore_errors=True)
    os.makedirs(OUTSIDE)
    outside_texts = {'secret.yaml': 'threshold_root_only_%s: 1300\n' % token,
                     'outside.launch': '<launch><param name="outside_%s" value="1300"/></launch>\n' % token}
    for name, text in outside_texts.items():
        with open(os.open(os.path.join(OUTSIDE, name), os.O_WRONLY | os.O_CREAT, 0o600), 'w') as f:
            f.write(text)
    secret_var = 'grader-env-%s' % secrets.token_hex(8)
    before = derived_files(GRADER_FOLDERS)
    out, records_path = root / 'out', root / 'records.json'
    code = ('import json, sys\nfrom exam_lab.grader import runner\n'
            'records = runner.grade_class(sys.argv[1], sys.argv[2], jobs=2)\n'
            'with open(sys.argv[3], "w") as f:\n    json.dump(records, f)\n')
    env = dict(os.environ, EXAM_HOSTILE_PARSERS_SECRET=secret_var)
    env.setdefault('EXAM_WS', os.path.join(REPO, '.ws'))
    try:
        try:
            done = subprocess.run([sys.executable, '-c', code, str(klass), str(out), str(records_path)], env=env,
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=CLASS_TIMEOUT)
            finished, output = done.returncode == 0, done.stdout.decode('utf-8', 'replace')[-3000:]
        except subprocess.TimeoutExpired:
            finished, output = False, 'the class did not finish within %d s' % CLASS_TIMEOUT
        records = {}
        if finished:
            with open(str(records_path)) as f:
                records = {r['student']: r for r in json.load(f)}
        yield {'out': str(out), 'records': records, 'finished': finished, 'output': output,
               'secrets': (token, secret_var), 'new_derived': sorted(set(derived_files(GRADER_FOLDERS)) - set(before)),
               'outside': sorted(os.listdir(OUTSIDE))}
    finally:
        shutil.rmtree(OUTSIDE, ignore_errors=True)
        for path in set(derived_files(GRADER_FOLDERS)) - set(before):
            os.remove(path)


def notes_of(record):
    return '\n'.join(record['for_the_teacher'])


def test_the_class_finishes(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    with open(os.path.join(parsed_class['out'], 'grades.csv')) as f:
        rows = f.read().splitlines()[1:]
    assert sorted(row.split(',')[0] for row in rows) == [name for name, _ in CLASS]


def test_no_secret_of_the_grader_reaches_the_results(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    for path, text in files_under(parsed_class['out']):
        for secret in parsed_class['secrets']:
            assert secret not in text, path


def test_nothing_outside_the_package_is_read_or_written(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    assert parsed_class['new_derived'] == [], 'derived copies written outside the work folder'
    assert parsed_class['outside'] == ['outside.launch', 'secret.yaml']
    notes = notes_of(parsed_class['records']['a_leaker'])
    for written in ('$(optenv EXAM_WS /nonexistent)/../mydrone/launch/mydrone.launch',
                    '/tmp/exam-hostile-parsers/outside.launch', '/tmp/exam-hostile-parsers/secret.yaml'):
        assert 'file outside the package: ' in notes and written in notes, notes


def test_the_bomb_and_the_pdf_say_why(parsed_class):
    assert parsed_class['finished'], parsed_class['output']
    record = parsed_class['records']['b_bomber']
    assert 'config/bomb.yaml not read: YAML anchors and aliases (&name, *name) are refused' in notes_of(record)
    assert record['documents'] == [{'name': 'report.pdf', 'pages': None}], 'the page says "pages unknown"'

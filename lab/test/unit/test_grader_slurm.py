"""The Slurm engine's own logic, without Slurm: what it reads of squeue and scontrol, what it submits,
and the retry rule (a task that ends without a grade is submitted once more, then is "not graded" with
Slurm's words), against a scripted Slurm. lab/test/grader/test_slurm.py runs it on a real one."""
import csv
import json
import os
import zipfile

import pytest

from exam_lab.grader import class_run
from exam_lab.grader.host import underlay
from exam_lab.grader.publish import grades, report
from exam_lab.grader.engine import slurm


def test_array_spec_joins_consecutive_indices():
    assert slurm.array_spec(range(60)) == '0-59'
    assert slurm.array_spec([17, 3, 18]) == '3,17-18'
    assert slurm.array_spec([5]) == '5'


def test_squeue_lines_give_each_task_its_state_and_reason():
    text = '12 0 RUNNING None\n12 [1-3,5%2] PENDING Resources\n13 4 PENDING Priority\n'
    tasks = slurm.parse_squeue(text)
    assert tasks[('12', 0)] == ('RUNNING', 'None')
    assert sorted(i for j, i in tasks if j == '12') == [0, 1, 2, 3, 5]
    assert tasks[('12', 5)] == ('PENDING', 'Resources')
    assert tasks[('13', 4)] == ('PENDING', 'Priority')


def test_what_slurm_said_of_a_task():
    fields = slurm.parse_scontrol('JobId=14 ArrayJobId=12 ArrayTaskId=2 JobName=exam-grade-out\n'
                                  '   JobState=CANCELLED Reason=None Dependency=(null)\n'
                                  '   Requeue=1 Restarts=0 BatchFlag=1 Reboot=0 ExitCode=0:15\n')
    assert slurm.slurm_said(fields) == 'CANCELLED, exit code 0:15'
    fields = slurm.parse_scontrol('JobState=TIMEOUT Reason=TimeLimit ExitCode=0:0')
    assert slurm.slurm_said(fields) == 'TIMEOUT, reason TimeLimit'
    assert slurm.slurm_said({}, ('PENDING', 'Resources')) == \
        'the task left the queue and Slurm keeps no record of it (last seen PENDING, Resources)'
    assert slurm.slurm_said({}) == 'the task left the queue and Slurm keeps no record of it'


def test_a_lost_node_is_named():
    fields = slurm.parse_scontrol('JobId=15 JobState=NODE_FAIL Reason=NodeDown Dependency=(null)\n'
                                  '   NodeList=exam-node1 BatchHost=exam-node1 ExitCode=0:0\n')
    assert slurm.slurm_said(fields) == 'NODE_FAIL on node exam-node1 (the node stopped answering the ' \
                                       'controller: its task is lost), reason NodeDown'
    assert slurm.slurm_said(slurm.parse_scontrol('JobState=CANCELLED NodeList=(null) ExitCode=0:15')) == \
        'CANCELLED, exit code 0:15'


def test_the_state_line_counts_pending_running_and_done():
    tasks = {('12', 0): ('RUNNING', 'None'), ('12', 1): ('PENDING', 'Resources'), ('13', 2): ('PENDING', 'Priority')}
    assert slurm.state_line(['12', '13'], tasks, 3, 1, 8) == \
        'slurm job 12+13: 2 pending, 1 running, 4 done of 8 (1 not graded)'
    assert slurm.state_line(['12', '13'], tasks, 3, 0, 8, again=2) == \
        'slurm job 12+13 (2 tasks submitted again): 2 pending, 1 running, 3 done of 8'


#: How a scripted task may end besides leaving its grade (any other text: the result file it leaves).
ENDS = ('record', 'queued') + slurm.ENDED


def graded(name, participant=None, folder=None):
    """A grade record as a task leaves it (report.grade_record's: a record of the grader), of the
    participant and Moodle's folder its manifest line names (the array's students: ``/class/<name>``)."""
    return report.grade_record(name, 'altitude', [], [], {'seconds': 1.0, 'participant': participant,
                                                          'folder': folder or name})


class ScriptedSlurm(object):
    """sbatch gives job ids 100, 101...; a task is in the queue for one look, then ends as ``ends``
    says for that attempt (``'record'``: it leaves its grade, as a good task does; ``'queued'``: it
    waits in the queue for ever)."""

    def __init__(self, base, ends):
        self.base, self.ends = base, ends
        self.calls, self.queued, self.attempt = [], set(), {}
        self.next_job = 100

    def __call__(self, argv):
        self.calls.append(argv)
        if argv[0] == 'sbatch':
            job = str(self.next_job)
            self.next_job += 1
            for index in slurm._indices(argv[argv.index('--array') + 1]):
                self.attempt[index] = self.attempt.get(index, 0) + 1
                self.queued.add((job, index))
            return 0, '%s\n' % job, ''
        if argv[0] == 'squeue':
            lines = []
            for key in sorted(self.queued):
                job, index = key
                end = self.ends[index][self.attempt[index] - 1]
                lines.append('%s %d %s' % (job, index, 'PENDING Resources' if end == 'queued' else 'RUNNING None'))
                if end == 'queued':
                    continue
                self.queued.discard(key)
                if end == 'record':
                    with open(os.path.join(self.base, 'results', '%d.json' % index), 'w') as f:
                        json.dump(graded('s%d' % index), f)
                elif end not in ENDS:  # the task left this text as its result (then ended COMPLETED)
                    with open(os.path.join(self.base, 'results', '%d.json' % index), 'w') as f:
                        f.write(end)
            return 0, '\n'.join(lines), ''
        if argv[0] == 'scontrol':
            index = int(argv[-1].split('_')[1])
            end = self.ends[index][self.attempt[index] - 1]
            return 0, 'JobState=%s Reason=None ExitCode=0:9' % (end if end in ENDS else 'COMPLETED'), ''
        return 0, '', ''


@pytest.fixture
def array(tmp_path, monkeypatch):
    def make(ends):
        base = str(tmp_path / '.slurm')
        for sub in ('results', 'logs'):
            os.makedirs(os.path.join(base, sub))
        fake = ScriptedSlurm(base, ends)
        monkeypatch.setattr(slurm, '_call', fake)
        students = [('s%d' % i, '/class/s%d' % i) for i in range(len(ends))]
        lines = []
        return slurm._Array(students, base, os.path.join(base, 'task.sh'), 'exam-grade-out', ['--partition=p'],
                            None, str(tmp_path), lines.append, None), fake, lines
    return make


def test_a_task_that_fails_is_submitted_once_more_then_not_graded_with_slurms_words(array):
    run, fake, lines = array([['record'], ['NODE_FAIL', 'record'], ['CANCELLED', 'CANCELLED']])
    run.submit(range(3))
    for now in range(4):
        run.look(float(now))
    assert [c[c.index('--array') + 1] for c in fake.calls if c[0] == 'sbatch'] == ['0-2', '1-2']
    assert all('--partition=p' in c for c in fake.calls if c[0] == 'sbatch')
    assert all('--no-requeue' in c for c in fake.calls if c[0] == 'sbatch'), 'the engine alone retries'
    assert [r['status'] for r in run.records] == ['graded', 'graded', 'not graded']
    assert run.records[2]['status_reason'] == 'could not grade: Slurm said: CANCELLED, exit code 0:9'
    assert os.path.isfile(os.path.join(str(run.out_dir), 's2', 'grade.json'))
    assert any('s1 (task 100_1) ended without a grade: NODE_FAIL' in line for line in lines)
    assert sum(1 for c in fake.calls if c[0] == 'sbatch') == 2, 'a second failure is not retried'


def test_a_completed_task_is_given_time_for_its_grade_to_arrive(array):
    run, fake, _ = array([['COMPLETED', 'COMPLETED']])
    run.submit([0])
    run.look(0.0)  # in the queue
    run.look(1.0)  # gone, COMPLETED, no record yet: waited for
    assert run.records == [None] and run.attempts[0] == 1
    run.look(1.0 + slurm.RESULT_GRACE_S)
    assert run.attempts[0] == 2, 'after the grace period, it is submitted again'


def test_ctrl_c_cancels_the_class_jobs(array, monkeypatch):
    run, fake, _ = array([['record'], ['record']])

    def interrupted(now):
        raise KeyboardInterrupt
    monkeypatch.setattr(run, 'look', interrupted)
    with pytest.raises(KeyboardInterrupt):
        slurm._follow(run, 0.0, None, lambda line: None)
    assert fake.calls[-1] == ['scancel', '100']


def test_out_of_time_cancels_and_says_where_each_student_was(array, monkeypatch):
    run, fake, _ = array([['record'], ['queued']])
    monkeypatch.setattr(slurm.time, 'sleep', lambda seconds: None)
    clock = iter([0.0, 5.0, 11.0])
    monkeypatch.setattr(slurm.time, 'monotonic', lambda: next(clock))
    records = slurm._follow(run, 0.0, 10.0, lambda line: None)
    assert records[0]['status'] == 'graded'
    assert records[1]['status_reason'] == \
        'could not grade: Slurm said: no grade within 10 s; last seen PENDING, Resources'
    assert ['scancel', '100'] in fake.calls


def test_a_task_of_a_student_the_intake_refused_says_why(tmp_path):
    """Issue 36 point 3: the manifest carries the intake's refusal; the task writes that student's
    "not graded" row with it (nothing of the student is run) and its measurements for a rescore."""
    manifest = tmp_path / '.slurm' / 'manifest.jsonl'
    (tmp_path / '.slurm' / 'results').mkdir(parents=True)
    why = "the files of 'Bob_12_assignsubmission_file_': 5001 more files, beyond the 5000 a submission may unpack"
    manifest.write_text(json.dumps({'student': 'Bob', 'submission': str(tmp_path / 'Bob_12_assignsubmission_file_'),
                                    'refused': why}) + '\n')
    record = slurm.run_task(str(manifest), 0, str(tmp_path))
    assert (record['status'], record['status_reason']) == ('not graded', 'submission refused: %s' % why)
    assert record['participant'] == 12
    assert json.loads((tmp_path / '.slurm' / 'results' / '0.json').read_text())['status_reason'] == record['status_reason']
    assert [r['status_reason'] for r in grades.rescore(str(tmp_path))[0]] == [record['status_reason']]


def test_a_task_says_in_the_grade_which_node_graded_it(tmp_path, monkeypatch):
    manifest = tmp_path / '.slurm' / 'manifest.jsonl'
    (tmp_path / '.slurm' / 'results').mkdir(parents=True)
    manifest.write_text(json.dumps({'student': 'Ann', 'submission': '/class/Ann'}) + '\n')
    monkeypatch.setenv('SLURMD_NODENAME', 'exam-node2')
    monkeypatch.setattr(class_run, 'grade_student', lambda name, folder, out, sheet, unsandboxed, refused=None: grades.could_not_grade(
        name, sheet, 'scripted'))
    slurm.run_task(str(manifest), 0, str(tmp_path))
    with open(str(tmp_path / 'Ann' / 'grade.json')) as f:
        assert json.load(f)['graded_on'] == 'exam-node2'
    with open(str(tmp_path / '.slurm' / 'results' / '0.json')) as f:
        assert json.load(f)['graded_on'] == 'exam-node2'


def test_a_moodle_class_zip_is_graded_as_a_folder_is(tmp_path, monkeypatch):
    """The zip a teacher downloads from Moodle: its students listed by the function the local engine
    uses (class_run.class_students, the intake in its box), unpacked on the shared OUT for the nodes, and
    removed at the end. It used to raise AttributeError before anything was submitted."""
    klass = tmp_path / 'class.zip'
    with zipfile.ZipFile(str(klass), 'w') as zf:
        for name, number in (('Ann Lee', 11), ('Bob Ray', 12)):
            zf.writestr('%s_%d_assignsubmission_file_/exam/package.xml' % (name, number),
                        '<package format="2"><name>exam</name></package>')
    out = tmp_path / 'out'
    seen = {}

    class FromManifest(ScriptedSlurm):
        """Each task "grades" its line: the submission the manifest names must be there, on OUT."""

        def __call__(self, argv):
            if argv[0] == 'squeue':
                with open(os.path.join(self.base, 'manifest.jsonl')) as f:
                    for index, line in enumerate(f):
                        entry = json.loads(line)
                        seen[entry['student']] = entry['submission']
                        assert os.path.isfile(os.path.join(entry['submission'], 'exam', 'package.xml'))
                        with open(os.path.join(self.base, 'results', '%d.json' % index), 'w') as r:
                            json.dump(dict(grades.could_not_grade(entry['student'], None, 'scripted'),
                                           participant=entry['participant'], folder=entry['folder']), r)
                return 0, '', ''
            return ScriptedSlurm.__call__(self, argv)

    monkeypatch.setattr(slurm, '_call', FromManifest(str(out / '.slurm'), {}))
    monkeypatch.setattr(underlay, 'ensure_underlay', lambda cache: cache)
    monkeypatch.setattr(slurm.shutil, 'which', lambda command: '/usr/bin/' + command)
    records = slurm.grade_class(str(klass), str(out), unsandboxed=True, poll_s=0.0)
    assert [r['student'] for r in records] == ['Ann Lee', 'Bob Ray']
    assert all(path.startswith(str(out / '.slurm' / 'class')) for path in seen.values()), seen
    with open(str(out / 'grades.csv')) as f:
        assert [row['student'] for row in csv.DictReader(f)] == ['Ann Lee', 'Bob Ray']
    assert not (out / '.slurm').exists(), 'the unpacked class is removed with the rest'


@pytest.mark.parametrize('left, why', [
    ('{"version": 1, "student": "s1", "status": "graded"}', 'grade.json: sheet is missing'),  # of another shape
    ('{"student": "s1", "status": "graded"}', 'grade.json: graded by an older grader: grade again'),  # no version
    ('{"student": "s1", "tot', 'grade.json: not JSON'),                          # cut short
    (json.dumps(graded('s0')), "grade.json: the grade of 's0', not of 's1'"),    # another student's
    (json.dumps(dict(graded('s1'), total='17')), 'grade.json.total: a number expected, got str'),
    # the same name, another participant or another folder of Moodle's: not this line's student
    (json.dumps(graded('s1', participant=7)), "the grade of participant 7 (folder 's1'), not of participant None "
                                              "(folder 's1')"),
    (json.dumps(graded('s1', folder='s1_7_assignsubmission_file_')), 'not of participant None'),
    (json.dumps(dict(graded('s1'), total=17.0)), 'grade.json.total: 17.0, but its 0 item(s) come to 0'),
])
def test_a_result_that_is_not_the_students_grade_stops_that_student_only(array, left, why):
    """Issue 37 point 1: the host reads each task's result as a grade record (capped, checked); one
    that is not (garbled, another shape, another student's) is that student's "not graded" row with
    the reason, and the class goes on (it used to raise out of the array and cancel every task)."""
    run, fake, lines = array([['record'], [left], ['record']])
    run.submit(range(3))
    for now in range(3):
        run.look(float(now))
    assert [r['status'] for r in run.records] == ['graded', 'not graded', 'graded']
    reason = run.records[1]['status_reason']
    assert reason.startswith('could not grade: its results/1.json is not its grade record: ') and why in reason, reason
    assert any(line.startswith('slurm: s1 (task 100_1) left a grade that is not one: ') for line in lines)
    assert sum(1 for c in fake.calls if c[0] == 'sbatch') == 1, 'the same grade would be written again: no retry'
    assert 'scancel' not in [c[0] for c in fake.calls]


def test_a_name_of_the_class_listing_is_the_name_its_grade_record_holds():
    """The host compares a result's student with the name it gave the task, as the record holds it
    (cleaned where made): every name the class's listing makes cleans to itself, so the record of a
    student is found as that student's, never taken for another's."""
    from exam_lab.grader.score import identity, safe_text
    folders = ['Eve\x1b[2J\x1b[H\r\x85\u202e_1_assignsubmission_file_', 'n\udcff\udce9_2_assignsubmission_file_',
               'Zoë Ünal_3_assignsubmission_file_', '\t.Anna\x00 Roy._4_assignsubmission_file_', 'grades.csv']
    for folder in folders:
        name = identity.student_name(folder)
        assert safe_text.clean(name) == name and graded(name)['student'] == name, (folder, name)


@pytest.mark.parametrize('text, said', [
    ('{"student": "Ann", "submission": "/class/Ann"}\n', 'has no such line (1 line(s))'),
    ('{"student": "Ann", "submission": "/class/Ann"}\n{"student": "Bob", "subm\n', 'cannot be read: '),
    ('{"student": "Ann", "submission": "/class/Ann"}\n["Bob", "/class/Bob"]\n', 'is not a student\'s line'),
    ('{"student": "Ann", "submission": "/class/Ann"}\n{"student": "Bob", "submission": null}\n',
     'is not a student\'s line'),
])
def test_a_garbled_manifest_line_stops_the_task_with_a_sentence(tmp_path, text, said):
    manifest = tmp_path / 'manifest.jsonl'
    manifest.write_text(text)
    with pytest.raises(RuntimeError) as raised:
        slurm.run_task(str(manifest), 1, str(tmp_path))
    assert str(raised.value).startswith('the Slurm manifest %s, line 2 ' % manifest) and said in str(raised.value)


def test_the_task_says_in_one_line_why_its_manifest_line_cannot_be_graded(tmp_path, capsys):
    """The task's log (kept in OUT/.slurm/logs/ and named in the student's row) holds the sentence."""
    manifest = tmp_path / 'manifest.jsonl'
    manifest.write_text('{"student": "Ann", "subm\n')
    assert slurm.main(['task', str(manifest), '0', '--out', str(tmp_path)]) == 1
    said = capsys.readouterr().err
    assert said.startswith('exam_lab.grader.engine.slurm task 0: the Slurm manifest %s, line 1 cannot be read: '
                           % manifest) and 'Traceback' not in said and said.count('\n') == 1


@pytest.mark.parametrize('args, said', [
    (['--nodes', '2', '--cpus', '0'], '--cpus takes 1 to'),
    (['--nodes', '2', '--cpus', 'two'], '--cpus takes 1 to'),
    (['--nodes', '2', '--cpus', str((os.cpu_count() or 1) + 1)], 'the CPUs a node\'s slurmd finds'),
    (['--cpus', '1'], '--cpus is for several nodes'),
    (['--nodes', '2', '--cpus'], '--cpus needs a number'),
])
def test_the_local_slurm_refuses_a_cpu_count_it_cannot_offer_before_starting_anything(tmp_path, args, said):
    """tools/slurm_local.sh start --cpus C: each node's CPUs, checked before a daemon or a namespace is made."""
    import subprocess
    script = os.path.join(os.path.dirname(__file__), '..', '..', '..', 'tools', 'slurm_local.sh')
    done = subprocess.run(['bash', script, 'start'] + args, env=dict(os.environ, EXAM_SLURM_DIR=str(tmp_path)),
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=30)
    assert done.returncode != 0 and said in done.stdout.decode(), done.stdout.decode()
    assert sorted(os.listdir(str(tmp_path))) == []

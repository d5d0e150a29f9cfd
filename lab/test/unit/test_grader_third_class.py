"""Issue 27, "fair on a third kind of class", on synthetic records: a refused request is still a call,
roslaunch's verdict on the file as handed in, several uploads, the types the probe saw, the
worksheet's scale, the page's title and its "needs the teacher" box."""
import os
import zipfile

from exam_lab.grader.boxed import package, uploads
from exam_lab.grader.publish import flightplot, moodle, page, report
from exam_lab.grader.score import rubric, sheets
from exam_lab.harness import oracle

from test_grader_rubric import STATIC, lost, measured


def answered(calls, accepted):
    return [[t, s, accepted, 'LED set' if accepted else 'unknown status'] for t, s in calls]


def lowercase_session():
    session = measured(calls=[[13.55, 'warning'], [16.08, 'normal']])
    main = session['runs'][0]['probe']
    main['answers'] = answered(main['calls'], False)
    threshold = session['runs'][1]['probe']
    threshold['calls'] = [[8.02, 'warning']]
    threshold['answers'] = answered(threshold['calls'], False)
    return session


def test_a_refused_request_is_still_a_call_judged_on_its_time():
    session = lowercase_session()
    assert lost(session) == {'Q13': 2.0}
    q13 = [i for i in rubric.score('altitude', STATIC, session) if i['id'] == 'Q13'][0]['evidence']
    assert 'WARNING while above, NORMAL once back below' in q13
    assert 'refused its 2 call(s) with "normal", "warning"' in q13, q13
    status, reason = rubric.status(STATIC, session)
    assert status == rubric.HAND_GRADE and 'refused' in reason, reason
    assert any('refused 2 call(s)' in d for d in rubric.doubts(STATIC, session))


def test_refused_calls_in_a_loop_cost_both_halves_and_other_words_are_named():
    calls = [[t / 10.0, 'warning' if 13.55 <= t / 10.0 < 16.0 else 'normal'] for t in range(0, 185)]
    session = measured(calls=calls)
    session['runs'][0]['probe']['answers'] = answered(calls, False)
    assert lost(session)['Q13'] == 3.0
    never = measured(calls=[[13.55, 'BEEP'], [16.08, 'STOP BEEP']], threshold_run=False)
    q13 = [i for i in rubric.score('altitude', STATIC, never) if i['id'] == 'Q13'][0]['evidence']
    assert '"BEEP", "STOP BEEP"' in q13 and 'mean neither' in q13, q13


def test_the_leds_colours_are_read_as_the_statuses_they_set():
    """"RED" / "GREEN" (the LED the call sets), or "Alert" / "ok": what the node meant is clear, so
    the calls are judged on their times and the words cost Q13's half once, as "warning" does."""
    for warning, normal in (('RED', 'GREEN'), ('Alert!', 'ok'), ('ALT WARN', 'normale')):
        session = measured(calls=[[13.55, warning], [16.08, normal]])
        main = session['runs'][0]['probe']
        main['answers'] = answered(main['calls'], False)
        threshold = session['runs'][1]['probe']
        threshold['calls'] = [[8.02, warning]]
        threshold['answers'] = answered(threshold['calls'], False)
        assert lost(session) == {'Q13': 2.0}, (warning, lost(session))
        assert rubric.status(STATIC, session)[0] == rubric.HAND_GRADE


def test_request_meaning():
    assert [sheets.request_meaning(r) for r in ('WARNING', ' normal ', "'Warning'", 'WARNING!', 'warning: too high',
                                                'red', 'Vert', 'depth warn')] == \
        ['WARNING', 'NORMAL', 'WARNING', 'WARNING', 'WARNING', 'WARNING', 'NORMAL', 'WARNING']
    assert [sheets.request_meaning(r) for r in ('NOT NORMAL', 'BEEP', '', None, 'WARNINGS', '42')] == [None] * 6


def test_roslaunch_refusing_the_file_as_handed_in():
    session = measured()
    session['launch_check'] = {'file': 'launch/exam.launch', 'status': 1, 'warnings': [], 'nodes': [],
                               'refused': 'roslaunch file contains multiple nodes named [/mydrone].'}
    assert lost(session) == {'Q12': 1.0}
    q12 = [i for i in rubric.score('altitude', STATIC, session) if i['id'] == 'Q12'][0]['evidence']
    assert 'multiple nodes named [/mydrone]' in q12 and 'starts mydrone/' not in q12, q12
    status, reason = rubric.status(STATIC, session)
    assert status == rubric.GRADED_WITH_FIXES and 'multiple nodes named [/mydrone]' in reason
    assert rubric.doubts(STATIC, session)
    accepted = measured()
    accepted['launch_check'] = {'file': 'launch/exam.launch', 'status': 0, 'refused': '', 'nodes': ['/exam'],
                                'warnings': ['WARNING: unknown tag <nod>']}
    assert lost(accepted) == {}
    assert 'roslaunch warns: WARNING: unknown tag <nod>' in [
        i for i in rubric.score('altitude', STATIC, accepted) if i['id'] == 'Q12'][0]['evidence']
    assert rubric.status(STATIC, accepted)[0] == rubric.GRADED


def float64_session(kept=20.0):
    """A node whose /temperature subscription rospy refused: it computes with ``kept`` degC."""
    session = measured()
    main = session['runs'][0]['probe']
    main['input_types'] = {
        '/temperature': {'type': 'std_msgs/Float64', 'connected': False,
                         'refused': 'rospy refused the connection: the node asked for std_msgs/Float64, the '
                                    'drone publishes std_msgs/Float32'},
        '/pressure': {'type': 'std_msgs/Float32', 'connected': True, 'refused': None}}
    main['formula'] = [{'inputs': {'/temperature': t, '/pressure': p}, 'expected': oracle.altitude_of(t, p),
                        'published': oracle.altitude_of(kept, p), 'samples': 5}
                       for t, p in ((15.0, 89570.9), (15.0, 84215.5), (-5.0, 85859.2))]
    return session


def test_a_refused_subscription_costs_q10_not_q11():
    session = float64_session()
    assert lost(session) == {'Q10': 1.0}
    items = {i['id']: i['evidence'] for i in rubric.score('altitude', STATIC, session)}
    assert '/temperature as std_msgs/Float64, but rospy refused the connection' in items['Q10'], items['Q10']
    assert 'at the constant temperature 20' in items['Q11'], items['Q11']
    wrong = float64_session()
    wrong['runs'][0]['probe']['formula'][1]['published'] += 30.0  # no constant explains these values
    assert lost(wrong) == {'Q10': 1.0, 'Q11': 1.5}


def test_a_refused_moving_input_published_in_the_nodes_type_costs_q10_once():
    """/pressure as Float64: the probe publishes it as Float64 once rospy refused it, and the node flies
    (the values, the warning and its timing judged): Q10 loses the input, the fix is named."""
    session = measured()
    session['runs'][0]['probe']['input_types'] = {
        '/temperature': {'type': 'std_msgs/Float32', 'connected': True, 'refused': None, 'adapted': None},
        '/pressure': {'type': 'std_msgs/Float64', 'connected': True, 'adapted': 'std_msgs/Float64',
                      'published': 'std_msgs/Float32',
                      'refused': 'rospy refused the connection: the node asked for std_msgs/Float64, the '
                                 'drone publishes std_msgs/Float32'}}
    assert lost(session) == {'Q10': 1.0}
    q10 = [i for i in rubric.score('altitude', STATIC, session) if i['id'] == 'Q10'][0]['evidence']
    assert 'published it as std_msgs/Float64' in q10 and '(0/1)' in q10, q10
    status, reason = rubric.status(STATIC, session)
    assert status == rubric.GRADED_WITH_FIXES, status
    assert 'the drone published /pressure as std_msgs/Float64' in reason and 'std_msgs/Float32' in reason, reason


def dated_zip(path, when, content=b'<package><name>exam</name></package>'):
    with zipfile.ZipFile(path, 'w') as zf:
        zf.writestr(zipfile.ZipInfo('exam/package.xml', when), content)


def test_choose_upload_by_dates_then_version():
    from datetime import datetime
    early, late = datetime(2026, 6, 12, 14, 52), datetime(2026, 6, 12, 16, 58)
    index, why, ambiguous = uploads.choose_upload([('exam.zip', early, None), ('exam_v2.zip', late, 2)])
    assert (index, ambiguous) == (1, False) and 'exam.zip (files dated 2026-06-12 14:52)' in why
    assert uploads.choose_upload([('b.zip', late, None), ('a.zip', early, None)])[:1] == (0,)
    index, why, ambiguous = uploads.choose_upload([('exam_v3.zip', None, 3), ('exam_v2.zip', None, 2)])
    assert (index, ambiguous) == (0, False) and 'highest version number' in why
    assert uploads.choose_upload([('exam.zip', early, None), ('exam_v2.zip', early, 2)])[:1] == (1,)
    assert uploads.choose_upload([('exam_v2.zip', late, 2), ('exam_v3.zip', early, 3)])[2] is True
    assert uploads.choose_upload([('a.zip', None, None), ('b.zip', None, None)])[2] is True
    assert [uploads.version_number(n) for n in ('exam.zip', 'exam_v2.zip', 'exam (3).zip', 'examV4.tar.gz',
                                                'exam-2.zip', 'exam_2026.zip')] == [None, 2, 3, 4, 2, None]


def test_several_uploads_in_one_folder(tmp_path):
    folder = tmp_path / 'Jane Doe_12_assignsubmission_file_'
    folder.mkdir()
    dated_zip(str(folder / 'exam_v2.zip'), (2026, 6, 12, 16, 58, 0),
              b'<package><name>exam</name><version>2.0.0</version></package>')
    dated_zip(str(folder / 'exam.zip'), (2026, 6, 12, 14, 52, 0))
    notes, uploads = [], []
    chosen = package.open_submission(str(folder), str(tmp_path / 'scratch'), notes, uploads=uploads)
    with open(os.path.join(chosen, 'package.xml')) as f:
        assert '2.0.0' in f.read()
    assert len(uploads) == 1 and uploads[0]['files'] == ['exam.zip', 'exam_v2.zip'], uploads
    assert "graded 'exam_v2.zip', the newest" in uploads[0]['why'] and not uploads[0]['ambiguous']
    assert not any('several candidate packages' in n for n in notes), notes
    static = {'uploads': [dict(uploads[0], ambiguous=True)]}
    assert rubric.status(static, measured())[0] == rubric.HAND_GRADE


WORKSHEET = ('\ufeffIdentifier,"Full name",Status,Grade,"Maximum grade","Grade can be changed",'
             '"Last modified (grade)","Feedback comments"\n'
             '"Participant 12","Jane Doe","Submitted for grading",,20.00,Yes,-,\n')


def test_the_worksheet_scale_is_never_silent():
    """The machine's 17 points are never written into a column out of 20; the whole grade is, scaled,
    and both the comment and the terminal say so."""
    from exam_lab.grader.publish import hand
    from exam_lab.grader.score.sheets import HAND_ITEMS
    record = {'student': 'Jane Doe', 'participant': 12, 'total': 17.0, 'max': 17.0, 'status': 'graded',
              'items': [{'id': 'runs', 'points': 2.0, 'max': 2.0, 'evidence': ''}]}
    text, summary = moodle.fill(WORKSHEET, [record])
    assert summary['graded'] == [] and text == WORKSHEET
    assert any("no whole grade yet" in l for l in moodle.summary_lines(summary, 'x.csv'))
    whole = hand.combine(record, hand.Hand('Jane Doe', {i: top for i, (top, _) in HAND_ITEMS.items()}, '', 12))
    text, summary = moodle.fill(WORKSHEET, [whole])
    assert summary['graded'] == [('Jane Doe', 12, '20')]
    assert 'scaled to 20 (x 20/30)' in text
    assert any('scaled to the maximum grade 20' in l for l in moodle.summary_lines(summary, 'x.csv'))


def test_the_class_name_for_the_title():
    assert moodle.class_name('/tmp/ROS2026-Exam altitude-1234.zip') == 'ROS2026-Exam altitude'
    assert moodle.class_name('/home/t/moodle/class folder/') == 'class folder'


def test_the_box_lists_every_doubt():
    items = [{'id': 'runs', 'points': 2.0, 'max': 2.0, 'evidence': ''}]
    records = [report.grade_record('calm', 'altitude', items, []),
               report.grade_record('doubtful', 'altitude', items, [], {'doubts': ['several uploads: graded x']})]
    html = page.render(records, 'Exam grades: ROS2026-Exam altitude', {})
    box = html.split('<h2 id="first">', 1)[1].split('<h2', 1)[0]
    assert '>doubtful</a>' in box and 'several uploads: graded x' in box and '>calm</a>' not in box
    assert report.needing_the_teacher(records) == ['doubtful: graded; several uploads: graded x']


def test_refused_calls_on_the_plot(tmp_path, monkeypatch):
    probe = lowercase_session()['runs'][0]['probe']
    probe.update(t0=-3.0, threshold=1300.0, sheet='altitude', trace={'published': [[0.0, 1170.0]], 'oracle': []})
    labels = []
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib.axes import Axes
    original = Axes.plot

    def plot(self, *args, **kwargs):
        labels.append(kwargs.get('label'))
        return original(self, *args, **kwargs)
    monkeypatch.setattr(Axes, 'plot', plot)
    assert flightplot.draw([('main', probe)], str(tmp_path / 'flight.png'))
    assert 'REFUSED "warning" calls (1 in the flight)' in labels and 'REFUSED "normal" calls (1 in the flight)' in labels, labels


def test_grade_md_says_what_to_look_at():
    items = [{'id': 'runs', 'points': 2.0, 'max': 2.0, 'evidence': ''}]
    text = report.markdown(report.grade_record('x', 'altitude', items, [], {'doubts': ['several uploads: graded y']}))
    assert '**Look at:** several uploads: graded y' in text
    assert '**Look at:**' not in report.markdown(report.grade_record('x', 'altitude', items, []))


class _Here(object):
    """A stand-in for the box and the supervisor: the check runs here, as the test's user."""
    home = '/tmp'

    workspace = None  # where the box's steps start when no cwd is given (its workspace)

    def argv(self, argv, env, cwd=None):
        cwd = cwd or self.workspace
        return (['env', '-C', cwd] if cwd else []) + argv

    def run(self, name, argv, timeout, env=None):
        import subprocess
        done = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=timeout, env=env)
        return done.returncode, done.stdout.decode(), 0.0


def test_roslaunch_verdict_on_the_file_as_handed_in(tmp_path):
    from exam_lab.grader.host import session
    launch = tmp_path / 'src' / 'exam' / 'launch'
    launch.mkdir(parents=True)
    (launch / 'dup.launch').write_text('<launch><node pkg="mydrone" name="mydrone" type="mydrone_node.py"/>'
                                       '<node pkg="exam" name="mydrone" type="exam_node.py"/></launch>')
    (launch / 'odd.launch').write_text('<launch><node pkg="exam" name="exam" type="exam_node.py">'
                                       '<parm name="threshold" value="1"/></node></launch>')
    here, env = _Here(), dict(os.environ)
    job = {'workspace': str(tmp_path), 'handed_in_launch': 'exam/launch/dup.launch'}
    refused = session.launch_verdict(here, here, env, **job)
    assert refused['status'] == 1 and refused['file'] == 'launch/dup.launch'
    assert 'multiple nodes named [/mydrone]' in refused['refused'], refused
    odd = session.launch_verdict(here, here, env, **dict(job, handed_in_launch='exam/launch/odd.launch'))
    assert odd['status'] == 0 and odd['refused'] == '' and odd['nodes'] == ['/exam'], odd
    assert any("unrecognized 'parm'" in w for w in odd['warnings']), odd

"""Moodle's names, end to end, against Moodle's own rule: the folders of a class zip as Moodle's
downloader names them (its own tests' names, moodle_download_names.tsv), the participant number the
grader reads from them, and the folders of OUT/moodle-feedback.zip, each read back by a port of Moodle's
feedback importer. The ports are test oracles, written here from Moodle's source and checked on Moodle's
own test cases; the product (publish/feedback.py, score/identity.py) is what they judge.

Moodle's source read (repository moodle/moodle unless said):
- mod/assign/feedback/file/importziplib.php at 0203d8f26027201de1d7d1ec8d8aa3cdcc4f5d5d,
  is_valid_filename_for_import(): Moodle >= 4.1 (:func:`moodle_import`, ``version='4.1'``).
- The same function of Moodle 3.1 to 4.0, as a site's copy of Moodle keeps it (ay9010x/2020moodlesetHo
  at dc418fdb317638d9ec1a6887b5fdd7e99ac5a34b, mod/assign/feedback/file/importziplib.php, comments
  stripped): the whole path split on its first four '_' (``version='3.1'``). The 4.1 file says of the
  folders: "fullname_userid_plugintype_pluginname (as created by zip export in Moodle >= 4.1) resp.
  fullname_userid_plugintype_pluginname_ (as created by earlier versions)".
- mod/assign/classes/downloader.php at da5455238d1a24a0246b11f4b682b73664993c0b, get_student_prefix()
  and load_submissionplugin_filelist() (:func:`download_path`).
- lib/filestorage/zip_packer.php at 01b4040a27980dfa6d68218f238a61a746c2ba15, extract_to_storage():
  a zip entry ``a/b/c`` becomes the file ``c`` in ``/import/a/b/``.
- lib/moodlelib.php clean_param(PARAM_FILE) (and lib/classes/param.php from 4.4): fix_utf8, then
  ``preg_replace('~[[:cntrl:]]|[&<>"`\\|\\':\\\\\\\\/]~u', '', $param)``, then '.' or '..' alone gives ''.
  PHP's /u also sets PCRE2_UCP, so [[:cntrl:]] is Unicode's Cc: C1 controls (U+0080-U+009F) go too.
  Observed with PHP 8.2.36 (PCRE2 10.42) on this machine: :data:`PHP_OBSERVED`.
"""
import html
import os
import re
import unicodedata
import zipfile

import pytest

from exam_lab.grader.boxed import classlist
from exam_lab.grader.publish import feedback
from exam_lab.grader.score import identity

HERE = os.path.dirname(os.path.realpath(__file__))
FIXTURE = os.path.join(HERE, 'moodle_download_names.tsv')

#: The plugins of an assignment with file submissions and file feedback (get_plugin_by_type's answers).
PLUGINS = {('assignsubmission', 'file'), ('assignsubmission', 'onlinetext'), ('assignfeedback', 'file'),
           ('assignfeedback', 'comments')}
#: What PHP 8.2.36 printed for preg_replace(PARAM_FILE's pattern, '', $s) and is_numeric($s).
PHP_OBSERVED = {
    'clean': [('a\u0085b', 'ab'), ('a\u009fb', 'ab'), ('a\u200bb', 'a\u200bb'), ('x\u2028y', 'x\u2028y'),
              ('é ü', 'é ü'), ('a..b', 'a..b'), ("Zoé O'Neil_7", 'Zoé ONeil_7'), ('A/B: C', 'AB C')],
    'numeric': [('12', True), (' 12', True), ('12 ', True), ('1e3', True), ('0x1A', False), ('.5', True),
                ('12abc', False), ('', False), ('+3', True), ('\t4\n', True), ('0012', True)],
}
_PHP_SPACE = ' \t\n\r\v\f'
_PHP_NUMERIC = re.compile(r'^[%s]*[+-]?([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?[%s]*$' % (_PHP_SPACE, _PHP_SPACE))
_REMOVED = set('&<>"`|\':\\/')


def param_file(text):
    """clean_param($text, PARAM_FILE), written from its definition (not the product's regex): invalid
    UTF-8 (here: lone surrogates) and every Unicode Cc character or one of & < > " ` | ' : \\ / removed;
    '.' and '..' alone give ''."""
    text = ''.join(c for c in text if not (unicodedata.category(c) in ('Cc', 'Cs') or c in _REMOVED))
    return '' if text in ('.', '..') else text


def php_is_numeric(text):
    return bool(_PHP_NUMERIC.match(text))


def php_key(text):
    """``$participantid += 0`` used as an array key: an integer (a float's key is truncated)."""
    text = text.strip(_PHP_SPACE)
    return int(text) if re.match(r'^[+-]?[0-9]+$', text) else int(float(text))


def php_explode(sep, text, limit):
    return text.split(sep, limit - 1)


def moodle_import(path, participants, version='4.1', plugins=PLUGINS):
    """is_valid_filename_for_import() for the zip entry ``path`` (extracted below /import/):
    ``(participant, subtype, type, filename)``, or None when Moodle skips the file."""
    if path.endswith('/'):
        return None  # a directory
    parts = path.strip('/').split('/')
    name, folders = parts[-1], parts[:-1]
    if name.startswith('.') or name.startswith('~'):
        return None  # "Ignore hidden files."
    whole = '/import/' + ''.join(f + '/' for f in folders) + name  # get_filepath() . get_filename()
    if version == '3.1':
        info = php_explode('_', whole, 5)
        if len(info) < 5 or not php_is_numeric(info[1]) or (info[2], info[3]) not in plugins:
            return None
        number = php_key(info[1])
        return (number, info[2], info[3], info[4]) if number in participants else None
    pathparts = whole.split('/')
    while pathparts:
        info = php_explode('_', pathparts.pop(0), 5)
        if len(info) < 4 or not php_is_numeric(info[1]):
            continue
        number = php_key(info[1])
        if number not in participants or (info[2], info[3]) not in plugins:
            continue
        pathparts.insert(0, info[4] if len(info) == 5 else '')
        return number, info[2], info[3], '/'.join(pathparts)
    return None


def download_path(fullname, number, filename, layout):
    """The path of a submitted file in "download all submissions" (downloader.php; 3.1-4.0 wrote the
    folder with a last '_'): ``layout`` is '4.1' (folders), '3.1' (folders) or 'flat' (files)."""
    prefix = param_file(fullname.replace('_', ' ') + '_' + str(number))
    if layout == 'flat':
        return param_file(prefix + '_assignsubmission_file_' + filename)
    return param_file(prefix + '_assignsubmission_file' + ('_' if layout == '3.1' else '')) + '/' + filename


def read_fixture():
    rows = {'download': [], 'import': [], 'name': []}
    with open(FIXTURE, encoding='utf-8') as f:
        for line in f:
            if line.startswith('#') or not line.strip():
                continue
            source, kind, *rest = line.rstrip('\n').split('\t')
            rows[kind].append(rest)
    return rows


FIXTURES = read_fixture()
NAMES = [fullname for fullname, in FIXTURES['name']]
#: Names Moodle's tests do not have, of kinds a class has: an apostrophe, a hyphen, an underscore, quotes,
#: a slash and a colon, brackets and a comma, digits, a C1 control character, two students of one name.
MORE_NAMES = ["Zoé O'Neil", "Anne-Sophie d'Arc", 'Jean_Pierre Martin', 'Ève "Evie" Lefèvre', 'A/B: C',
              'Li WEI (Leo WEI)', 'KIM,MINSU-2018000001', 'Ann\u0085e Roy', 'Marie Dupont', 'Marie Dupont']
#: Participant numbers (assign_user_mapping ids: any positive integers) for NAMES + MORE_NAMES.
NUMBERS = [4000 + 17 * i for i in range(len(NAMES) + len(MORE_NAMES))]


def test_the_fixture_is_read():
    assert len(FIXTURES['download']) == 9 and len(FIXTURES['import']) == 8 and len(NAMES) == 12


def test_param_file_is_what_php_printed():
    for text, printed in PHP_OBSERVED['clean']:
        assert param_file(text) == printed, text
    for text, numeric in PHP_OBSERVED['numeric']:
        assert php_is_numeric(text) is numeric, text


def test_the_products_clean_filename_is_param_file_for_every_character():
    """Every code point, alone and between letters: the product's rule removes exactly what Moodle's does
    (C1 controls included: PHP's /u makes [[:cntrl:]] Unicode's)."""
    wrong = [hex(c) for c in range(0x110000) if feedback.clean_filename('a%sb' % chr(c)) != param_file('a%sb' % chr(c))]
    assert wrong == []
    assert feedback.clean_filename('.') == param_file('.') == '' and feedback.clean_filename('..') == ''


@pytest.mark.parametrize('version', ['4.1', '3.1'])
def test_the_importer_port_gives_moodles_own_test_answers(version):
    """importziplib_test.php's names and verdicts, through the port of either version (the 3.1 one splits
    the whole path, so only its folder-less names are its own: the rest is checked as 4.1's)."""
    student = 4711
    for row in FIXTURES['import']:
        path = re.sub(r'(?<![A-Za-z])ID\+100(?![A-Za-z])', str(student + 100), row[0])
        path = re.sub(r'(?<![A-Za-z])ID(?![A-Za-z])', str(student), path)
        got = moodle_import(path, {student}, version)
        if row[1] == 'skip':
            assert got is None, path
        elif version == '4.1' or '/' not in path:
            assert got is not None and got[0] == student and got[3] == row[2], (path, got)


def downloads(fullname, number):
    """Each layout's path of one submitted file, from the fixture's [D] paths filled in as
    downloader_test.php does (STUDENT1: the name cleaned, STUDENT1.ID: the number)."""
    who = param_file(fullname.replace('_', ' '))
    paths = []
    for template, kind in FIXTURES['download']:
        if kind != 'student':
            continue
        for search, replace in (('STUDENT1.ID', str(number)), ('STUDENT1', who), ('STUDENT2.ID', str(number)),
                                ('STUDENT2', who)):
            template = template.replace(search, replace)
        paths.append(template)
    return paths


@pytest.mark.parametrize('fullname, number', list(zip(NAMES + MORE_NAMES, NUMBERS)))
def test_each_download_name_gives_moodles_number_and_a_feedback_folder_moodle_imports(fullname, number):
    """A student's download names (Moodle's tests' paths, both folder layouts and flat files): Moodle's
    importer reads its number from them; the grader reads the same, keeps Moodle's name, and writes a
    feedback folder both importers give to that number, the page at the top of the student's files."""
    found = downloads(fullname, number)
    assert found == [download_path(fullname, number, 'submissionsample01.txt', '4.1'),
                     download_path(fullname, number, 'submissionsample02.txt', '4.1'),
                     download_path(fullname, number, 'submissionsample01.txt', 'flat')]
    found.append(download_path(fullname, number, 'exam.zip', '3.1'))
    everyone = set(NUMBERS)
    for path in found:
        top = path.split('/')[0]
        assert moodle_import(path, everyone)[:3] == (number, 'assignsubmission', 'file'), path
        assert identity.participant_number(top) == number, top
        record = {'folder': top, 'student': identity.student_name(top), 'participant': number}
        assert identity.identity(record)[:2] == (number, top if '/' in path else top[:top.index('_file_') + 6])
        name = feedback.moodle_name(record, number)
        assert name == param_file(fullname.replace('_', ' '))  # as Moodle wrote it: accents, spaces kept
        entry = feedback.folder_name(name, number) + '/' + feedback.PAGE
        for version in ('4.1', '3.1'):
            assert moodle_import(entry, everyone, version) == (number, 'assignfeedback', 'file', '/feedback.html')
        assert all(param_file(part) == part for part in entry.split('/'))  # stored by Moodle unchanged


def test_another_scripts_digits_are_no_number():
    """Python's \\d takes Arabic-Indic digits; Moodle's is_numeric does not: no number for either."""
    for top in ('Ali_\u0663\u0664_assignsubmission_file_', 'Ali_\u0663\u0664_assignsubmission_file'):
        assert moodle_import(top + '/exam.zip', {34}) is None
        assert identity.participant_number(top) is None and identity.identity({'folder': top, 'student': 'Ali'})[:2] \
            == (None, None)
        assert feedback.moodle_name({'folder': top, 'student': 'the grader\'s Ali'}, 34) == 'the grader\'s Ali'


def test_two_students_of_one_name_have_two_folders():
    first, second = [feedback.folder_name('Marie Dupont', n) for n in NUMBERS[-2:]]
    assert first != second and {moodle_import(f + '/feedback.html', set(NUMBERS))[0] for f in (first, second)} == \
        set(NUMBERS[-2:])


def test_what_a_team_or_the_default_team_folder_gives():
    """Team submissions name a folder by the group (its name and id) or "Default group" (no number):
    the grader reads what Moodle's importer would read, the group's id or nothing. No name tells a group's
    id from a participant's: docs/grading.md says the feedback zip is for individual submissions."""
    group, everyone = 77, {77, 4000}
    for template, kind in FIXTURES['download']:
        if kind not in ('group', 'none', 'participant'):
            continue
        path = template.replace('GROUP1.ID', str(group)).replace('GROUP2.ID', str(group)) \
            .replace('GROUP1', param_file('Group A')).replace('GROUP2', param_file('Group_B'.replace('_', ' '))).replace('PARTICIPANT', 'Participant') \
            .replace('STUDENT1.ID', '4000').replace('STUDENT2.ID', '4000').replace('DEFAULTTEAM', 'Default group')
        top = path.split('/')[0]
        moodle = moodle_import(path, everyone)
        assert identity.participant_number(top) == (moodle[0] if moodle else None), path
        assert (moodle is None) == (kind == 'none')


def test_the_zip_of_a_class_with_these_names_imports_each_page_to_its_student(tmp_path):
    """A class zip with these names (as Moodle's downloader streams it, non-ASCII names flagged UTF-8),
    listed by the grader, graded, and the feedback zip written: every entry of it is imported by both
    importers, each to its own participant, none skipped as hidden, each page titled with Moodle's name."""
    from test_grader_feedback import graded_class, record
    from test_grader_unpack import PACKAGE_XML, make_zip
    fullnames = NAMES + MORE_NAMES
    folders = [download_path(n, k, '', '3.1' if i % 2 else '4.1').rstrip('/') for i, (n, k) in
               enumerate(zip(fullnames, NUMBERS))]
    archive = make_zip(tmp_path / 'ROS-Exam-12.zip', [('%s/exam/package.xml' % f, PACKAGE_XML) for f in folders])
    scratch, out = tmp_path / 'scratch', tmp_path / 'out'
    scratch.mkdir()
    out.mkdir()
    listed = classlist.list_students(str(archive), str(scratch))
    assert sorted(os.path.basename(path) for _, path in listed) == sorted(folders)
    names = [name for name, _ in listed]
    unique = [name if names.index(name) == i else '%s_%d' % (name, i) for i, name in enumerate(names)]
    records = [record(student, folder=os.path.basename(path)) for student, (_, path) in zip(unique, listed)]
    for r in records:
        r['participant'] = identity.participant_number(r['folder'])
    graded_class(str(out), records)
    feedback.write(str(out), records, show='points')
    with zipfile.ZipFile(str(out / feedback.FILE)) as written:
        entries = {info.filename: info for info in written.infolist()}
        pages = {name: written.read(name).decode('utf-8') for name in entries}
    assert all(info.flag_bits & 0x800 for name, info in entries.items() if not name.isascii())
    expected = {number: param_file(n.replace('_', ' ')) for n, number in zip(fullnames, NUMBERS)}
    for version in ('4.1', '3.1'):
        got = {}
        for name, text in pages.items():
            imported = moodle_import(name, set(NUMBERS), version)
            assert imported is not None and imported[1:] == ('assignfeedback', 'file', '/feedback.html'), name
            got[imported[0]] = text
        assert sorted(got) == sorted(NUMBERS)
        for number, text in got.items():
            title = re.search(r'<h1>(.*?): ', text).group(1)
            assert title == html.escape(expected[number], quote=True), (number, title)


def test_a_student_whose_name_starts_with_a_dot_is_listed(tmp_path):
    """Moodle writes a full name starting with '.' as it is: that folder is a student's, not a hidden
    file; .DS_Store and macOS's ._ copy of a flat download (its participant number included) are not."""
    from test_grader_unpack import PACKAGE_XML, make_zip
    inner = make_zip(tmp_path / 'exam.zip', [('exam/package.xml', PACKAGE_XML)])
    with open(inner, 'rb') as f:
        packed = f.read()
    dotted = download_path('.Anna Roy', 77, '', '4.1').rstrip('/')
    flat = download_path('Jane Doe', 12, 'exam.zip', 'flat')
    archive = make_zip(tmp_path / 'class.zip', [(dotted + '/exam/package.xml', PACKAGE_XML), (flat, packed),
                                                ('._' + flat, b'\0\5\26\7'), ('.DS_Store', b'\0')])
    scratch = tmp_path / 'scratch'
    scratch.mkdir()
    listed = classlist.list_students(str(archive), str(scratch))
    assert [(name, os.path.basename(path)) for name, path in listed] == [('Anna Roy', dotted), ('Jane Doe', flat)]
    name = feedback.moodle_name({'folder': dotted, 'student': 'Anna Roy'}, 77)
    assert name == '.Anna Roy' and moodle_import(feedback.folder_name(name, 77) + '/feedback.html', {77})[0] == 77

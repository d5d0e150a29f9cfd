"""Unpacking what students upload: unsafe archives refused as a whole, the package found."""
import io
import os
import re
import shutil
import stat
import struct
import subprocess
import sys
import tarfile
import zipfile

import pytest

from exam_lab.grader.boxed import archives, classlist, package, source
from exam_lab.grader.host import staging
from exam_lab.grader.score import identity

PACKAGE_XML = '<package format="2"><name>exam</name></package>'


def make_zip(path, entries, links=()):
    with zipfile.ZipFile(path, 'w', zipfile.ZIP_DEFLATED) as zf:
        for name, data in entries:
            zf.writestr(name, data)
        for name, target in links:
            info = zipfile.ZipInfo(name)
            info.external_attr = (stat.S_IFLNK | 0o777) << 16
            zf.writestr(info, target)
    return str(path)


@pytest.mark.parametrize('name', ['../evil.py', 'exam/../../evil.py', '/etc/evil', 'C:/evil', '..\\evil'])
def test_escaping_paths_are_refused(tmp_path, name):
    archive = make_zip(tmp_path / 'a.zip', [('exam/package.xml', PACKAGE_XML), (name, 'x')])
    with pytest.raises(archives.UnpackError):
        archives.safe_extract(archive, str(tmp_path / 'out'))
    assert not (tmp_path / 'out').exists(), 'nothing is written from a refused archive'


def test_links_are_dropped_and_noted_never_followed(tmp_path):
    archive = make_zip(tmp_path / 'a.zip', [('exam/package.xml', PACKAGE_XML)], links=[('exam/l', '/etc/passwd')])
    notes, fixes = [], []
    assert archives.safe_extract(archive, str(tmp_path / 'out'), notes=notes, fixes=fixes) == 1
    assert not os.path.lexists(str(tmp_path / 'out' / 'exam' / 'l'))
    assert fixes and "'exam/l' -> '/etc/passwd'" in fixes[0] and not notes


def test_bombs_and_crowds_are_refused(tmp_path):
    bomb = make_zip(tmp_path / 'bomb.zip', [('exam/big', b'\0' * (archives.RATIO_FROM_BYTES + 1))])
    with pytest.raises(archives.UnpackError, match='bomb'):
        archives.safe_extract(bomb, str(tmp_path / 'out'))
    crowd = make_zip(tmp_path / 'crowd.zip', [('f%d' % i, 'x') for i in range(20)])
    with pytest.raises(archives.UnpackError, match='20 more files, beyond the 10'):
        archives.safe_extract(crowd, str(tmp_path / 'out2'), max_files=10)
    big = make_zip(tmp_path / 'big.zip', [('f', 'y' * 5000)])
    with pytest.raises(archives.UnpackError, match='5000 more bytes, beyond the 1000'):
        archives.safe_extract(big, str(tmp_path / 'out3'), max_bytes=1000)


def test_not_a_zip(tmp_path):
    path = tmp_path / 'report.zip'
    path.write_text('not a zip')
    with pytest.raises(archives.UnpackError, match='not a readable zip'):
        archives.safe_extract(str(path), str(tmp_path / 'out'))


def unreadable_zip(path, how, links=()):
    """A zip whose listing reads but whose bytes cannot be had: ``crc`` (a byte of its package.xml's data
    changed, as a cut or damaged download), ``encrypted`` (every entry flagged password-protected in
    both its headers, as a zip a student made with a password: APPNOTE.TXT 4.4.4, general purpose bit 0)."""
    make_zip(path, [('exam/package.xml', PACKAGE_XML)], links)
    data = bytearray(path.read_bytes())
    with zipfile.ZipFile(str(path)) as zf:
        infos = zf.infolist()
    if how == 'crc':
        data[infos[0].header_offset + 30 + len(infos[0].filename) + 1] ^= 0xff  # a byte of the compressed data
    else:
        central = data.index(b'PK\x01\x02')
        for info in infos:
            data[info.header_offset + 6] |= 0x1  # the local header's flags
            data[data.index(b'PK\x01\x02', central) + 8] |= 0x1  # the central header's
            central = data.index(b'PK\x01\x02', central) + 4
    path.write_bytes(bytes(data))
    return str(path)


@pytest.mark.parametrize('how', ['crc', 'encrypted'])
def test_a_zip_whose_bytes_cannot_be_read_is_refused_with_why(tmp_path, how):
    """A damaged or password-protected upload is refused with the reason for the teacher, as a class
    archive's student is (classlist), never a crash of the inspection; a link among its entries (whose
    target is read for the teacher's note) changes nothing."""
    (tmp_path / 'upload').mkdir()
    archive = unreadable_zip(tmp_path / 'upload' / 'exam.zip', how, links=[('exam/l', '/etc/passwd')])
    why = {'crc': "Bad CRC-32 for file 'exam/package.xml'", 'encrypted': 'it is encrypted (made with a password)'}[how]
    with pytest.raises(archives.UnpackError, match=re.escape('exam.zip cannot be unpacked: %s' % why)):
        archives.safe_extract(archive, str(tmp_path / 'out'))
    with pytest.raises(archives.UnpackError, match=re.escape('exam.zip (refused: exam.zip cannot be unpacked: %s' % why)):
        package.open_submission(str(tmp_path / 'upload'), str(tmp_path / 'scratch'), [])


@pytest.mark.parametrize('prefix', ['', 'exam_jdupont/', 'catkin_ws/src/'])
def test_package_found_at_the_top_or_below(tmp_path, prefix):
    archive = make_zip(tmp_path / 'a.zip', [(prefix + 'exam/package.xml', PACKAGE_XML),
                                            (prefix + 'exam/scripts/exam_node.py', 'print(1)'),
                                            ('__MACOSX/._exam', 'junk')])
    notes = []
    found = package.open_submission(archive, str(tmp_path / 'scratch'), notes)
    assert found.endswith(os.path.join(prefix.rstrip('/'), 'exam').lstrip('/'))
    assert os.path.isfile(os.path.join(found, 'scripts', 'exam_node.py'))


def test_student_folder_with_report_and_zip(tmp_path):
    folder = tmp_path / 'Jane Doe_1234_assignsubmission_file_'
    folder.mkdir()
    (folder / 'report.pdf').write_bytes(b'%PDF-1.4')
    make_zip(folder / 'exam.zip', [('exam/package.xml', PACKAGE_XML)])
    students = classlist.list_students(str(tmp_path), str(tmp_path / 'scratch'))
    assert [name for name, _ in students] == ['Jane Doe']
    found = package.open_submission(students[0][1], str(tmp_path / 'scratch'), [])
    assert package.package_name(os.path.join(found, 'package.xml')) == 'exam'


def test_a_link_in_a_class_folder_is_never_followed_and_its_student_is_said(tmp_path):
    """A student's folder that is a link (a teacher's class folder made of links to downloads kept
    elsewhere) is that student's row, refused with why, never followed nor silently dropped; a link
    not named as Moodle names a student is passed over."""
    klass, elsewhere = tmp_path / 'class', tmp_path / 'elsewhere'
    for folder in (klass / 'Ann_1_assignsubmission_file_', elsewhere / 'Bob_2_assignsubmission_file_'):
        (folder / 'exam').mkdir(parents=True)
        (folder / 'exam' / 'package.xml').write_text(PACKAGE_XML)
    os.symlink(str(elsewhere / 'Bob_2_assignsubmission_file_'), str(klass / 'Bob_2_assignsubmission_file_'))
    os.symlink(str(tmp_path / 'class.zip'), str(klass / 'Cy_3_assignsubmission_file_.zip'))
    os.symlink(str(elsewhere), str(klass / 'latest'))
    refused = {}
    students = classlist.list_students(str(klass), None, refused)
    assert [name for name, _ in students] == ['Ann', 'Bob', 'Cy']
    assert refused == {str(klass / 'Bob_2_assignsubmission_file_'): classlist.LINKED,
                       str(klass / 'Cy_3_assignsubmission_file_.zip'): classlist.LINKED}
    assert [name for name, _ in classlist.list_students(str(klass), None)] == ['Ann'], 'no refusals asked: passed over'


def test_a_link_at_the_top_of_a_class_archive_is_its_students_refused_row(tmp_path):
    """A class zip (or tar) whose student entry is a link, not a folder or an archive (a class folder
    of links zipped again): that student's row says why, never silently dropped, never followed."""
    archive = str(tmp_path / 'class.zip')
    with zipfile.ZipFile(archive, 'w') as zf:
        zf.writestr('Ann_1_assignsubmission_file_/exam/package.xml', PACKAGE_XML)
        for name, target in (('Bob_2_assignsubmission_file_', '/etc'), ('Cy_3_assignsubmission_file_.zip', '/x.zip')):
            info = zipfile.ZipInfo(name)
            info.create_system, info.external_attr = 3, (stat.S_IFLNK | 0o777) << 16
            zf.writestr(info, target)
    refused = {}
    students = classlist.list_students(archive, str(tmp_path / 'scratch'), refused)
    assert [name for name, _ in students] == ['Ann', 'Bob', 'Cy']
    assert sorted(os.path.basename(path) for path in refused) == ['Bob_2_assignsubmission_file_',
                                                                  'Cy_3_assignsubmission_file_.zip']
    assert all('is a link in the class archive, not a folder or an archive: never followed' in why
               for why in refused.values())
    assert not any(os.path.islink(path) or os.path.getsize(path) for _, path in students[1:])


def test_a_flat_download_student_without_an_archive_still_has_a_row(tmp_path):
    """Moodle's flat download (no folders): a student who handed in a report only (or an online text)
    is listed, its first file its submission; one with an archive too is listed once, by its archive."""
    from test_grader_moodle_names import download_path  # downloader.php's names, ported
    klass = tmp_path / 'class'
    klass.mkdir()
    ann_zip, ann_pdf, bob_pdf = (download_path(name, number, filename, 'flat') for name, number, filename in
                                 (('Ann Roy', 7, 'exam.zip'), ('Ann Roy', 7, 'report.pdf'), ('Bob Li', 8, 'report.pdf')))
    make_zip(klass / ann_zip, [('exam/package.xml', PACKAGE_XML)])
    (klass / ann_pdf).write_bytes(b'%PDF-1.4')
    (klass / bob_pdf).write_bytes(b'%PDF-1.4')
    # The online text plugin's file, named as downloader.php names any plugin's (subtype, type, file):
    # 'onlinetext.html' is assignsubmission_onlinetext's string 'onlinetextfilename'.
    (klass / bob_pdf.replace('_assignsubmission_file_report.pdf',
                             '_assignsubmission_onlinetext_onlinetext.html')).write_text('<p>see attached</p>')
    (klass / 'grading-worksheet.csv').write_text('x')  # the teacher's own file: nobody's
    listed = classlist.list_students(str(klass), None)
    assert [(name, os.path.basename(path)) for name, path in listed] == [('Ann Roy', ann_zip), ('Bob Li', bob_pdf)]


def test_refused_zip_is_reported(tmp_path):
    folder = tmp_path / 'student'
    folder.mkdir()
    make_zip(folder / 'exam.zip', [('../x', 'x')])
    with pytest.raises(archives.UnpackError, match='climbs out'):
        package.open_submission(str(folder), str(tmp_path / 'scratch'), [])


def test_class_zip(tmp_path):
    archive = make_zip(tmp_path / 'class.zip', [('all/Ann_1_assignsubmission_file_/exam/package.xml', PACKAGE_XML),
                                                ('all/Bob_2_assignsubmission_file_/exam/package.xml', PACKAGE_XML)])
    students = classlist.list_students(archive, str(tmp_path / 'scratch'))
    assert [name for name, _ in students] == ['Ann', 'Bob']


def test_copy_skips_build_products_and_links(tmp_path):
    src = tmp_path / 'exam'
    (src / 'build').mkdir(parents=True)
    (src / 'scripts').mkdir()
    (src / 'scripts' / 'exam_node.py').write_text('x')
    os.symlink('/etc/passwd', str(src / 'scripts' / 'link'))
    notes = []
    package.copy_package(str(src), str(tmp_path / 'copy'), notes)
    assert sorted(os.listdir(str(tmp_path / 'copy'))) == ['scripts']
    assert os.listdir(str(tmp_path / 'copy' / 'scripts')) == ['exam_node.py']
    assert any('link' in n for n in notes)


def test_a_compressible_file_in_an_upload_is_no_bomb(tmp_path):
    """A few MB of log or a one-colour screenshot compress 1000x: the budget bounds them, not the ratio."""
    upload = make_zip(tmp_path / 'exam.zip', [('exam/package.xml', PACKAGE_XML),
                                              ('exam/run.log', b'[INFO] altitude 1300.0\n' * 100000)])
    assert archives.safe_extract(upload, str(tmp_path / 'out')) == 2


def moodle_class(path, students):
    """A Moodle "download all submissions" zip: ``{folder name: [(file, bytes)]}`` (Moodle's naming:
    ``Full Name_<participant>_assignsubmission_file_/``), each entry deflated as Moodle does."""
    return make_zip(path, [('%s/%s' % (folder, name), data) for folder, files in sorted(students.items())
                           for name, data in files])


def test_a_class_zip_judges_each_student_by_its_own_bounds(tmp_path, monkeypatch):
    """Issue 36 point 3: a one-colour screenshot (5 MB of one byte) is no reason to refuse anyone; a
    student over its own bounds is refused alone, on its own row, with the reason; the others are
    unpacked."""
    monkeypatch.setattr(archives, 'MAX_FILES', 3)
    upload = [('exam.zip', open(make_zip(tmp_path / 'exam.zip', [('exam/package.xml', PACKAGE_XML)]), 'rb').read())]
    archive = moodle_class(tmp_path / 'class.zip', {
        'Ann Lee_11_assignsubmission_file_': upload + [('screenshot.bmp', b'\xff' * (5 << 20))],
        'Bob Crowd_12_assignsubmission_file_': upload + [('f%d.txt' % i, 'x') for i in range(4)],
        'Cy Fine_13_assignsubmission_file_': upload})
    refused = {}
    students = classlist.list_students(archive, str(tmp_path / 'scratch'), refused)
    assert [name for name, _ in students] == ['Ann Lee', 'Bob Crowd', 'Cy Fine']
    paths = dict(students)
    assert list(refused) == [paths['Bob Crowd']] and os.listdir(paths['Bob Crowd']) == []
    assert refused[paths['Bob Crowd']] == "the files of 'Bob Crowd_12_assignsubmission_file_': 5 more files, " \
        "beyond the 3 a submission may unpack"
    assert os.path.getsize(os.path.join(paths['Ann Lee'], 'screenshot.bmp')) == 5 << 20
    assert os.path.isfile(os.path.join(paths['Cy Fine'], 'exam.zip'))


def test_a_name_longer_than_a_folder_name_stops_no_one(tmp_path):
    """Moodle allows 100 characters each for a first and a last name: in Cyrillic or Chinese, with the
    participant number and the plugin, a folder name of 300 bytes or more, longer than this machine's
    255. That student is unpacked in a folder whose name lost characters from the middle of the name
    (its participant number kept), and graded; a class archive of uploads at the top with such a name
    refuses that upload alone; the others are unpacked."""
    upload = [('exam.zip', open(make_zip(tmp_path / 'exam.zip', [('exam/package.xml', PACKAGE_XML)]), 'rb').read())]
    long_folder = 'Жанна %s_4711_assignsubmission_file_' % ('Ш' * 140)
    archive = moodle_class(tmp_path / 'class.zip', {long_folder: upload, 'Cy Fine_13_assignsubmission_file_': upload})
    refused = {}
    students = classlist.list_students(archive, str(tmp_path / 'scratch'), refused)
    assert refused == {}
    assert len(students) == 2 and students[0][0] == 'Cy Fine'
    name, folder = students[1]
    assert os.path.isfile(os.path.join(folder, 'exam.zip'))
    assert len(os.path.basename(folder).encode('utf-8')) <= archives.NAME_MAX
    assert os.path.basename(folder).startswith('Жанна ШШ') and os.path.basename(folder).endswith(
        'Ш_4711_assignsubmission_file_')
    assert identity.participant_number(os.path.basename(folder)) == 4711
    at_top = make_zip(tmp_path / 'tops.zip', [('%s.zip' % ('Ш' * 140), upload[0][1]), ('Cy Fine.zip', upload[0][1])])
    refused = {}
    students = classlist.list_students(at_top, str(tmp_path / 'tops'), refused)
    assert [name for name, _ in students][0] == 'Cy Fine' and len(students) == 2
    assert list(refused.values()) == ['entry %s has a name of more than 255 bytes' % archives.shown_name('Ш' * 140 + '.zip')]


def test_a_class_zip_is_bounded_as_a_whole(tmp_path, monkeypatch):
    """What no student's bounds can say refuses the class: more entries or bytes than a class holds, an
    entry outside every student's folder."""
    students = {'S%d_%d_assignsubmission_file_' % (i, i): [('a.txt', 'x' * 100)] for i in range(3)}
    archive = moodle_class(tmp_path / 'class.zip', students)
    monkeypatch.setattr(classlist, 'CLASS_BYTES', 250)
    with pytest.raises(archives.UnpackError, match=r'come to 300 bytes \(at most 250 for a class\)'):
        classlist.list_students(archive, str(tmp_path / 'a'))
    monkeypatch.setattr(classlist, 'CLASS_FILES', 2)
    with pytest.raises(archives.UnpackError, match=r'holds 3 entries \(at most 2 for a class\)'):
        classlist.list_students(archive, str(tmp_path / 'b'))
    monkeypatch.setattr(classlist, 'CLASS_FILES', 100)
    with zipfile.ZipFile(archive, 'a') as zf:
        zf.writestr('../outside.txt', 'x')
    with pytest.raises(archives.UnpackError, match='outside'):
        classlist.list_students(archive, str(tmp_path / 'c'))


def test_a_student_named_like_an_output_gets_a_folder_of_its_own(tmp_path):
    """``grades.csv.zip`` and ``index.html.zip`` at a class's top, a Moodle folder ``hand.csv_7_...``:
    none is named like the class's files."""
    archive = make_zip(tmp_path / 'class.zip', [
        ('grades.csv.zip', 'z'), ('index.html.zip', 'z'), ('hand.csv_7_assignsubmission_file_/exam.zip', 'z')])
    names = [name for name, _ in classlist.list_students(archive, str(tmp_path / 'scratch'))]
    assert names == ['grades_csv', 'hand_csv', 'index_html']


def test_a_name_in_any_bytes_is_shown_as_its_bytes():
    """A byte that is not UTF-8 (surrogateescape) reads ``\\xNN`` in a note, as on the page; a name
    that merely holds a backslash is not taken for one."""
    assert archives.shown_name(b'exam/lien\xfe'.decode('utf-8', 'surrogateescape')) == "'exam/lien\\xfe'"
    assert archives.shown_name('a\\udcff') == "'a\\\\udcff'"
    assert archives.shown_name('Größe\n') == "'Größe\\n'"


def _class_archive(path, kind, entries):
    """A class archive of ``(name, bytes, mode)`` entries, each with its Unix mode, as zip or tar."""
    if kind == 'zip':
        with zipfile.ZipFile(str(path), 'w', zipfile.ZIP_DEFLATED) as zf:
            for name, data, mode in entries:
                info = zipfile.ZipInfo(name, (2026, 6, 12, 14, 0, 0))
                info.create_system = 3
                info.external_attr = (stat.S_IFREG | mode) << 16
                zf.writestr(info, data)
    else:
        with tarfile.open(str(path), 'w:gz') as tf:
            for name, data, mode in entries:
                info = tarfile.TarInfo(name)
                info.size, info.mode = len(data), mode
                tf.addfile(info, io.BytesIO(data))
    return str(path)


@pytest.mark.parametrize('kind', ['zip', 'tar'])
def test_a_class_archive_keeps_each_script_s_x_bit_through_every_copy(tmp_path, kind):
    """Issue 38: whether a script is executable is a fact of the grade (the sheet asks for chmod +x), so a
    script handed in executable in a class archive stays so through every copy the grader makes (the
    intake's unpacking, the staging for the student's box, the package's copy into the workspace),
    whatever the umask (077 on a cluster's account), and one handed in without it is still "made
    executable"."""
    folder = 'Ann Lee_11_assignsubmission_file_/exam/'
    archive = _class_archive(tmp_path / ('class.' + kind), kind, [
        (folder + 'package.xml', PACKAGE_XML.encode(), 0o644),
        (folder + 'scripts/exam_node.py', b'#!/usr/bin/env python3\nprint(1)\n', 0o755),
        (folder + 'scripts/helper.py', b'#!/usr/bin/env python3\nprint(2)\n', 0o644)])
    umask = os.umask(0o077)
    try:
        (name, unpacked), = classlist.list_students(archive, str(tmp_path / 'intake'))
        staged = str(tmp_path / 'upload')
        staging.stage_upload(unpacked, staged)
        notes = []
        pkg = str(tmp_path / 'ws' / 'exam')
        package.copy_package(package.open_submission(staged, str(tmp_path / 'scratch'), notes), pkg, notes)
        for at in (os.path.join(unpacked, 'exam'), staged + '/exam', pkg):
            assert os.stat(os.path.join(at, 'scripts', 'exam_node.py')).st_mode & 0o777 == 0o755, at
            assert os.stat(os.path.join(at, 'scripts', 'helper.py')).st_mode & 0o111 == 0, at
        assert source.make_runnable(pkg, ['exam_node.py']) == [
            'scripts/helper.py was not executable: made executable (chmod +x), as the sheet asks']
    finally:
        os.umask(umask)
    assert name == 'Ann Lee'


def test_a_class_tar_judges_a_student_s_huge_member_on_that_student_s_row(tmp_path, monkeypatch):
    """Issue 36 point 3, for a class the teacher packed as a .tar.gz: a student's member over the
    student's own bounds refuses that student alone, on its row, as in a class zip (it was counted
    against the class's total while the tar was listed, and stopped the listing of the whole class);
    the class's own bounds (what listing reads through, its entries) still refuse the class. Bounds
    lowered: 5 MB of zeros (a few KB packed) stand for a recording of gigabytes."""
    monkeypatch.setattr(archives, 'MAX_BYTES', 1 << 20)
    monkeypatch.setattr(classlist, 'CLASS_BYTES', 4 << 20)
    monkeypatch.setattr(classlist, 'CLASS_READ_BYTES', 8 << 20)
    upload = open(make_zip(tmp_path / 'exam.zip', [('exam/package.xml', PACKAGE_XML)]), 'rb').read()
    folder = '%s_%d_assignsubmission_file_/'
    archive = str(tmp_path / 'class.tar.gz')
    with tarfile.open(archive, 'w:gz') as tf:
        for name, data in ((folder % ('Ann Lee', 11) + 'exam.zip', upload),
                           (folder % ('Bob Bag', 12) + 'exam.zip', upload),
                           (folder % ('Bob Bag', 12) + 'flight.bag', b'\0' * (5 << 20)),
                           (folder % ('Cy Fine', 13) + 'exam.zip', upload)):
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tf.addfile(info, io.BytesIO(data))
    assert os.path.getsize(archive) < 64 << 10
    refused = {}
    students = classlist.list_students(archive, str(tmp_path / 'scratch'), refused)
    assert [name for name, _ in students] == ['Ann Lee', 'Bob Bag', 'Cy Fine']
    paths = dict(students)
    assert refused == {paths['Bob Bag']: "the files of 'Bob Bag_12_assignsubmission_file_': %d more bytes, beyond "
                                         "the %d a submission may unpack" % ((5 << 20) + len(upload), 1 << 20)}
    assert os.listdir(paths['Bob Bag']) == []
    for name in ('Ann Lee', 'Cy Fine'):
        assert open(os.path.join(paths[name], 'exam.zip'), 'rb').read() == upload, name
    monkeypatch.setattr(classlist, 'CLASS_READ_BYTES', 3 << 20)  # the class's own bounds still hold
    with pytest.raises(archives.UnpackError, match=r'class.tar.gz: listing it would read \d+ bytes \(at most 3145728 '
                                                   r'for a class, students refused by their own bounds included\)'):
        classlist.list_students(archive, str(tmp_path / 'again'))
    monkeypatch.setattr(classlist, 'CLASS_READ_BYTES', 8 << 20)
    monkeypatch.setattr(classlist, 'CLASS_FILES', 3)
    with pytest.raises(archives.UnpackError, match=r'holds more than 3 entries \(at most 3 for a class\)'):
        classlist.list_students(archive, str(tmp_path / 'more'))


def test_every_box_s_work_folder_is_laid_out_alike(tmp_path):
    """One layout for every box's work folder (a submission's, a class archive's intake, the similarity
    check's): 0711, each source as ``upload/<index>/<name>`` (a name that is no file name as
    ``upload``), the workspace ``ws/src``; a source over its bounds is refused, raised or named in
    ``refused`` with the others still staged."""
    ann, big = tmp_path / 'Ann Lee_11_assignsubmission_file_', tmp_path / 'big.zip'
    ann.mkdir()
    (ann / 'exam.zip').write_bytes(b'zip')
    big.write_bytes(b'x' * 64)
    work = staging.new_work('exam-test-', str(tmp_path))
    assert stat.S_IMODE(os.stat(work).st_mode) == 0o711
    refused = {}
    staged = staging.stage_work(work, [(ann.name, str(ann)), ('..', str(ann / 'exam.zip')), ('big.zip', str(big))],
                                (16, 10), refused)
    assert staged == [os.path.join(work, 'upload', '0', ann.name), os.path.join(work, 'upload', '1', 'upload'), None]
    assert open(os.path.join(staged[0], 'exam.zip'), 'rb').read() == b'zip' and os.path.isfile(staged[1])
    assert list(refused) == [str(big)] and 'larger than the grader takes' in refused[str(big)]
    assert sorted(os.listdir(os.path.join(work, 'upload'))) == ['0', '1']
    assert os.path.isdir(os.path.join(work, 'ws', 'src')) and os.listdir(os.path.join(work, 'ws', 'src')) == []
    again = staging.new_work('exam-test-', str(tmp_path))
    with pytest.raises(staging.UploadRefused):
        staging.stage_work(again, [('big.zip', str(big))], (16, 10))


# Class zips as the usual tools make them (issue 45 point 4): each zip below is made by the real tool on
# this machine (tools/install_deps.sh installs Info-ZIP's zip, bsdtar, 7-Zip), from a class folder laid
# out as Moodle names it; what each tool wrote is checked first, so that a test says what it tests.

#: Students of the class, each a name in Moodle and a participant number: accents in Latin-1, and
#: (for the tools that write UTF-8) a name no single-byte code page holds.
LATIN1_CLASS = (("Zoé D'Arc", 42), ('Bob Late', 43), ('Jürgen Groß', 44))
UTF8_CLASS = LATIN1_CLASS + (('Анна Петрова', 45),)
#: A class folder as a teacher names what they unpacked Moodle's zip into.
CLASS_FOLDER = 'Robotique-Examen-1234'


@pytest.fixture(scope='module')
def locales(tmp_path_factory):
    """``{locale: LOCPATH}``: 'C' with no other locale at all (a server's or a container's: Info-ZIP's
    zip then writes UTF-8 names unflagged), 'en_US.UTF-8' (a desktop's, the locale Info-ZIP's zip looks
    for) and 'fr_FR.ISO-8859-1' (an older system's, a code page as Windows' are), each made by
    localedef from Debian's locale sources (package locales)."""
    missing = [tool for tool in ('zip', 'bsdtar', '7z', 'localedef') if shutil.which(tool) is None]
    assert not missing, 'tools/install_deps.sh installs them: %s' % missing
    base = tmp_path_factory.mktemp('locales')
    (base / 'none').mkdir()
    for name in ('en_US.UTF-8', 'fr_FR.ISO-8859-1'):
        source, charmap = name.split('.')
        subprocess.run(['localedef', '-i', source, '-f', charmap, str(base / name)], check=True, timeout=120,
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    return {'C': str(base / 'none'), 'en_US.UTF-8': str(base), 'fr_FR.ISO-8859-1': str(base)}


def run_tool(argv, cwd, locales, locale):
    """Run an archiver in ``locale`` and only it (LOCPATH: no locale of this machine's is seen)."""
    env = {'PATH': os.environ['PATH'], 'HOME': str(cwd), 'LC_ALL': locale, 'LOCPATH': locales[locale]}
    subprocess.run(argv, cwd=str(cwd), env=env, check=True, timeout=120, stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def moodle_class_folder(base, students, layout='4.1', encoding='utf-8'):
    """The class folder as Moodle's "download all submissions" unpacks: ``<folder as downloader.php names
    it>/exam.zip``, each a package (made by Python's zipfile), its file names in ``encoding`` as a system
    of that code page keeps them. Returns ``(the folder, {student's folder name: its exam.zip's bytes})``."""
    from test_grader_moodle_names import download_path  # downloader.php's names, ported
    klass = base / CLASS_FOLDER
    uploads = {}
    for name, number in students:
        folder = download_path(name, number, 'exam.zip', layout).split('/')[0]
        path = os.path.join(str(klass).encode(), folder.encode(encoding))
        os.makedirs(path)
        upload = io.BytesIO()
        with zipfile.ZipFile(upload, 'w') as zf:
            zf.writestr('exam/package.xml', PACKAGE_XML)
            zf.writestr('exam/scripts/exam_node.py', '# %s\n' % name)
        uploads[folder] = upload.getvalue()
        with open(os.path.join(path, b'exam.zip'), 'wb') as f:
            f.write(uploads[folder])
    return klass, uploads


def raw_entries(archive):
    """``[(the name field's bytes, flagged UTF-8, extra field ids)]`` of a zip, as it is written."""
    out = []
    with zipfile.ZipFile(str(archive)) as zf:
        for info in zf.infolist():
            raw = info.orig_filename.encode('utf-8' if info.flag_bits & 0x800 else 'cp437')
            extra, ids = info.extra, []
            while len(extra) >= 4:
                kind, size = struct.unpack('<HH', extra[:4])
                ids.append(kind)
                extra = extra[4 + size:]
            out.append((raw, bool(info.flag_bits & 0x800), ids))
    return out


def assert_class_read(archive, uploads, tmp_path):
    """Every student listed under the name Moodle's folder gives (:func:`identity.student_name`), with its
    participant number, none refused, each one's upload unpacked as it was handed in."""
    refused = {}
    students = classlist.list_students(str(archive), str(tmp_path / 'intake'), refused)
    assert refused == {}
    assert sorted(name for name, _ in students) == sorted(identity.student_name(f) for f in uploads)
    for name, path in students:
        folder = [f for f in uploads if identity.student_name(f) == name][0]
        assert identity.participant_number(os.path.basename(path)) == identity.participant_number(folder)
        assert os.listdir(path) == ['exam.zip'], name
        assert open(os.path.join(path, 'exam.zip'), 'rb').read() == uploads[folder], name
    return [name for name, _ in students]


#: How each tool is run on the class folder, from inside it ('.', the students at the top) or from its
#: parent (the class folder a directory entry at the top, as Moodle's "download in folders" zipped
#: again), in which locale, and what it writes (checked): directory entries, names flagged or not.
CLASS_ZIPS = {
    'zip -r, C locale': (['zip', '-q', '-r', '../class.zip', '.'], 'inside', 'C', 'dirs unflagged'),
    'zip -r, UTF-8 locale': (['zip', '-q', '-r', 'class.zip', CLASS_FOLDER], 'parent', 'en_US.UTF-8', 'dirs flagged'),
    'zip -r -D (no directory entries)': (['zip', '-q', '-r', '-D', 'class.zip', CLASS_FOLDER], 'parent', 'C',
                                         'unflagged'),
    'bsdtar, C locale': (['bsdtar', '-a', '-cf', '../class.zip', '.'], 'inside', 'C', 'dirs unflagged'),
    'bsdtar, UTF-8 locale': (['bsdtar', '-a', '-cf', 'class.zip', CLASS_FOLDER], 'parent', 'en_US.UTF-8',
                             'dirs flagged'),
    '7z a': (['7z', 'a', '-bd', '-tzip', '../class.zip', '.'], 'inside', 'C', 'dirs flagged'),
    '7z a -mcl=on (local code page, Unicode Path field)': (
        ['7z', 'a', '-bd', '-tzip', '-mcl=on', 'class.zip', CLASS_FOLDER], 'parent', 'en_US.UTF-8',
        'dirs unflagged unicode-path'),
    "Python's zipfile -c": ([sys.executable, '-m', 'zipfile', '-c', 'class.zip', CLASS_FOLDER], 'parent', 'C',
                            'dirs flagged'),
}


@pytest.mark.parametrize('how', sorted(CLASS_ZIPS))
def test_a_class_zip_made_by_the_usual_tools_grades_every_student(tmp_path, locales, how):
    """Issue 45 point 4: a class folder zipped again by the teacher, by each usual tool, in a C or a UTF-8
    locale: its folders' own entries are folders (they refused every student: "'Bob Late_43_
    assignsubmission_file' is both a file and a folder"), its names read as the tool wrote them, UTF-8
    flagged or not ("Zo├⌐ DArc", then "Zo__ DArc" on the teacher's page, when read as cp437)."""
    argv, where, locale, wrote = CLASS_ZIPS[how]
    klass, uploads = moodle_class_folder(tmp_path, UTF8_CLASS)
    run_tool(argv, klass if where == 'inside' else tmp_path, locales, locale)
    entries = raw_entries(tmp_path / 'class.zip')
    accented = [(flagged, ids) for raw, flagged, ids in entries if 'Zoé'.encode() in raw]
    assert accented, 'the names are written in UTF-8'
    assert all(flagged == ('unflagged' not in wrote) for flagged, _ in accented), entries
    assert all((0x7075 in ids) == ('unicode-path' in wrote) for _, ids in accented), entries
    assert any(raw.endswith(b'/') for raw, _, _ in entries) == ('dirs' in wrote), entries
    names = assert_class_read(tmp_path / 'class.zip', uploads, tmp_path)
    assert "Zoé DArc" in names and 'Анна Петрова' in names and 'Jürgen Groß' in names


def test_a_class_zip_in_a_code_page_reads_its_names_as_written(tmp_path, locales):
    """Names in a single-byte code page, as Windows' tools and older systems write them (here by the real
    tools on this machine, in a Latin-1 locale or with their code page option): 7-Zip's Unicode Path
    Extra Field gives the name when it stands for the name field (its CRC-32) and is UTF-8; names that
    are not UTF-8 are cp437 (APPNOTE.TXT's, and Windows Explorer's in Western Europe agrees with it on
    é, ü, ß: cp850); a field that is not UTF-8 is passed over; a name flagged UTF-8 that is not refuses
    the zip (zipfile cannot list it) with why, for the teacher to zip it again."""
    klass, uploads = moodle_class_folder(tmp_path, LATIN1_CLASS, encoding='latin-1')
    run_tool(['7z', 'a', '-bd', '-tzip', '-mcl=on', '../7z-latin1.zip', '.'], klass, locales, 'fr_FR.ISO-8859-1')
    written = [(raw, ids) for raw, _, ids in raw_entries(tmp_path / '7z-latin1.zip') if b'Zo\xe9' in raw]
    assert written and all(0x7075 in ids for _, ids in written), 'Latin-1 names, each with its UTF-8 field'
    assert "Zoé DArc" in assert_class_read(tmp_path / '7z-latin1.zip', uploads, tmp_path / 'a')

    utf8_class, utf8_uploads = moodle_class_folder(tmp_path / 'utf8', LATIN1_CLASS)
    run_tool(['bsdtar', '--options', 'zip:hdrcharset=CP850', '-a', '-cf', '../../cp850.zip', '.'], utf8_class,
             locales, 'en_US.UTF-8')
    assert [raw for raw, flagged, _ in raw_entries(tmp_path / 'cp850.zip') if b'Zo\x82' in raw and not flagged]
    names = assert_class_read(tmp_path / 'cp850.zip', utf8_uploads, tmp_path / 'b')
    assert "Zoé DArc" in names and 'Jürgen Groß' in names

    run_tool(['7z', 'a', '-bd', '-tzip', '-mcl=on', '../7z-c.zip', '.'], klass, locales, 'C')
    with zipfile.ZipFile(str(tmp_path / '7z-c.zip')) as zf:
        fields = [info.extra for info in zf.infolist() if b'Zo\xe9' in info.orig_filename.encode('cp437')]
    assert fields and all(b'Zo\xe9' in extra for extra in fields), "7-Zip's field holds the Latin-1 bytes"
    refused = {}
    students = classlist.list_students(str(tmp_path / '7z-c.zip'), str(tmp_path / 'c'), refused)
    assert refused == {} and len(students) == 3, 'no student lost, each with its number'
    assert sorted(identity.participant_number(os.path.basename(p)) for _, p in students) == [42, 43, 44]
    assert 'ZoΘ DArc' in [name for name, _ in students], 'what cp437 makes of é in Latin-1, not UTF-8'

    run_tool(['bsdtar', '-a', '-cf', '../flagged.zip', '.'], klass, locales, 'en_US.UTF-8')
    assert [raw for raw, flagged, _ in raw_entries_unchecked(tmp_path / 'flagged.zip') if b'Zo\xe9' in raw and flagged]
    with pytest.raises(archives.UnpackError, match=re.escape(
            "flagged.zip is not a readable zip: an entry's name is said to be UTF-8 and is not (byte \\xe9; made by "
            "a tool whose locale was not the names' own): ask for it zipped again")):
        classlist.list_students(str(tmp_path / 'flagged.zip'), str(tmp_path / 'd'))
    student = tmp_path / 'upload'
    student.mkdir()
    shutil.copy(str(tmp_path / 'flagged.zip'), str(student / 'exam.zip'))
    with pytest.raises(archives.UnpackError, match=re.escape('exam.zip (refused: exam.zip is not a readable zip')):
        package.open_submission(str(student), str(tmp_path / 'scratch'), [])


def raw_entries_unchecked(archive):
    """``[(name field's bytes, flagged UTF-8, None)]`` read from the central directory by its offsets
    (APPNOTE.TXT 4.3.12, 4.3.16), for a zip whose names zipfile cannot decode."""
    data = open(str(archive), 'rb').read()
    end = data.rindex(b'PK\x05\x06')
    count, _, start = struct.unpack('<HLL', data[end + 10:end + 20])
    out = []
    for _ in range(count):
        flags, = struct.unpack('<H', data[start + 8:start + 10])
        name_len, extra_len, comment_len = struct.unpack('<HHH', data[start + 28:start + 34])
        out.append((data[start + 46:start + 46 + name_len], bool(flags & 0x800), None))
        start += 46 + name_len + extra_len + comment_len
    return out


def test_a_class_zipped_on_a_mac_skips_its_finder_copies(tmp_path, locales):
    """macOS's ``ditto -c -k --keepParent`` (Finder's "Compress") writes the class folder at the top, a
    ``__MACOSX/`` folder of AppleDouble copies and, beside an entry with Finder data, its ``._<name>``
    copy. No Mac here: the folder is laid out as ditto's zip holds it (the copies' bytes stand for Finder
    data) and zipped by Info-ZIP's zip; none of the copies is a student, nor a second upload of one."""
    klass, uploads = moodle_class_folder(tmp_path, LATIN1_CLASS)
    for folder in uploads:
        (klass / folder / '._exam.zip').write_bytes(b'Finder data, not a zip')
        (klass / ('._' + folder)).write_bytes(b'Finder data')
        sequestered = tmp_path / '__MACOSX' / CLASS_FOLDER / folder
        sequestered.mkdir(parents=True)
        (sequestered / '._exam.zip').write_bytes(b'Finder data, not a zip')
    (tmp_path / ('._' + CLASS_FOLDER)).write_bytes(b'Finder data')
    run_tool(['zip', '-q', '-r', 'class.zip', CLASS_FOLDER, '._' + CLASS_FOLDER, '__MACOSX'], tmp_path, locales, 'C')
    names = [raw for raw, _, _ in raw_entries(tmp_path / 'class.zip')]
    assert sum(raw.split(b'/')[-1].startswith(b'._') for raw in names) == 3 * len(uploads) + 1
    assert "Zoé DArc" in assert_class_read(tmp_path / 'class.zip', uploads, tmp_path)
    notes = []
    students = dict(classlist.list_students(str(tmp_path / 'class.zip'), str(tmp_path / 'again')))
    package.open_submission(students['Bob Late'], str(tmp_path / 'scratch'), notes)
    assert notes == []


def test_a_student_both_a_file_and_a_folder_is_refused_alone(tmp_path, locales):
    """A name that really is a file and a folder in one class zip (an upload added to a zip that held
    the student's folder, by Info-ZIP's zip run twice) refuses that student only: its row says why, the
    others are graded; the class folder's own entry and the students' refuse no one."""
    klass, uploads = moodle_class_folder(tmp_path, LATIN1_CLASS)
    run_tool(['zip', '-q', '-r', '../class.zip', '.'], klass, locales, 'C')
    (tmp_path / 'later').mkdir()
    (tmp_path / 'later' / 'Bob Late_43_assignsubmission_file').write_bytes(uploads['Bob Late_43_assignsubmission_file'])
    run_tool(['zip', '-q', '../class.zip', 'Bob Late_43_assignsubmission_file'], tmp_path / 'later', locales, 'C')
    refused = {}
    students = dict(classlist.list_students(str(tmp_path / 'class.zip'), str(tmp_path / 'intake'), refused))
    assert sorted(students) == ['Bob Late', 'Jürgen Groß', "Zoé DArc"]
    assert refused == {students['Bob Late']: "'Bob Late_43_assignsubmission_file' is both a file and a folder"}
    assert os.listdir(students["Zoé DArc"]) == ['exam.zip'] and os.listdir(students['Jürgen Groß']) == ['exam.zip']


@pytest.mark.parametrize('tool', ['zip', 'bsdtar', '7z'])
def test_a_student_s_own_zip_is_read_as_the_class_s(tmp_path, locales, tool):
    """A student's package zipped by the usual tools (its folders' entries, a file named in French,
    Info-ZIP's zip under a C locale writing it unflagged, macOS's copies): the same reader as a class
    zip's, so the package is found and its files keep their names."""
    (tmp_path / 'exam' / 'scripts').mkdir(parents=True)
    (tmp_path / 'exam' / 'package.xml').write_text(PACKAGE_XML)
    (tmp_path / 'exam' / 'scripts' / 'réponse_q3.txt').write_text('12 m')
    (tmp_path / 'exam' / '._package.xml').write_bytes(b'Finder data')
    argv = {'zip': ['zip', '-q', '-r', 'exam.zip', 'exam'], 'bsdtar': ['bsdtar', '-a', '-cf', 'exam.zip', 'exam'],
            '7z': ['7z', 'a', '-bd', '-tzip', '-mcl=on', 'exam.zip', 'exam']}[tool]
    run_tool(argv, tmp_path, locales, 'C')
    assert any(raw.endswith(b'/') for raw, _, _ in raw_entries(tmp_path / 'exam.zip'))
    assert any(not flagged for raw, flagged, _ in raw_entries(tmp_path / 'exam.zip') if 'é'.encode() in raw)
    notes = []
    found = package.open_submission(str(tmp_path / 'exam.zip'), str(tmp_path / 'scratch'), notes)
    assert sorted(os.listdir(found)) == ['package.xml', 'scripts'] and notes == []
    assert os.listdir(os.path.join(found, 'scripts')) == ['réponse_q3.txt']


def test_class_zips_of_other_shapes(tmp_path, locales):
    """Cases of the same kind: names with Windows' backslashes (a Linux file name holding them, zipped
    by Info-ZIP's zip, as some Windows tools write every separator), flagged and unflagged entries in one
    zip (7-Zip adding a late student to a zip Info-ZIP's zip made under a C locale), and a class of one
    student zipped with its folder at the top (a folder Moodle names a student's is never taken for a
    class folder)."""
    klass, uploads = moodle_class_folder(tmp_path, LATIN1_CLASS[:2])
    run_tool(['zip', '-q', '-r', '../mixed.zip', '.'], klass, locales, 'C')
    late, late_uploads = moodle_class_folder(tmp_path / 'late', (('Анна Петрова', 45),))
    run_tool(['7z', 'a', '-bd', '-tzip', '../../mixed.zip', '.'], late, locales, 'C')
    flags = set(flagged for raw, flagged, _ in raw_entries(tmp_path / 'mixed.zip') if not raw.isascii())
    assert flags == {True, False}
    uploads.update(late_uploads)
    assert 'Анна Петрова' in assert_class_read(tmp_path / 'mixed.zip', uploads, tmp_path / 'a')

    flat = tmp_path / 'windows'
    flat.mkdir()
    for folder, data in uploads.items():
        (flat / (folder + '\\exam.zip')).write_bytes(data)
    run_tool(['zip', '-q', '-r', '../windows.zip', '.'], flat, locales, 'C')
    assert all(b'\\' in raw for raw, _, _ in raw_entries(tmp_path / 'windows.zip'))
    assert_class_read(tmp_path / 'windows.zip', uploads, tmp_path / 'b')

    zoe = 'Zoé DArc_42_assignsubmission_file'
    run_tool(['zip', '-q', '-r', '../one.zip', zoe], klass, locales, 'C')
    assert_class_read(tmp_path / 'one.zip', {zoe: uploads[zoe]}, tmp_path / 'c')

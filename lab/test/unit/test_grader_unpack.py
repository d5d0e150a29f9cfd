"""Unpacking what students upload: unsafe archives refused as a whole, the package found."""
import os
import stat
import zipfile

import pytest

from exam_lab.grader.boxed import unpack

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
    with pytest.raises(unpack.UnpackError):
        unpack.safe_extract(archive, str(tmp_path / 'out'))
    assert not (tmp_path / 'out').exists(), 'nothing is written from a refused archive'


def test_links_are_dropped_and_noted_never_followed(tmp_path):
    archive = make_zip(tmp_path / 'a.zip', [('exam/package.xml', PACKAGE_XML)], links=[('exam/l', '/etc/passwd')])
    notes, fixes = [], []
    assert unpack.safe_extract(archive, str(tmp_path / 'out'), notes=notes, fixes=fixes) == 1
    assert not os.path.lexists(str(tmp_path / 'out' / 'exam' / 'l'))
    assert fixes and "'exam/l' -> '/etc/passwd'" in fixes[0] and not notes


def test_bombs_and_crowds_are_refused(tmp_path):
    bomb = make_zip(tmp_path / 'bomb.zip', [('exam/big', b'\0' * (5 * 1024 * 1024))])
    with pytest.raises(unpack.UnpackError, match='bomb'):
        unpack.safe_extract(bomb, str(tmp_path / 'out'))
    crowd = make_zip(tmp_path / 'crowd.zip', [('f%d' % i, 'x') for i in range(20)])
    with pytest.raises(unpack.UnpackError, match='20 more files, beyond the 10'):
        unpack.safe_extract(crowd, str(tmp_path / 'out2'), max_files=10)
    big = make_zip(tmp_path / 'big.zip', [('f', 'y' * 5000)])
    with pytest.raises(unpack.UnpackError, match='5000 more bytes, beyond the 1000'):
        unpack.safe_extract(big, str(tmp_path / 'out3'), max_bytes=1000)


def test_not_a_zip(tmp_path):
    path = tmp_path / 'report.zip'
    path.write_text('not a zip')
    with pytest.raises(unpack.UnpackError, match='not a readable zip'):
        unpack.safe_extract(str(path), str(tmp_path / 'out'))


@pytest.mark.parametrize('prefix', ['', 'exam_jdupont/', 'catkin_ws/src/'])
def test_package_found_at_the_top_or_below(tmp_path, prefix):
    archive = make_zip(tmp_path / 'a.zip', [(prefix + 'exam/package.xml', PACKAGE_XML),
                                            (prefix + 'exam/scripts/exam_node.py', 'print(1)'),
                                            ('__MACOSX/._exam', 'junk')])
    notes = []
    found = unpack.open_submission(archive, str(tmp_path / 'scratch'), notes)
    assert found.endswith(os.path.join(prefix.rstrip('/'), 'exam').lstrip('/'))
    assert os.path.isfile(os.path.join(found, 'scripts', 'exam_node.py'))


def test_student_folder_with_report_and_zip(tmp_path):
    folder = tmp_path / 'Jane Doe_1234_assignsubmission_file_'
    folder.mkdir()
    (folder / 'report.pdf').write_bytes(b'%PDF-1.4')
    make_zip(folder / 'exam.zip', [('exam/package.xml', PACKAGE_XML)])
    students = unpack.list_students(str(tmp_path), str(tmp_path / 'scratch'))
    assert [name for name, _ in students] == ['Jane Doe']
    found = unpack.open_submission(students[0][1], str(tmp_path / 'scratch'), [])
    assert unpack.package_name(os.path.join(found, 'package.xml')) == 'exam'


def test_refused_zip_is_reported(tmp_path):
    folder = tmp_path / 'student'
    folder.mkdir()
    make_zip(folder / 'exam.zip', [('../x', 'x')])
    with pytest.raises(unpack.UnpackError, match='climbs out'):
        unpack.open_submission(str(folder), str(tmp_path / 'scratch'), [])


def test_class_zip(tmp_path):
    archive = make_zip(tmp_path / 'class.zip', [('all/Ann_1_assignsubmission_file_/exam/package.xml', PACKAGE_XML),
                                                ('all/Bob_2_assignsubmission_file_/exam/package.xml', PACKAGE_XML)])
    students = unpack.list_students(archive, str(tmp_path / 'scratch'))
    assert [name for name, _ in students] == ['Ann', 'Bob']


def test_copy_skips_build_products_and_links(tmp_path):
    src = tmp_path / 'exam'
    (src / 'build').mkdir(parents=True)
    (src / 'scripts').mkdir()
    (src / 'scripts' / 'exam_node.py').write_text('x')
    os.symlink('/etc/passwd', str(src / 'scripts' / 'link'))
    notes = []
    unpack.copy_package(str(src), str(tmp_path / 'copy'), notes)
    assert sorted(os.listdir(str(tmp_path / 'copy'))) == ['scripts']
    assert os.listdir(str(tmp_path / 'copy' / 'scripts')) == ['exam_node.py']
    assert any('link' in n for n in notes)

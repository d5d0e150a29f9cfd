"""What students really upload, unpacked as meant: Windows zips, tar archives, whole workspaces, any
package name; one budget per submission; unwritable or control-character names refused with a reason."""
import io
import os
import stat
import tarfile
import zipfile

import pytest

from exam_lab.grader.boxed import archives, classlist, package, source

PACKAGE_XML = '<package format="2"><name>%s</name></package>'


def windows_zip(path, entries):
    """A zip as Windows' "send to compressed folder" makes it: backslashes, no Unix modes."""
    with zipfile.ZipFile(str(path), 'w', zipfile.ZIP_DEFLATED) as zf:
        for name, data in entries:
            info = zipfile.ZipInfo(name.replace('/', '\\'))
            info.create_system = 0
            info.external_attr = 0x20  # the DOS "archive" attribute, no Unix mode
            zf.writestr(info, data)
    return str(path)


def make_tar(path, entries, links=(), mode='w:gz'):
    with tarfile.open(str(path), mode) as tf:
        for name, data in entries:
            data = data.encode() if isinstance(data, str) else data
            info = tarfile.TarInfo(name)
            info.size = len(data)
            info.mode = 0o755 if name.endswith('.py') else 0o644
            tf.addfile(info, io.BytesIO(data))
        for name, target in links:
            info = tarfile.TarInfo(name)
            info.type = tarfile.SYMTYPE
            info.linkname = target
            tf.addfile(info)
    return str(path)


def test_a_windows_zip_with_crlf_is_read_as_meant(tmp_path):
    script = '#!/usr/bin/env python3\r\nprint(1)\r\n'
    archive = windows_zip(tmp_path / 'exam.zip', [('exam/package.xml', PACKAGE_XML % 'exam'),
                                                  ('exam/scripts/exam_node.py', script)])
    found = package.open_submission(archive, str(tmp_path / 'scratch'), [])
    node = os.path.join(found, 'scripts', 'exam_node.py')
    assert os.path.isfile(node), 'backslashes are folders, not parts of a file name'
    fixes = source.fix_text(found)
    assert open(node, 'rb').read() == b'#!/usr/bin/env python3\nprint(1)\n'
    assert fixes == ['Windows line endings (CRLF) changed to LF, as dos2unix does, in 1 file(s): '
                     'scripts/exam_node.py']
    assert any('made executable' in n for n in source.make_runnable(found, ['exam_node.py']))
    assert os.stat(node).st_mode & stat.S_IXUSR


def test_a_utf8_bom_hiding_the_shebang_is_removed(tmp_path):
    pkg = tmp_path / 'exam'
    (pkg / 'scripts').mkdir(parents=True)
    (pkg / 'scripts' / 'exam_node.py').write_bytes(b'\xef\xbb\xbf#!/usr/bin/env python3\nprint(1)\n')
    (pkg / 'scripts' / 'clean.py').write_bytes(b'print(2)\n')
    assert source.fix_text(str(pkg)) == ['UTF-8 byte order mark removed from 1 file(s): scripts/exam_node.py']
    assert (pkg / 'scripts' / 'exam_node.py').read_bytes().startswith(b'#!')
    assert source.fix_text(str(pkg)) == [], 'a fixed package needs no second fix'


@pytest.mark.parametrize('name, mode', [('exam.tar.gz', 'w:gz'), ('exam.tgz', 'w:gz'), ('exam.tar.xz', 'w:xz'),
                                        ('exam.tar', 'w'), ('exam.tar.bz2', 'w:bz2')])
def test_tar_archives(tmp_path, name, mode):
    archive = make_tar(tmp_path / name, [('exam/package.xml', PACKAGE_XML % 'exam'),
                                         ('exam/scripts/exam_node.py', 'print(1)\n')], mode=mode)
    found = package.open_submission(archive, str(tmp_path / 'scratch'), [])
    assert os.access(os.path.join(found, 'scripts', 'exam_node.py'), os.X_OK), 'tar keeps the modes'


@pytest.mark.parametrize('name', ['../evil', '/etc/evil', 'exam/../../evil'])
def test_tar_entries_escaping_are_refused(tmp_path, name):
    archive = make_tar(tmp_path / 'exam.tar.gz', [('exam/package.xml', PACKAGE_XML % 'exam'), (name, 'x')])
    with pytest.raises(archives.UnpackError):
        archives.safe_extract(archive, str(tmp_path / 'out'))
    assert not (tmp_path / 'out').exists()


def test_a_whole_workspace_gives_its_package(tmp_path):
    """catkin_ws/ with build/, devel/, the drones and catkin's src/CMakeLists.txt link."""
    entries = [('catkin_ws/src/exam/package.xml', PACKAGE_XML % 'exam'),
               ('catkin_ws/src/mydrone/package.xml', PACKAGE_XML % 'mydrone'),
               ('catkin_ws/build/CMakeCache.txt', 'x' * 100), ('catkin_ws/devel/setup.bash', 'x'),
               ('catkin_ws/.catkin_workspace', '')]
    archive = make_tar(tmp_path / 'ws.tar.gz', entries,
                       links=[('catkin_ws/src/CMakeLists.txt', '/opt/ros/noetic/share/catkin/cmake/toplevel.cmake'),
                              ('catkin_ws/devel/lib/x', '/x')])
    notes, fixes = [], []
    found = package.open_submission(archive, str(tmp_path / 'scratch'), notes, fixes)
    assert found.endswith(os.path.join('catkin_ws', 'src', 'exam'))
    assert not os.path.exists(os.path.join(os.path.dirname(os.path.dirname(found)), 'build'))
    assert any("build products of a workspace not unpacked: catkin_ws/build/ (1 entries), "
               "catkin_ws/devel/ (2 entries)" in n for n in notes), notes
    assert any('a whole catkin workspace' in n for n in notes)
    assert fixes == ["ws.tar.gz: catkin's link 'catkin_ws/src/CMakeLists.txt' dropped (links are never "
                     "followed; the grader makes its own workspace)"]


def test_a_whole_workspace_zipped_on_linux_keeps_its_package(tmp_path):
    """zip -r catkin_ws.zip catkin_ws: catkin's link is a Unix symlink entry; dropped, not refused."""
    with zipfile.ZipFile(str(tmp_path / 'ws.zip'), 'w') as zf:
        zf.writestr('catkin_ws/src/exam/package.xml', PACKAGE_XML % 'exam')
        zf.writestr('catkin_ws/devel/setup.sh', 'x')
        info = zipfile.ZipInfo('catkin_ws/src/CMakeLists.txt')
        info.create_system = 3
        info.external_attr = (stat.S_IFLNK | 0o777) << 16
        zf.writestr(info, '/opt/ros/noetic/share/catkin/cmake/toplevel.cmake')
    notes, fixes = [], []
    found = package.open_submission(str(tmp_path / 'ws.zip'), str(tmp_path / 'scratch'), notes, fixes)
    assert found.endswith(os.path.join('catkin_ws', 'src', 'exam'))
    assert not os.path.lexists(os.path.join(os.path.dirname(found), 'CMakeLists.txt'))
    assert len(fixes) == 1 and "catkin's link 'catkin_ws/src/CMakeLists.txt' dropped" in fixes[0]
    assert 'a whole catkin workspace was uploaded: graded its package catkin_ws/src/exam' in notes


def test_a_package_however_named(tmp_path):
    archive = windows_zip(tmp_path / 'a.zip', [('catkin_ws/src/mydrone/package.xml', PACKAGE_XML % 'mydrone'),
                                               ('catkin_ws/src/exam_pkg/package.xml', PACKAGE_XML % 'exam_pkg')])
    fixes = []
    found = package.open_submission(archive, str(tmp_path / 'scratch'), [], fixes)
    assert os.path.basename(found) == 'exam_pkg', 'never a simulator'
    assert fixes == ["the package is named 'exam_pkg', not exam (question 9 asks for exam): graded as it is"]


def test_nested_archives_share_one_budget(tmp_path):
    """Twenty inner zips of 300 bytes each: each alone fits 1000 bytes, together they do not."""
    inner = io.BytesIO()
    with zipfile.ZipFile(inner, 'w') as zf:
        zf.writestr('data', 'z' * 300)
    outer = tmp_path / 'outer.zip'
    with zipfile.ZipFile(str(outer), 'w') as zf:
        for i in range(20):
            zf.writestr('part%d.zip' % i, inner.getvalue())
    notes = []
    with pytest.raises(archives.UnpackError, match='more bytes, beyond the'):
        package.open_submission(str(outer), str(tmp_path / 'scratch'), notes,
                               budget=archives.Budget(max_bytes=len(inner.getvalue()) * 20 + 1000))
    refused = [n for n in notes if 'beyond the' in n]
    assert refused and len(refused) < 20, notes
    written = sum(len(f) for _, _, f in os.walk(str(tmp_path / 'scratch')))
    assert written < 25


@pytest.mark.parametrize('name, reason', [('exam/a\nb.py', 'control character'), ('exam/a\x1b[2J.py', 'control character'),
                                          ('exam/' + 'x' * 300, 'more than 255 bytes'),
                                          ('/'.join(['d' * 200] * 25), 'more than 4096 bytes')])
def test_names_beyond_the_limits_are_refused_with_a_reason(tmp_path, name, reason):
    with zipfile.ZipFile(str(tmp_path / 'a.zip'), 'w') as zf:
        zf.writestr('exam/package.xml', PACKAGE_XML % 'exam')
        zf.writestr(name, 'x')
    notes = []
    with pytest.raises(archives.UnpackError, match=reason) as err:
        package.open_submission(str(tmp_path / 'a.zip'), str(tmp_path / 'scratch'), notes)
    assert '\n' not in str(err.value) and '\x1b' not in str(err.value) and len(str(err.value)) < 200


def test_duplicates_and_case_collisions_are_noted(tmp_path):
    with zipfile.ZipFile(str(tmp_path / 'a.zip'), 'w') as zf:
        zf.writestr('exam/package.xml', PACKAGE_XML % 'exam')
        zf.writestr('exam/scripts/node.py', 'old')
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter('ignore')  # zipfile warns about the duplicate it writes
            zf.writestr('exam/scripts/node.py', 'new')
        zf.writestr('exam/Scripts/node.py', 'other')
    notes = []
    found = package.open_submission(str(tmp_path / 'a.zip'), str(tmp_path / 'scratch'), notes)
    assert open(os.path.join(found, 'scripts', 'node.py')).read() == 'new'
    assert any("'exam/scripts/node.py'" in n and 'more than once' in n for n in notes), notes
    assert any('differ only by case' in n and 'exam/Scripts/node.py / exam/scripts/node.py' in n for n in notes)


def test_formats_that_cannot_be_opened_say_so_by_name(tmp_path):
    folder = tmp_path / 'Ann_1_assignsubmission_file_'
    folder.mkdir()
    (folder / 'exam.rar').write_bytes(b'Rar!\x1a\x07\x01\x00' + b'\0' * 20)
    (folder / 'report.pdf').write_bytes(b'%PDF-1.4')
    with pytest.raises(archives.UnpackError, match='RAR archive'):
        package.open_submission(str(folder), str(tmp_path / 'scratch'), [])
    with pytest.raises(archives.UnpackError, match='exam.rar is a RAR archive: the grader opens zip and tar'):
        package.open_submission(str(folder / 'exam.rar'), str(tmp_path / 'scratch'), [])


def test_a_class_of_tar_uploads(tmp_path):
    make_tar(tmp_path / 'Bob_2.tar.gz', [('exam/package.xml', PACKAGE_XML % 'exam')])
    students = classlist.list_students(str(tmp_path), str(tmp_path / 'scratch'))
    assert [name for name, _ in students] == ['Bob']

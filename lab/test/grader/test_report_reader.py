"""Students' reports read in a real box (host/reports.read_report, boxed/report_reader; issue 47 points
1 and 8): each fixture of lab/test/unit/data/reports (made by lab/test/reports/make_reports.py with
the tools students use) read, what was read checked on its page with its source; a report that cannot
be read is "not read" with why; a class with such students grades the others."""
import json
import os
import re
import shutil
import stat
import subprocess
import zipfile

import pytest

from exam_lab.grader import class_run
from exam_lab.grader.host import reports
from exam_lab.grader.publish import proposals
from exam_lab.grader.score.records import ReportRecord

HERE = os.path.dirname(os.path.realpath(__file__))
DATA = os.path.join(HERE, '..', 'unit', 'data', 'reports')
GOOD = os.path.join(HERE, 'submissions', 'good_student', 'exam')


def read(tmp_path, *names, folder='Jeanne Martin_12_assignsubmission_file_'):
    """The fixtures ``names`` handed in, in a Moodle folder, read in a box: ``(record, OUT)``."""
    submission = tmp_path / folder
    submission.mkdir()
    for name in names:
        shutil.copyfile(os.path.join(DATA, name), str(submission / name))
    out = tmp_path / 'out'
    record = reports.read_report(str(submission), str(out))
    assert ReportRecord.read(str(out / 'report.json')) == record  # what is kept is what was read
    return record, out


def page_with(record, words, source):
    """The page holding every one of ``words`` (its number), read from ``source``."""
    for page in record.pages:
        if all(w in page.text for w in words):
            assert page.source == source, (page.number, page.source)
            return page
    raise AssertionError('%s on no page:\n%s' % (words, '\n----\n'.join(p.text for p in record.pages)))


def assert_kept(record, out):
    """Every file and page image the record names is in OUT/report/, read-only, a page a PNG."""
    for path in [f.copy for f in record.files] + [p.image for p in record.pages]:
        assert path is not None
        full = os.path.join(str(out), path)
        assert not os.stat(full).st_mode & (stat.S_IWUSR | stat.S_IWGRP | stat.S_IWOTH)
        if path.endswith('.png'):
            with open(full, 'rb') as f:
                assert f.read(8) == b'\x89PNG\r\n\x1a\n'


def test_a_libreoffice_pdf_is_read_from_its_text_layer_and_its_screenshots_by_ocr(tmp_path):
    record, out = read(tmp_path, 'fr_odt.pdf')
    assert record.state == 'read' and record.why == ''
    assert [(f.kind, f.converted, f.pages, f.state) for f in record.files] == [('pdf', False, 2, 'read')]
    first = page_with(record, ['Question 4', '$ rosnode list', '/mydrone', 'Deux nœuds tournent'], 'text')
    assert first.number == 1 and first.confidence is None and first.pictures == 0
    second = page_with(record, ['Question 7', 'float32 data', 'average rate: 0.778'], 'text')
    assert second.number == 2 and second.pictures == 2 and second.confidence > 80
    text = second.text
    # the screenshots' words, where the screenshots stand: Q7's type before its comment, Q8's rate after its echo
    assert text.index('[picture 1, OCR]') < text.index('rosmsg info std_msgs/Float32') < text.index('Le message est du type')
    assert text.index('data: ') < text.index('[picture 2, OCR]') < text.index('average rate: 0.778') < \
        text.index('[end of picture 2]') < text.index('Les messages sont publiés à 0.778 Hz')
    assert_kept(record, out)


@pytest.mark.parametrize('name,converted', [('en_docx_table.docx', True), ('en_docx_table.pdf', False)])
def test_a_word_document_with_its_answers_in_a_table_is_read(tmp_path, name, converted):
    record, out = read(tmp_path, name, folder='John Smith_13_assignsubmission_file_')
    assert record.state == 'read'
    assert [(f.kind, f.converted, f.state) for f in record.files] == \
        [(name.rsplit('.', 1)[1], converted, 'read')]
    # each cell's text on lines of its own, as the cell wraps it
    q7 = page_with(record, ['Q7', 'std_msgs/Float32', 'float32 data', 'The type is', 'one field'], 'text')
    assert 'Q7' in q7.layout and 'float32 data' in q7.layout
    # the table's columns side by side in the layout text: the question, its command, its output
    assert any('Q4' in line and 'rosnode list' in line for line in q7.layout.splitlines())
    remote = page_with(record, ['[picture 1, OCR]', 'rostopic echo -n 3 /pressure_remote',
                                'subscribed to [/pressure_remote]', 'average rate: 1.0'], 'text')
    assert remote.pictures == 1
    assert_kept(record, out)


def test_an_odt_handed_in_is_converted_in_the_box(tmp_path):
    record, _ = read(tmp_path, 'fr_odt.odt')
    assert [(f.kind, f.converted, f.pages) for f in record.files] == [('odt', True, 2)]
    page_with(record, ['Question 9', 'catkin_create_pkg exam rospy std_msgs mydrone'], 'text')


def test_libreoffice_starts_once_from_the_readers_profile_without_its_graphics_tests(tmp_path):
    """The reader's LibreOffice profile (report_reader.OFFICE_PROFILE) is as the installed LibreOffice's first
    start leaves it: LibreOffice converts at its first start, without restarting itself (soffice.bin's exit
    81, which the soffice script hides) and without its graphics tests, whose log a new profile gets."""
    from exam_lab.grader.boxed import report_reader
    profile = str(tmp_path / 'profile')
    report_reader.office_profile(profile)
    done = subprocess.run([os.path.join(report_reader.OFFICE, 'program', 'soffice.bin'), '--headless', '--norestore',
                           '--nolockcheck', '-env:UserInstallation=file://%s' % profile, '--convert-to', 'pdf',
                           '--outdir', str(tmp_path), os.path.join(DATA, 'fr_odt.odt')],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=120)
    assert done.returncode == 0 and (tmp_path / 'fr_odt.pdf').is_file(), done.stdout
    assert not os.path.exists(os.path.join(profile, 'user', 'GraphicsRenderTests.log'))
    reader = report_reader.Reader(str(tmp_path / 'out'))  # the reader's own conversion starts from it
    reader.convert(0, os.path.join(DATA, 'fr_odt.odt'))
    user = os.path.join(reader.scratch, 'lo-profile', 'user')
    assert os.path.isdir(os.path.join(user, 'extensions', 'bundled'))  # LibreOffice used it
    assert not os.path.exists(os.path.join(user, 'GraphicsRenderTests.log'))


def test_an_image_only_scan_is_read_by_ocr_with_its_confidence(tmp_path):
    record, out = read(tmp_path, 'scan.pdf')
    assert record.state == 'read' and [p.source for p in record.pages] == ['ocr', 'ocr']
    assert all(p.layout == '' and 50 < p.confidence <= 100 for p in record.pages)
    page_with(record, ['Question 4', 'rosnode list', '/mydrone', '/rosout'], 'ocr')
    page_with(record, ['Question 8', 'float32 data', '0.778'], 'ocr')
    assert all(isinstance(w, str) for p in record.pages for w in p.unsure)
    assert_kept(record, out)


def test_a_screenshot_handed_in_is_read_by_ocr(tmp_path):
    record, _ = read(tmp_path, 'screenshot_rosnode_list.png')
    assert [(f.kind, f.state) for f in record.files] == [('image', 'read')]
    page = page_with(record, ['/mydrone', '/rosout_agg', '/temperature', 'rostopic list'], 'ocr')
    # tesseract reads this screenshot's first command "rosnode List" (its case is the proposals' to ignore)
    assert 'rosnode list' in page.text.lower()
    assert page.image == 'report/page-1-1.png' and page.confidence > 70


@pytest.mark.parametrize('name,why', [
    ('encrypted.pdf', "'encrypted.pdf': an encrypted PDF (it opens with a password): ask for it without one"),
    ('broken.pdf', "'broken.pdf': a broken PDF"),
    ('long_45_pages.pdf', "'long_45_pages.pdf': 46 pages, the reader reads 40"),
    ('picture_bomb.png', "'picture_bomb.png': a picture of 30000 x 30000 pixels (at most 40 million)"),
])
def test_a_report_that_cannot_be_read_is_not_read_with_why(tmp_path, name, why):
    record, out = read(tmp_path, name)
    assert record.state == 'not read' and record.pages == ()
    assert record.why.startswith(why), record.why
    assert record.files[0].state == 'not read' and record.files[0].note == record.why
    assert os.path.isfile(os.path.join(str(out), record.files[0].copy))  # kept for the teacher all the same


def test_one_file_not_read_leaves_the_others_read(tmp_path):
    record, _ = read(tmp_path, 'encrypted.pdf', 'fr_odt.pdf')
    assert record.state == 'read' and [f.state for f in record.files] == ['not read', 'read']
    assert {p.file for p in record.pages} == {1}


def test_no_report_handed_in_is_said(tmp_path):
    (tmp_path / 'empty').mkdir()
    (tmp_path / 'empty' / 'onlinetext.html').write_text('<p>see my zip</p>')
    record = reports.read_report(str(tmp_path / 'empty'), str(tmp_path / 'out'))
    assert (record.state, record.why) == ('not read', 'no report handed in (no PDF, no document, no picture '
                                                      'among the files)')


def test_the_report_inside_the_package_zip_is_read(tmp_path):
    folder = tmp_path / 'Paul Durand_14_assignsubmission_file_'
    folder.mkdir()
    with zipfile.ZipFile(str(folder / 'exam.zip'), 'w', zipfile.ZIP_DEFLATED) as zf:
        zf.write(os.path.join(DATA, 'fr_odt.pdf'), 'exam/rapport.pdf')
        zf.writestr('exam/package.xml', '<package><name>exam</name></package>')
    record = reports.read_report(str(folder), str(tmp_path / 'out'))
    assert [f.name for f in record.files] == ['exam.zip/exam/rapport.pdf']
    page_with(record, ['Question 4', '/mydrone'], 'text')


def test_a_class_with_reports_not_read_grades_every_student(tmp_path):
    """A student with a package and a PDF, two who handed in only a report (an encrypted PDF, a picture
    bomb): each has its row and its report.json, the one with a package its grade and its code/."""
    klass = tmp_path / 'class'
    good = klass / 'Jeanne Martin_12_assignsubmission_file_'
    good.mkdir(parents=True)
    shutil.copyfile(os.path.join(DATA, 'fr_odt.pdf'), str(good / 'rapport.pdf'))
    with zipfile.ZipFile(str(good / 'exam.zip'), 'w') as zf:
        for dirpath, _, filenames in os.walk(GOOD):
            for filename in filenames:
                full = os.path.join(dirpath, filename)
                zf.write(full, os.path.join('exam', os.path.relpath(full, GOOD)))
    for student, name in (('Anne Roy_13', 'encrypted.pdf'), ('Marc Petit_14', 'picture_bomb.png')):
        shutil.copyfile(os.path.join(DATA, name), str(klass / ('%s_assignsubmission_file_%s' % (student, name))))
    out = tmp_path / 'out'
    records = class_run.grade_class(str(klass), str(out), jobs=2)
    by_name = {r['student']: r for r in records}
    assert sorted(by_name) == ['Anne Roy', 'Jeanne Martin', 'Marc Petit']
    assert by_name['Jeanne Martin']['total'] == 17, json.dumps(by_name['Jeanne Martin'], indent=1)[:3000]
    kept = {name: proposals.kept_report(str(out / name)) for name in by_name}
    assert kept['Jeanne Martin'].state == 'read'
    assert kept['Anne Roy'].state == 'not read' and 'an encrypted PDF' in kept['Anne Roy'].why
    assert kept['Marc Petit'].state == 'not read' and '30000 x 30000 pixels' in kept['Marc Petit'].why
    code = out / 'Jeanne Martin' / 'code'
    assert sorted(os.listdir(str(code))) == sorted(os.listdir(GOOD))
    with open(os.path.join(GOOD, 'package.xml'), 'rb') as f:
        assert (code / 'package.xml').read_bytes() == f.read()  # as handed in: before any fix
    assert not os.stat(str(code / 'package.xml')).st_mode & stat.S_IWUSR
    assert not (out / 'Anne Roy' / 'code').exists()

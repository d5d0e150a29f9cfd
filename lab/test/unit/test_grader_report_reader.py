"""The report reader's pure parts (lab/src/exam_lab/grader/boxed/report_report_text.py, report_images.py) and
the report's record (score/records.ReportRecord): no box, no tool run. The reading of real reports in
a real box is test/grader/test_report_report_text.py."""
import os
import re
import zipfile

import pytest

from exam_lab.grader.boxed import report_files, report_reader, report_text
from exam_lab.grader.publish import proposals
from exam_lab.grader.score.records import REPORT_UNSURE, RecordError, ReportRecord

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), 'data', 'reports')

#: tesseract's TSV of a terminal line as it reads it: the underscore of /pressure_remote dropped.
TSV = '\n'.join([
    'level\tpage_num\tblock_num\tpar_num\tline_num\tword_num\tleft\ttop\twidth\theight\tconf\ttext',
    '1\t1\t0\t0\t0\t0\t0\t0\t900\t200\t-1\t',
    '5\t1\t1\t1\t1\t1\t20\t20\t120\t30\t96.1\trostopic',
    '5\t1\t1\t1\t1\t2\t160\t20\t60\t30\t95.0\techo',
    '5\t1\t1\t1\t1\t3\t240\t20\t130\t36\t91.2\t/pressure',
    '5\t1\t1\t1\t1\t4\t384\t20\t100\t30\t40.5\tremote',
    '5\t1\t1\t1\t2\t1\t20\t70\t90\t30\t93.0\tdata:',
    '5\t1\t1\t1\t2\t2\t130\t70\t150\t30\t88.0\t101349.66',
    '5\t1\t2\t1\t1\t1\t20\t150\t100\t30\t-1\t ',
])


def test_tesseract_words_are_read_with_their_place_and_confidence():
    words = report_text.parse_tsv(TSV)
    assert [w.text for w in words] == ['rostopic', 'echo', '/pressure', 'remote', 'data:', '101349.66']
    assert words[2].box == (240, 20, 130, 36) and words[3].confidence == 40.5
    assert report_text.words_text(words) == 'rostopic echo /pressure remote\ndata: 101349.66'


def test_words_apart_by_an_underscore_are_joined_and_spaces_are_kept():
    words = report_text.parse_tsv(TSV)
    joined = report_text.join_underscores(words, lambda a, b: a == (240, 20, 130, 36))
    assert report_text.words_text(joined) == 'rostopic echo /pressure_remote\ndata: 101349.66'
    assert joined[2].box == (240, 20, 244, 36) and joined[2].confidence == 40.5
    # a word tesseract ended with the underscore itself ("/pressure_ remote") is joined once
    trailing = [words[2]._replace(text='/pressure_'), words[3]]
    assert [w.text for w in report_text.join_underscores(trailing, lambda a, b: True)] == ['/pressure_remote']
    # never across lines
    assert len(report_text.join_underscores(words[3:5], lambda a, b: True)) == 2


def test_ocr_facts_give_the_mean_confidence_and_the_unsure_words_once():
    words = report_text.parse_tsv(TSV) + report_text.parse_tsv(TSV)
    facts = report_text.ocr_facts(words)
    assert facts == {'confidence': 84.0, 'unsure': ['remote']}
    assert report_text.ocr_facts([]) == {'confidence': None, 'unsure': []}


def test_more_unsure_words_than_the_cap_are_said_in_a_note():
    word = report_text.parse_tsv(TSV)[0]
    words = [word._replace(text='w%d' % n, confidence=10.0) for n in range(REPORT_UNSURE + 40)]
    notes = []
    facts = report_text.ocr_facts(words + words, 'page 2 of report.pdf', notes)
    assert facts['unsure'] == ['w%d' % n for n in range(REPORT_UNSURE)]
    assert notes == ['page 2 of report.pdf: %d words read by OCR with low confidence, the first %d listed'
                     % (REPORT_UNSURE + 40, REPORT_UNSURE)]
    notes = []
    report_text.ocr_facts(words[:REPORT_UNSURE], 'page 1 of a.pdf', notes)
    assert notes == []


def test_a_pictures_text_goes_where_the_picture_stands():
    lines = [{'text': 'Question 8', 'top': 100.0}, {'text': 'Les messages sont publiés à 0.778 Hz', 'top': 400.0},
             {'text': 'Question 9', 'top': 500.0}]
    text = report_text.merge_pictures(lines, [(480.0, 'catkin_create_pkg exam'), (150.0, 'average rate: 0.778')])
    assert text.split('\n') == ['Question 8', '[picture 1, OCR]', 'average rate: 0.778', '[end of picture 1]',
                                'Les messages sont publiés à 0.778 Hz', '[picture 2, OCR]', 'catkin_create_pkg exam',
                                '[end of picture 2]', 'Question 9']
    # a picture below the last line (or of no known place) comes last
    assert report_text.merge_pictures(lines[:1], [(900.0, 'x')]).endswith('[picture 1, OCR]\nx\n[end of picture 1]')


def test_a_region_is_read_from_the_picture_of_its_shape_only():
    pictures = [(760, 137, 'a.png'), (760, 270, 'b.png')]
    assert report_text.matching_picture((50, 100, 480, 177), pictures)[2] == 'a.png'     # 5.6 : 1
    assert report_text.matching_picture((50, 300, 480, 452), pictures)[2] == 'b.png'     # 2.8 : 1
    assert report_text.matching_picture((50, 300, 100, 450), pictures) is None           # a tall one: none
    assert report_text.matching_picture((0, 0, 10, 10), []) is None


def test_a_files_kind_is_read_from_its_bytes_not_its_name(tmp_path):
    (tmp_path / 'report.pdf').write_bytes(b'%PDF-1.6\n')
    (tmp_path / 'looks.pdf').write_bytes(b'\x89PNG\r\n\x1a\n....')
    (tmp_path / 'notes.rtf').write_bytes(b'{\\rtf1 hello}')
    with zipfile.ZipFile(str(tmp_path / 'rapport.zip'), 'w') as zf:  # an .odt is a zip with its mimetype
        zf.writestr('mimetype', 'application/vnd.oasis.opendocument.text')
        zf.writestr('content.xml', '<x/>')
    with zipfile.ZipFile(str(tmp_path / 'exam.zip'), 'w') as zf:
        zf.writestr('exam/package.xml', '<package/>')
    kinds = {name: report_files.kind_of(str(tmp_path / name)) for name in sorted(os.listdir(str(tmp_path)))}
    assert kinds == {'exam.zip': 'other', 'looks.pdf': 'image', 'notes.rtf': 'rtf', 'rapport.zip': 'odt',
                     'report.pdf': 'pdf'}
    assert report_files.kind_of(os.path.join(DATA, 'en_docx_table.docx')) == 'docx'
    assert report_files.kind_of(os.path.join(DATA, 'fr_odt.odt')) == 'odt'


def test_a_copys_name_is_safe_and_keeps_the_students_name():
    assert report_files.copy_name(0, 'Jeanne Martin_12_assignsubmission_file_rapport.pdf') == \
        '1-Jeanne Martin_12_assignsubmission_file_rapport.pdf'
    assert report_files.copy_name(2, 'exam.zip/exam/../é$(rm).pdf') == '3-___rm_.pdf'
    assert report_files.copy_name(1, '...') == '2-report'


def test_reports_are_found_in_the_folder_and_in_its_archives_the_same_bytes_once(tmp_path):
    pdf = open(os.path.join(DATA, 'fr_odt.pdf'), 'rb').read()
    folder = tmp_path / 'Jeanne Martin_12_assignsubmission_file_'
    folder.mkdir()
    (folder / 'rapport.pdf').write_bytes(pdf)
    (folder / 'capture.png').write_bytes(b'\x89PNG\r\n\x1a\n')
    with zipfile.ZipFile(str(folder / 'exam.zip'), 'w') as zf:
        zf.writestr('exam/package.xml', '<package/>')
        zf.writestr('exam/rapport.pdf', pdf)                       # the same report, inside the package
        zf.writestr('exam/doc/annexe.docx', open(os.path.join(DATA, 'en_docx_table.docx'), 'rb').read())
        zf.writestr('exam/doc/figure.png', b'\x89PNG\r\n\x1a\n')  # a picture of the package: not a report
    notes = []
    found = report_files.find_reports(str(folder), str(tmp_path / 'scratch'), notes)
    assert [name for name, _ in found] == ['capture.png', 'rapport.pdf', 'exam.zip/exam/doc/annexe.docx']
    assert notes == ["'exam.zip/exam/rapport.pdf': the same file as 'rapport.pdf', read once"]
    alone = report_files.find_reports(str(folder / 'rapport.pdf'), str(tmp_path / 'scratch2'), [])
    assert [name for name, _ in alone] == ['rapport.pdf']


def _page(**changes):
    return dict({'file': 0, 'number': 1, 'source': 'text', 'text': 'x', 'layout': 'x', 'confidence': None,
                 'unsure': [], 'pictures': 0, 'image': 'report/page-1-1.png'}, **changes)


def _record(**changes):
    return dict({'version': 1, 'state': 'read', 'why': '', 'notes': [], 'seconds': 1.0, 'pages': [_page()],
                 'files': [{'name': 'r.pdf', 'kind': 'pdf', 'converted': False, 'pages': 1, 'note': '',
                            'state': 'read', 'copy': 'report/1-r.pdf'}]}, **changes)


def test_the_report_record_is_checked_across_its_fields():
    assert ReportRecord.make(_record()).pages[0].text == 'x'
    assert ReportRecord.not_read('report.pdf: an encrypted PDF').state == 'not read'
    for bad, why in ((_record(state='not read'), 'state not read with 1 page'),
                     (_record(why='encrypted'), 'state read with a why'),
                     (_record(pages=[], state='not read'), 'state not read without a why'),
                     (_record(pages=[_page(file=1)]), 'pages[0].file: 1 of 1 file'),
                     (_record(pages=[_page(image='../../etc/passwd')]), 'is not a file of report/'),
                     (_record(pages=[_page(image='report/sub/page.png')]), 'is not a file of report/'),
                     (_record(pages=[_page(source='guess')]), 'is not one of text, ocr')):
        with pytest.raises(RecordError, match=re.escape(why)):
            ReportRecord.make(bad)


def test_the_records_text_is_cleaned_of_escape_sequences():
    record = ReportRecord.make(_record(pages=[_page(text='rate: 0.778\x1b[2J\x1b]0;owned\x07 Hz')]))
    assert record.pages[0].text == 'rate: 0.778 Hz'


def test_a_kept_report_is_read_back_checked_or_said_not_read(tmp_path):
    assert proposals.kept_report(str(tmp_path)).why.startswith('no report.json kept')
    (tmp_path / 'report.json').write_text(ReportRecord.make(_record()).to_json())
    assert proposals.kept_report(str(tmp_path)).state == 'read'
    (tmp_path / 'report.json').write_text('{"version": 1, "state": "read"}')
    kept = proposals.kept_report(str(tmp_path))
    assert kept.state == 'not read' and 'not a record of the grader' in kept.why
    # Read through the contract: a link to a good record is not followed, a FIFO is not waited on.
    good = tmp_path / 'good.json'
    good.write_text(ReportRecord.make(_record()).to_json())
    for plant in ('link', 'fifo'):
        (tmp_path / 'report.json').unlink()
        if plant == 'link':
            (tmp_path / 'report.json').symlink_to(good)
        else:
            os.mkfifo(str(tmp_path / 'report.json'))
        kept = proposals.kept_report(str(tmp_path))
        assert kept.state == 'not read' and 'not a record of the grader' in kept.why, (plant, kept.why)


def test_an_underscore_is_told_from_a_space_by_its_ink():
    image_module = pytest.importorskip('PIL.Image')
    from PIL import ImageDraw
    from exam_lab.grader.boxed import report_images
    image = image_module.new('L', (400, 60), 255)
    draw = ImageDraw.Draw(image)
    draw.rectangle([10, 10, 100, 40], fill=0)      # "pressure"
    draw.rectangle([130, 10, 220, 40], fill=0)     # "remote"
    draw.rectangle([100, 41, 130, 43], fill=0)     # the underscore between them
    draw.rectangle([250, 10, 340, 40], fill=0)     # a word after a space
    assert report_images.underscore_between(image, (10, 10, 91, 31), (130, 10, 91, 31))
    assert not report_images.underscore_between(image, (130, 10, 91, 31), (250, 10, 91, 31))


def test_a_pictures_place_is_the_ink_no_word_explains():
    image_module = pytest.importorskip('PIL.Image')
    from PIL import ImageDraw
    from exam_lab.grader.boxed import report_images
    # a page of 600 x 800 points drawn at 1 pixel a point: a line of text, a dark screenshot, a rule
    page = image_module.new('L', (600, 800), 255)
    draw = ImageDraw.Draw(page)
    draw.rectangle([50, 50, 400, 62], fill=0)       # the text layer's line
    draw.rectangle([50, 200, 500, 300], fill=40)    # the screenshot
    draw.line([50, 500, 550, 500], fill=0)           # a rule: thin, not a picture
    regions = report_images.picture_regions(page, [(50, 50, 400, 62)], 600)
    assert len(regions) == 1
    x0, y0, x1, y1 = regions[0]
    assert 40 <= x0 <= 50 and 190 <= y0 <= 200 and 500 <= x1 <= 515 and 300 <= y1 <= 315, regions


def test_libreoffices_profile_is_made_with_its_version_and_build(tmp_path):
    office = tmp_path / 'libreoffice'
    (office / 'share' / 'registry').mkdir(parents=True)
    (office / 'program').mkdir()
    (office / 'share' / 'registry' / 'main.xcd').write_text(
        '<node oor:name="Product">\n<prop oor:name="ooSetupVersion">\n        <value>7.4</value>\n      </prop>\n'
        '<prop oor:name="ooSetupVersionAboutBox">\n        <value>7.4.7.2</value></prop></node>')
    (office / 'program' / 'versionrc').write_text('[Version]\nAllLanguages=en-US\nbuildid=40(Build:2)\nVendor=Debian\n')
    report_reader.office_profile(str(tmp_path / 'profile'), str(office))
    user = tmp_path / 'profile' / 'user'
    settings = (user / 'registrymodifications.xcu').read_text()
    assert '<prop oor:name="ooSetupInstCompleted" oor:op="fuse"><value>true</value></prop>' in settings
    assert '<prop oor:name="ooSetupLastVersion" oor:op="fuse"><value>7.4</value></prop>' in settings
    assert (user / 'extensions' / 'buildid').read_text() == '40(Build:2)'
    # an installation whose version and build cannot be read: LibreOffice does the rest itself
    report_reader.office_profile(str(tmp_path / 'other'), str(tmp_path / 'nowhere'))
    assert 'ooSetupLastVersion' not in (tmp_path / 'other' / 'user' / 'registrymodifications.xcu').read_text()
    assert os.listdir(str(tmp_path / 'other' / 'user' / 'extensions')) == []

"""The Moodle worksheet round trip: a worksheet as Moodle writes it, filled, read back with Python's
csv module under the rules of Moodle's importer (BOM dropped, every row as wide as the header, the
participant number after Moodle's word), every row checked."""
import csv
import io

import pytest

from exam_lab.grader.publish import moodle
from exam_lab.grader.score.sheets import ITEMS

HEADER = ['Identifier', 'Full name', 'Email address', 'Status', 'Grade', 'Maximum grade',
          'Grade can be changed', 'Last modified (submission)', 'Online text', 'Last modified (grade)',
          'Feedback comments']
#: Rows as Moodle's writer quotes them (spaces, commas, line breaks, quotes), CRLF line ends.
WORKSHEET = '\ufeff' + '\r\n'.join([
    ','.join(HEADER),
    '"Participant 101","Jane Doe",jane@example.org,"Submitted for grading",,17.00,Yes,'
    '"Monday, 3 March 2025, 10:12 AM","a ""quoted""\nline",-,',
    '"Participant 102","Paul Martin",paul@example.org,"Submitted for grading",,17.00,Yes,'
    '"Monday, 3 March 2025, 10:13 AM",,-,',
    '"Participant 103","Ada Lovelace",ada@example.org,"Submitted for grading",12.00,17.00,Yes,'
    '"Monday, 3 March 2025, 10:14 AM",,"Monday, 3 March 2025, 11:00 AM","<p>seen by hand</p>"',
    '"Participant 104","Alan Turing",alan@example.org,"No submission",,17.00,Yes,-,,-,',
    '"Participant 105","Grace Hopper",grace@example.org,"Submitted for grading",,17.00,Yes,'
    '"Monday, 3 March 2025, 10:15 AM",,-,',
]) + '\r\n'


def record(student, participant, points, status='graded'):
    items = []
    for item, (top, _) in ITEMS.items():
        got = top if item != 'Q11' else points - (sum(t for t, _ in ITEMS.values()) - top)
        items.append({'id': item, 'points': got, 'max': top,
                      'evidence': 'values: 3 of 3 disagree, "in degC"\nmore' if got < top else 'ok'})
    return {'student': student, 'participant': participant, 'total': points, 'max': 17.0, 'items': items,
            'status': status, 'status_reason': 'the node crashed' if status != 'graded' else ''}


RECORDS = [record('Jane Doe', 101, 17.0), record('Paul Martin', 102, 15.5), record('Ada Lovelace', 103, 17.0),
           record('Grace Hopper', 105, 14.0, status='needs a hand grade'), record('Bob NoNumber', None, 10.0),
           record('Eve Elsewhere', 999, 16.0)]


def moodle_read(text):
    """Moodle's importer with Python's csv module: BOM dropped, line ends normalised, empty lines
    skipped, every row as wide as the header, columns found by their header."""
    assert text.startswith('\ufeff')
    text = text[1:].replace('\r\n', '\n').replace('\r', '\n').strip()
    rows = [row for row in csv.reader(io.StringIO(text)) if row != []]
    header = rows[0]
    for row in rows[1:]:
        assert len(row) == len(header), row
    return header, rows[1:]


def test_participant_number_from_moodle_names():
    assert moodle.participant_number('Jane Doe_1234567_assignsubmission_file_') == 1234567
    assert moodle.participant_number('Jane_Doe_12_assignsubmission_file_exam.zip') == 12
    assert moodle.participant_number('Participant_88_assignsubmission_file') == 88
    assert moodle.participant_number('jdupont') is None
    assert moodle.participant_number('Jane Doe_12') is None


def test_parse_gives_the_text_back_exactly():
    for text in (WORKSHEET[1:], 'a,b\n"x,""y"""\n', 'a,\n,\n', 'a\r\n\r\nb', 'a,"b\r\nc"', ''):
        assert moodle.unparse(moodle.parse(text)) == text


def test_quoted_is_read_back_by_csv():
    for value in ('15,5', 'a "b"', 'two\nlines', 'plain', '<p>x y</p>', ' '):
        assert next(csv.reader(io.StringIO(moodle.quoted(value)))) == [value]


def test_filled_worksheet_reads_back_row_by_row():
    filled, summary = moodle.fill(WORKSHEET, RECORDS)
    header, rows = moodle_read(filled)
    original_header, original = moodle_read(WORKSHEET)
    assert header == original_header
    assert len(rows) == len(original)
    grade, comments = header.index('Grade'), header.index('Feedback comments')
    by_id = {row[0][len('Participant '):]: (row, before) for row, before in zip(rows, original)}
    for number, (row, before) in by_id.items():
        for column, (cell, old) in enumerate(zip(row, before)):
            if column not in (grade, comments):
                assert cell == old, (number, header[column])
    jane, paul = by_id['101'][0], by_id['102'][0]
    assert jane[grade] == '17' and paul[grade] == '15.5'
    assert paul[comments].startswith('<p>Machine-graded by running the package: 15.5 / 17 points')
    for item in ITEMS:
        assert '<li>%s ' % item in paul[comments]
    assert '<li>Q11 2.5/4: values: 3 of 3 disagree, &quot;in degC&quot;</li>' in paul[comments]
    assert 'more' not in paul[comments]  # the evidence's first line only
    assert by_id['103'][0][grade] == '12.00' and by_id['103'][0][comments] == '<p>seen by hand</p>'
    for untouched in ('103', '104', '105'):
        assert by_id[untouched][0] == by_id[untouched][1]
    assert [g[:2] for g in summary['graded']] == [('Jane Doe', 101), ('Paul Martin', 102)]
    assert sorted(s for s, _ in summary['kept']) == ['Ada Lovelace', 'Grace Hopper']
    assert sorted(s for s, _ in summary['unmatched']) == ['Bob NoNumber', 'Eve Elsewhere']
    assert summary['no_submission'] == ['Alan Turing']


def test_every_byte_outside_the_filled_cells_is_kept():
    filled, _ = moodle.fill(WORKSHEET, RECORDS)
    before, after = WORKSHEET.split('\r\n'), filled.split('\r\n')
    assert before[0] == after[0]
    for line in (3, 4, 5):  # Ada (graded by hand), Alan (no submission), Grace (needs a hand grade)
        assert before[line] == after[line]
    assert after[1].startswith('"Participant 101","Jane Doe",jane@example.org,"Submitted for grading",17,17.00,')
    assert filled.endswith('\r\n')


def test_decimal_comma_follows_the_worksheet():
    text = WORKSHEET.replace('17.00', '"17,00"').replace('12.00', '"12,00"')
    filled, _ = moodle.fill(text, RECORDS)
    _, rows = moodle_read(filled)
    assert rows[1][4] == '15,5'


def test_a_malformed_worksheet_is_refused():
    with pytest.raises(moodle.WorksheetError, match='no grade column'):
        moodle.fill('\ufeffIdentifier,Full name,Feedback comments\n"Participant 1",A,\n', RECORDS)
    with pytest.raises(moodle.WorksheetError, match='fields, the header'):
        moodle.fill('\ufeff' + ','.join(HEADER) + '\n"Participant 101",x\n', RECORDS)
    with pytest.raises(moodle.WorksheetError, match='never ends'):
        moodle.parse('a,"b\n')


def test_the_identifier_column_in_another_language_is_found_by_its_cells():
    text = WORKSHEET.replace('Identifier', 'Kennung').replace('"Participant ', '"Teilnehmer/in ')
    _, summary = moodle.fill(text, RECORDS)
    assert [g[:2] for g in summary['graded']] == [('Jane Doe', 101), ('Paul Martin', 102)]
    with pytest.raises(moodle.WorksheetError, match='switch it to English'):
        moodle.fill(WORKSHEET.replace('Grade,', 'Bewertungxyz,', 1), RECORDS)


def test_points_above_the_maximum_are_not_written():
    text = WORKSHEET.replace('17.00', '10.00')
    _, summary = moodle.fill(text, RECORDS)
    assert summary['graded'] == []
    assert any('exceed the maximum' in why for _, why in summary['kept'])


def test_fill_file_and_summary(tmp_path):
    source, target = tmp_path / 'worksheet.csv', tmp_path / 'filled.csv'
    source.write_bytes(WORKSHEET.encode('utf-8'))
    summary = moodle.fill_file(str(source), str(target), RECORDS)
    assert target.read_bytes().startswith(b'\xef\xbb\xbf')
    lines = moodle.summary_lines(summary, str(target))
    assert '2 grade(s) written' in lines[0]
    assert any('NOT MATCHED: Eve Elsewhere' in line for line in lines)

"""The Moodle worksheet round trip: a worksheet as Moodle writes it, filled, read back with Python's
csv module under the rules of Moodle's importer (BOM dropped, every row as wide as the header, the
participant number after Moodle's word), every row checked."""
import csv
import io

import pytest

from exam_lab.grader.publish import cells, hand, moodle
from exam_lab.grader.score import identity
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS

#: The header line of a real worksheet, exactly as Moodle wrote it in English (quoting included):
#: copied from a public grading script that quotes a downloaded worksheet's first line in a comment
#: (found with the search tools; its repository is not named there). Its columns are those of
#: mod/assign/gradingtable.php in download mode (moodle/moodle at 003699db) for an assignment
#: with groups, file submissions (no column: no editor field) and feedback comments, each headed by
#: the English string of mod/assign/lang/en/assign.php ('Maximum Grade': the later of its two
#: 'maxgrade' lines, which PHP keeps), lang/en/moodle.php and assignfeedback_comments.
HEADER_LINE = ('Identifier,"Full name","Email address",Status,Group,Grade,"Maximum Grade","Grade can be changed",'
               '"Last modified (submission)","Last modified (grade)","Feedback comments"')
HEADER = next(csv.reader([HEADER_LINE]))
#: Rows as Moodle's writer quotes them (spaces, commas, line breaks, quotes), CRLF line ends; the
#: assignment's maximum grade 30, the sheets' points (the grades written are the whole grades as they are).
WORKSHEET = '\ufeff' + '\r\n'.join([
    HEADER_LINE,
    '"Participant 101","Jane Doe",jane@example.org,"Submitted for grading","Team ""A"", the\nmorning",,30.00,Yes,'
    '"Monday, 3 March 2025, 10:12 AM",-,',
    '"Participant 102","Paul Martin",paul@example.org,"Submitted for grading","Default group",,30.00,Yes,'
    '"Monday, 3 March 2025, 10:13 AM",-,',
    '"Participant 103","Ada Lovelace",ada@example.org,"Submitted for grading","Default group",12.00,30.00,Yes,'
    '"Monday, 3 March 2025, 10:14 AM","Monday, 3 March 2025, 11:00 AM","<p>seen by hand</p>"',
    '"Participant 104","Alan Turing",alan@example.org,"No submission","Default group",,30.00,Yes,-,-,',
    '"Participant 105","Grace Hopper",grace@example.org,"Submitted for grading","Default group",,30.00,Yes,'
    '"Monday, 3 March 2025, 10:15 AM",-,',
]) + '\r\n'


def machine_record(student, participant, points, status='graded'):
    items = []
    for item, (top, _) in ITEMS.items():
        got = top if item != 'Q11' else points - (sum(t for t, _ in ITEMS.values()) - top)
        items.append({'id': item, 'points': got, 'max': top,
                      'evidence': 'values: 3 of 3 disagree, "in degC"\nmore' if got < top else 'ok'})
    return {'student': student, 'participant': participant, 'total': points, 'max': 17.0, 'items': items,
            'status': status, 'status_reason': 'the node crashed' if status != 'graded' else ''}


def record(student, participant, points, status='graded'):
    """The whole grade make worksheet fills with: the machine's ``points`` and every hand point given."""
    return hand.combine(machine_record(student, participant, points, status),
                        hand.Hand(student, {item: top for item, (top, _) in HAND_ITEMS.items()}, '', participant))


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
    assert identity.participant_number('Jane Doe_1234567_assignsubmission_file_') == 1234567
    assert identity.participant_number('Jane_Doe_12_assignsubmission_file_exam.zip') == 12
    assert identity.participant_number('Participant_88_assignsubmission_file') == 88
    assert identity.participant_number('jdupont') is None
    assert identity.participant_number('Jane Doe_12') is None


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
    assert jane[grade] == '30' and paul[grade] == '28.5'
    assert paul[comments].startswith('<p>28.5 / 30 points: 15.5 of 17 by the machine')
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
    assert after[1].startswith('"Participant 101","Jane Doe",jane@example.org,"Submitted for grading","Team ""A"", '
                               'the\nmorning",30,30.00,')
    assert filled.endswith('\r\n')


def test_decimal_comma_follows_the_worksheet():
    text = WORKSHEET.replace('30.00', '"30,00"').replace('12.00', '"12,00"')
    filled, _ = moodle.fill(text, RECORDS)
    header, rows = moodle_read(filled)
    assert rows[1][header.index('Grade')] == '28,5'


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
    """Scaled, a grade exceeds the maximum only when its points exceed their own maximum: never written."""
    _, summary = moodle.fill(WORKSHEET, [dict(RECORDS[0], total=31.0)])
    assert summary['graded'] == []
    assert any('exceed the maximum' in why for _, why in summary['kept'])


def test_only_whole_grades_are_written():
    """The machine's 17 points alone, or a whole grade with a hand point missing, are no grade: the
    row stays as downloaded, its feedback cell too (Moodle imports a feedback cell even with no grade:
    process_import_grades in mod/assign/feedback/offline/locallib.php), and the summary says why."""
    missing = hand.combine(machine_record('Paul Martin', 102, 15.5), hand.Hand('Paul Martin', {'Q4': 1.0}, '', 102))
    filled, summary = moodle.fill(WORKSHEET, [machine_record('Jane Doe', 101, 17.0), missing])
    assert filled == WORKSHEET and summary['graded'] == []
    why = dict(summary['kept'])
    assert why['Jane Doe'].startswith("only the machine's 17 points, not a grade") and \
        why['Paul Martin'].startswith('hand points not given yet in hand.csv: Q5, Q6')


def test_a_report_only_student_is_hand_gradable():
    """A student who handed in a report only (refused before anything ran: 0 by the machine) gets her
    hand points as her grade; a student the grader failed on does not (0 would not be measured)."""
    refused = record('Paul Martin', 102, 0.0, status='not graded')
    refused['status_reason'] = 'submission refused: no catkin package (package.xml) in report.pdf'
    failed = dict(record('Jane Doe', 101, 0.0, status='not graded'), status_reason='the grader failed on this submission')
    filled, summary = moodle.fill(WORKSHEET, [refused, failed])
    assert summary['graded'] == [('Paul Martin', 102, '13')]
    assert 'nothing of the package ran: submission refused: no catkin package' in filled
    assert dict(summary['kept'])['Jane Doe'].startswith('status "not graded"')


def test_the_teachers_remark_is_a_paragraph_of_its_own():
    """Never spliced into the grade's sentence (issue 49: "...code quality). relu le 1 The grade is")."""
    whole = dict(record('Jane Doe', 101, 17.0), remark='relu le 1')
    text = moodle.feedback(whole, maximum=20.0)
    assert "code quality). The grade is these points scaled to 20 (x 20/30).</p><p>The teacher&#x27;s remark: " \
        "relu le 1</p><ul>" in text


def test_fill_file_and_summary(tmp_path):
    source, target = tmp_path / 'worksheet.csv', tmp_path / 'filled.csv'
    source.write_bytes(WORKSHEET.encode('utf-8'))
    summary = moodle.fill_file(str(source), str(target), RECORDS)
    assert target.read_bytes().startswith(b'\xef\xbb\xbf')
    lines = moodle.summary_lines(summary, str(target))
    assert '2 whole grade(s)' in lines[0] and 'upload it in Moodle' in lines[0]
    assert any('NOT MATCHED: Eve Elsewhere' in line for line in lines)


#: The same worksheet as Moodle writes it in French, German and Spanish, each header the string of that
#: language's pack (Moodle 4.5 packs from AMOS, as kept in projectestac/moodle-langpacks at 6340d351:
#: <lang>/assign.php recordid, maxgrade, gradecanbechanged, lastmodifiedsubmission, lastmodifiedgrade;
#: <lang>/moodle.php fullname, email, status, gradenoun; <lang>/assignfeedback_comments.php pluginname),
#: copied here by hand from those files, apart from the module's table, so a slip in either shows.
#: English twice: as PHP reads mod/assign/lang/en/assign.php ('Maximum Grade') and as AMOS's pack
#: has it ('Maximum grade').
LANGUAGES = {
    'en': HEADER_LINE.replace(',Group', ''),
    'en AMOS': HEADER_LINE.replace(',Group', '').replace('Maximum Grade', 'Maximum grade'),
    'fr': 'Identifiant,"Nom complet","Adresse de courriel",Statut,Note,"Note maximale","La note peut être modifiée",'
          '"Dernière modification (travail remis)","Dernière modification (note)","Feedback par commentaires"',
    'de': 'ID,"Vollständiger Name",E-Mail-Adresse,Status,Bewertung,Bestwertung,"Bewertung kann geändert werden",'
          '"Zuletzt geändert (Abgabe)","Zuletzt geändert (Bewertung)","Feedback als Kommentar"',
    'es': 'Identificador,"Nombre completo","Dirección de correo",Estado,Calificación,"Calificación máxima",'
          '"La calificación puede ser cambiada","Última modificación (entrega)","Última modificación (calificación)",'
          '"Comentarios de retroalimentación"',
    'en lower case': HEADER_LINE.replace(',Group', '').lower(),
}
WORD = {'en': 'Participant', 'en AMOS': 'Participant', 'fr': 'Participant', 'de': 'Teilnehmer/in',
        'es': 'Participante', 'en lower case': 'Participant'}


@pytest.mark.parametrize('language', sorted(LANGUAGES))
def test_moodles_own_headers_in_each_language_and_any_case(language):
    """The maximum grade column is found whatever its language or case: with the worksheet out of 20,
    the whole grade 28.5 of 30 is scaled to 19."""
    text = '\ufeff' + '\r\n'.join([
        LANGUAGES[language],
        '"%s 102","Paul Martin",paul@example.org,"-",,20.00,Yes,-,-,' % WORD[language],
    ]) + '\r\n'
    filled, summary = moodle.fill(text, [record('Paul Martin', 102, 15.5)])
    assert summary['graded'] == [('Paul Martin', 102, '19')]
    assert summary['maxima'] == [20.0]
    header, rows = moodle_read(filled)
    assert rows[0][4] == '19' and rows[0][9].startswith('<p>')


def test_a_worksheet_whose_maximum_grade_is_not_recognised_stops():
    """Never a total out of 17 (or 30) into a column out of 20 without a word: a maximum grade column
    not recognised stops the filling, naming what was looked for; a scale says so."""
    for other in ('Max. grade', 'Maximum points'):
        text = WORKSHEET.replace('"Maximum Grade"', '"%s"' % other, 1)
        with pytest.raises(moodle.WorksheetError, match="no maximum grade column .*'Maximum Grade'"):
            moodle.fill(text, RECORDS)
    with pytest.raises(moodle.WorksheetError, match='graded on a scale'):
        moodle.fill(WORKSHEET.replace('"Maximum Grade"', 'Scale', 1), RECORDS)
    with pytest.raises(moodle.WorksheetError, match='no last modified'):
        moodle.fill(WORKSHEET.replace('"Last modified (grade)"', 'Modified', 1), RECORDS)


def test_a_row_whose_maximum_is_no_number_is_left_with_why():
    text = WORKSHEET.replace('"Default group",,30.00', '"Default group",,', 1)  # Paul's row
    _, summary = moodle.fill(text, RECORDS)
    assert ('Paul Martin', "its maximum grade '' is not a number above 0") in summary['kept']
    assert [g[0] for g in summary['graded']] == ['Jane Doe']


def test_cells_a_student_chose_cannot_run_in_a_spreadsheet():
    """OWASP's rule on the filled copy: a name, an email, a group beginning with = + - @ tab or CR
    begins with a quote; Moodle's own "-" and the columns its importer reads are as they were."""
    hostile = {'Full name': '=HYPERLINK("http://x","y")', 'Email address': '@SUM(1+1)', 'Group': '-2+3'}
    text = WORKSHEET.replace('"Jane Doe",jane@example.org', '"=HYPERLINK(""http://x"",""y"")",@SUM(1+1)', 1)
    text = text.replace('"Team ""A"", the\nmorning"', '-2+3', 1)
    text = text.replace('"Paul Martin"', '"\tPaul"', 1).replace('"Ada Lovelace"', '"\'t Hooft"', 1)
    filled, summary = moodle.fill(text, RECORDS)
    header, rows = moodle_read(filled)
    jane = rows[0]
    for column, value in hostile.items():
        assert jane[header.index(column)] == "'" + value
        assert cells.read_cell(jane[header.index(column)]) == value
    assert rows[1][1] == "'\tPaul" and rows[2][1] == "''t Hooft"
    assert jane[header.index('Grade')] == '30' and jane[header.index('Last modified (grade)')] == '-'
    assert rows[3][header.index('Last modified (submission)')] == '-'
    assert [g[1] for g in summary['graded']] == [101, 102]


def test_a_participant_two_records_claim_is_written_for_neither():
    """Two folders of OUT with one participant (a stale folder, a renamed student): the row is not
    guessed."""
    records = RECORDS + [record('Jane Doe_2', 101, 3.0)]
    filled, summary = moodle.fill(WORKSHEET, records)
    _, rows = moodle_read(filled)
    assert rows[0][5] == ''
    assert sorted(s for s, why in summary['unmatched'] if 'participant 101 is also' in why) == ['Jane Doe', 'Jane Doe_2']


def test_identity_gives_the_participant_and_moodles_folder():
    jane = dict(record('Jane Doe', 1234567, 17.0), folder='Jane Doe_1234567_assignsubmission_file_')
    assert identity.identity(jane) == (1234567, 'Jane Doe_1234567_assignsubmission_file_', ('participant', 1234567))
    flat = dict(jane, folder='Jane Doe_1234567_assignsubmission_file_exam.zip')
    assert identity.identity(flat).folder == 'Jane Doe_1234567_assignsubmission_file_'
    plain = dict(record('jdupont', None, 17.0), folder='jdupont')
    assert identity.identity(plain) == (None, None, ('name', 'jdupont'))
    from_folder = dict(record('Jane Doe', None, 17.0), folder='Jane Doe._88_assignsubmission_file_')
    assert identity.identity(from_folder) == (88, 'Jane Doe._88_assignsubmission_file_', ('participant', 88))

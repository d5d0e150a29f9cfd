"""Grades back into Moodle: the assignment's offline grading worksheet, filled. No rospy here.

The layout is Moodle's own (``mod/assign/gradingtable.php`` in download mode, written by
``dataformat/csv``; read back by ``mod/assign/feedback/offline/importgradeslib.php`` through
``lib/csvlib.class.php``), see docs/grading.md:

- UTF-8, usually with a byte order mark; comma-separated, ``"`` encloses a field holding a comma, a
  quote (doubled), a line break or a space; one header row, then one row per participant.
- The importer finds its columns by their header, in the teacher's language: the identifier
  (``Identifier``, values ``Participant 1234567``; the number after the word is the participant's
  unique id, the same number as in the "download all submissions" folder ``Jane Doe_1234567_
  assignsubmission_file_``: :mod:`~exam_lab.grader.score.identity`), ``Grade``, ``Last modified
  (grade)`` and each feedback plugin's field (``Feedback comments``). It needs every row to have as
  many fields as the header; it skips a grade that is empty, negative, above the maximum or equal to
  the one it has, and any row whose grade was changed in Moodle after the worksheet was downloaded.

So the filled copy changes only the grade and the feedback cells of the rows it matched, byte for byte
everything else (the mark, the quoting of every other cell, the line ends), and leaves a grade or a
feedback already in the worksheet as it was (a teacher's grade wins over the machine's).

One file is for Moodle: :data:`UPLOAD` in OUT, written only with whole grades (the machine's points
and the teacher's hand points of ``hand.csv``, scaled to the worksheet's maximum grade). A student
whose hand points are not all given is left blank there: the importer skips an empty grade
(``process_import_grades`` in ``mod/assign/feedback/offline/locallib.php``), and since it imports a
feedback cell even then, that cell is left as downloaded too. The machine's 17 points alone are never
written into a grade column.
"""
import html
import os
import re

from exam_lab.grader import contract
from exam_lab.grader.publish import cells, student_view
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.sheets import ITEMS

#: A cell of the identifier column: Moodle's word for participant (any language), then the number.
_IDENTIFIER = re.compile(r'^\D*?(\d+)$')
#: Moodle's own headers of the worksheet, as ``get_string`` gives them in each language (matched
#: case-insensitively: Moodle's English ``maxgrade`` is defined twice in
#: ``mod/assign/lang/en/assign.php``, ``'Maximum grade'`` then ``'Maximum Grade'``, and PHP keeps the
#: later one, while AMOS's English pack has the first). Which string heads which column:
#: ``mod/assign/gradingtable.php`` (download mode): ``recordid`` (assign), ``fullname`` (core),
#: ``grade``/``gradenoun`` (core), ``maxgrade`` or ``scale`` (assign), ``lastmodifiedgrade`` (assign),
#: each feedback plugin's editor field: ``pluginname`` of ``assignfeedback_comments``. The importer
#: (``mod/assign/feedback/offline/importgradeslib.php``) finds the identifier, grade, last-modified
#: and feedback columns by the same strings, exactly.
#: Sources: en: moodle/moodle at 0085741f (mod/assign/lang/en/assign.php) and 7fceae55
#: (mod/assign/feedback/comments/lang/en/assignfeedback_comments.php); fr, de, es, it, nl: Moodle's
#: language packs from AMOS as kept in projectestac/moodle-langpacks at 6340d351 (2026-06-18, packs of
#: Moodle 4.5: <lang>/assign.php, <lang>/moodle.php, <lang>/assignfeedback_comments.php; the same
#: strings in its packs of 3.8, 3.11, 4.1 and 4.4). Only English has two spellings of one string.
HEADERS = {
    'identifier': ('Identifier', 'Identifiant', 'ID', 'Identificador', 'Identificativo', 'Identificatie'),
    'name': ('Full name', 'Nom complet', 'Vollständiger Name', 'Nombre completo', 'Nome', 'Volledige naam'),
    'grade': ('Grade', 'Note', 'Bewertung', 'Calificación', 'Valutazione', 'Cijfer'),
    'maximum': ('Maximum Grade', 'Maximum grade', 'Note maximale', 'Bestwertung', 'Calificación máxima',
                'Valutazione massima', 'Maximaal cijfer'),
    'scale': ('Scale', 'Barème', 'Skala', 'Escala', 'Scala', 'Schaal'),
    'modified': ('Last modified (grade)', 'Dernière modification (note)', 'Zuletzt geändert (Bewertung)',
                 'Última modificación (calificación)', 'Ultima modifica (valutazione)',
                 'Laatst gewijzigd (beoordeling)'),
    'feedback': ('Feedback comments', 'Feedback par commentaires', 'Feedback als Kommentar',
                 'Comentarios de retroalimentación', 'Commenti', 'Feedback tekstvak'),
}
#: Statuses whose points go into the grade column (the others wait for the teacher).
GRADED = ('graded', 'graded with fixes')
#: The start of the status reason of a submission refused before anything ran (no package in it, a
#: report only, an archive refused): the machine's points are 0, measured as such, and the teacher's
#: hand points (the report's questions) make its grade all the same.
REFUSED = 'submission refused'
#: The file to upload into Moodle (Grading action: Upload grading worksheet), in OUT.
UPLOAD = 'moodle-worksheet.csv'
#: Moodle's worksheet as the teacher downloaded it, kept in OUT: what make worksheet and make rescore
#: fill again without WORKSHEET= (blank: importing it changes nothing).
DOWNLOADED = 'worksheet-as-downloaded.csv'
_BOM = '\ufeff'


class WorksheetError(Exception):
    """The file is not a worksheet this module can fill without changing what it must not."""


#: Moodle's "download all submissions" zip: ``<course short name>-<assignment name>-<module id>.zip``
#: (``download_submissions()`` in ``mod/assign/locallib.php``).
_CLASS_ZIP = re.compile(r'^(.+?)-\d+$')
_ENDINGS = ('.zip', '.tar.gz', '.tgz', '.tar')


def _stem(path):
    """``(file name without its archive ending, whether it had one)``."""
    name = path.rstrip('/\\').replace('\\', '/').split('/')[-1]
    for ending in _ENDINGS:
        if name.lower().endswith(ending):
            return name[:-len(ending)], True
    return name, False


def class_name(path):
    """The class's name for the page's title: Moodle's zip gives the course and the assignment
    (``ROS-Exam altitude-1234.zip`` gives ``ROS-Exam altitude``), a folder its own name."""
    name, archive = _stem(path)
    match = _CLASS_ZIP.match(name) if archive else None
    return match.group(1) if match else name


def out_name(path):
    """The default output folder's name for a class or a submission at ``path``: its name without the
    archive ending, each run of characters a shell would need quoted (spaces, parentheses, quotes;
    letters of any language stay) one ``_``: ``ROS-2026-Exam submarinedrone (groupe D)-915302.zip`` gives
    ``ROS-2026-Exam_submarinedrone_groupe_D-915302``, pasted as it is in any later ``OUT=``."""
    name = re.sub(r'[^\w.-]+', '_', _stem(path)[0]).strip('_.')
    return re.sub(r'_?-_?', '-', name) or 'grades'


def shell_quoted(value):
    """``value`` in double quotes as bash reads it back (``OUT="..."``): ``"``, ``$``, `````, ``\\``
    escaped."""
    return '"%s"' % re.sub(r'(["$`\\])', r'\\\1', value)


def parse(text):
    """Split CSV text into records, keeping the raw text of every field.

    :returns: ``[(fields, end)]``: ``fields`` a list of ``[raw, value]``, ``end`` the record's line end
        as written (``'\\n'``, ``'\\r\\n'``, ``'\\r'`` or ``''`` for the last one). Joining the raw
        fields with commas and the ends gives ``text`` back exactly.
    """
    records, fields, i, n = [], [], 0, len(text)
    while i < n or fields:
        start = i
        if i < n and text[i] == '"':
            i += 1
            value = []
            while True:
                if i >= n:
                    raise WorksheetError('a quoted field never ends (from character %d)' % start)
                if text[i] == '"':
                    if i + 1 < n and text[i + 1] == '"':
                        value.append('"')
                        i += 2
                        continue
                    i += 1
                    break
                value.append(text[i])
                i += 1
            tail_start = i
            while i < n and text[i] not in ',\r\n':
                i += 1
            value = ''.join(value) + text[tail_start:i]
        else:
            while i < n and text[i] not in ',\r\n':
                i += 1
            value = text[start:i]
        fields.append([text[start:i], value])
        if i < n and text[i] == ',':
            i += 1
            if i == n:
                fields.append(['', ''])
            else:
                continue
        end = ''
        if i < n and text[i] == '\r':
            end = '\r\n' if text[i + 1:i + 2] == '\n' else '\r'
        elif i < n and text[i] == '\n':
            end = '\n'
        i += len(end)
        records.append((fields, end))
        fields = []
        if i >= n:
            break
    return records


def unparse(records):
    return ''.join(','.join(raw for raw, _ in fields) + end for fields, end in records)


def quoted(value):
    """A field as Moodle writes one (PHP's fputcsv): enclosed when it holds a delimiter, a quote, a
    line break, a tab, a space or a backslash, quotes doubled."""
    if re.search(r'[,"\r\n\t \\]', value):
        return '"%s"' % value.replace('"', '""')
    return value


def _find(header, what):
    """The index of the column ``what`` (a key of :data:`HEADERS`) in ``header``, or None: Moodle's
    string in any language, whatever its case and the spaces around it."""
    names = {name.casefold() for name in HEADERS[what]}
    found = [i for i, cell in enumerate(header) if cell.strip().casefold() in names]
    return found[0] if found else None


def _column(header, what, label):
    index = _find(header, what)
    if index is None:
        raise WorksheetError('no %s column (looked for %s, in any case) in the header: %s. Moodle names the '
                             'columns in the language of its interface: switch it to English and download the '
                             'worksheet again' % (label, ', '.join(repr(n) for n in HEADERS[what]),
                                                  ', '.join(header)))
    return index


def _maximum_column(header):
    """The "Maximum grade" column: without it the grade's scale is unknown, so nothing is written
    (never a total out of 17 or 30 into a column out of 20 without a word)."""
    index = _find(header, 'maximum')
    if index is not None:
        return index
    if _find(header, 'scale') is not None:
        raise WorksheetError('the assignment is graded on a scale (the worksheet has a %r column, no maximum '
                             'grade): the grader writes points; give the assignment a point grade (Type: Point) '
                             'and download the worksheet again' % header[_find(header, 'scale')])
    _column(header, 'maximum', 'maximum grade')


def _identifier_column(header, rows):
    """The identifier column by its header, else the one column whose every cell is a word and a
    number (``Participant 12``, ``Teilnehmer/in 12``) in any language."""
    try:
        return _column(header, 'identifier', 'identifier')
    except WorksheetError:
        found = [i for i in range(len(header)) if rows and all(
            len(fields) == len(header) and re.match(r'^\D+\s?\d+$', fields[i][1].strip()) for fields, _ in rows)]
        if len(found) == 1:
            return found[0]
        raise


def _feedback_column(header):
    try:
        return _column(header, 'feedback', 'feedback comments')
    except WorksheetError:
        found = [i for i, h in enumerate(header) if 'comment' in h.lower()]
        if len(found) == 1:
            return found[0]
        raise


def _points(x, comma=False):
    text = ('%.2f' % x).rstrip('0').rstrip('.')
    return text.replace('.', ',') if comma else text


def feedback(record, maximum=None):
    """The feedback comment of one student (HTML, as Moodle's feedback comments are): the total, then
    one line per item with its points, and why for each point lost. With the worksheet's ``maximum``
    grade (a number) other than the record's, it says the grade is the points scaled to it.
    ``record`` is a :class:`~exam_lab.grader.score.kept.GradeRecord`'s value (the desk's, or make
    worksheet's read from grade.json), whole when :func:`~exam_lab.grader.publish.hand.combine` added
    its hand items: its text is clean where the record was made; the teacher's remark from hand.csv
    is a paragraph of its own, after the sentences about the grade."""
    lines = []
    for entry in record['items']:
        line = '%s %s/%s' % (entry['id'], _points(entry['points']), _points(entry['max']))
        if entry.get('by') == 'hand':
            line += ' (by hand)' if entry['id'] not in record.get('missing', ()) else ': not given yet'
        elif entry['points'] < entry['max'] and entry.get('evidence'):
            why = student_view.item_words(entry, record).split('\n', 1)[0]  # never the threshold run
            line += ': ' + (why if len(why) <= 200 else why[:197] + '...')
        lines.append(line)
    paragraphs = []
    if 'machine_total' in record:  # the whole grade (exam_lab.grader.publish.hand.combine)
        ran = '' if record.get('status') in GRADED else ' (nothing of the package ran: %s)' % safe_text.one_line(
            record.get('status_reason', ''))
        head = ('%s / %s points: %s of %s by the machine, running the package (%s)%s, and %s of %s by the '
                'teacher (the report\'s questions, comments, code quality).' % (
                    _points(record['total']), _points(record['max']), _points(record['machine_total']),
                    _points(sum(e['max'] for e in record['items'] if e.get('by') != 'hand')), ', '.join(ITEMS),
                    ran, _points(record['total'] - record['machine_total']),
                    _points(sum(e['max'] for e in record['items'] if e.get('by') == 'hand'))))
    else:
        head = ('Machine-graded by running the package: %s / %s points (%s). Not scored by the machine: '
                'comments, code quality and the report.' % (_points(record['total']), _points(record['max']),
                                                            ', '.join(ITEMS)))
    if maximum is not None and abs(maximum - record['max']) > 1e-9:
        head += ' The grade is these points scaled to %s (x %s/%s).' % (_points(maximum), _points(maximum),
                                                                        _points(record['max']))
    paragraphs.append(head)
    if record.get('remark'):
        paragraphs.append('The teacher\'s remark: %s' % safe_text.one_line(record['remark']))
    return '%s<ul>%s</ul>' % (''.join('<p>%s</p>' % _escape(p) for p in paragraphs),
                              ''.join('<li>%s</li>' % _escape(l) for l in lines))


def whole_grade(record):
    """Whether ``record``'s points are a grade for Moodle: a whole grade (machine + hand) with every
    hand point given, of a student the machine graded or whose submission was refused before anything
    ran (a report only: 0 by the machine, measured as such). Else the reason it is not, one line."""
    if 'machine_total' not in record:
        return 'only the machine\'s %s points, not a grade: make worksheet adds the hand points of hand.csv' % (
            _points(record['max']))
    if record.get('missing'):
        return 'hand points not given yet in hand.csv: %s' % ', '.join(record['missing'])
    status = record.get('status', 'graded')
    if status in GRADED or record.get('status_reason', '').startswith(REFUSED):
        return None
    return 'status "%s": %s' % (status, record.get('status_reason', ''))


def _escape(text):
    # No double quote and no backslash in what we write: no field of ours needs PHP's escape rules.
    return html.escape(text, quote=True).replace('\\', '&#92;')


def fill(text, records):
    """Fill the worksheet ``text`` with the grades of ``records`` (each with ``participant``).

    Only a whole grade (:func:`whole_grade`) is written, scaled to the row's "Maximum grade" (20,
    Moodle's default 100), and its comment says so; any other record leaves its row as it was, with
    why in the summary.

    A row is the participant's: a record is matched by its participant number only (never by name),
    and a number two records claim (two folders of one participant in OUT) fills neither row. Every
    other cell a student chose (the full name, the email, a group, an online text) is made one no
    spreadsheet runs (:mod:`~exam_lab.grader.publish.cells`); Moodle's importer reads none of them.

    :returns: ``(filled text, summary)``; summary: ``graded`` [(student, participant, points)],
        ``kept`` [(student, why)] (rows matched but left as they were), ``unmatched`` [(student, why)],
        ``no_submission`` [row names of the worksheet no record matched].
    :raises WorksheetError: the file lacks a column the import needs (the maximum grade among them:
        without it the grade's scale is unknown), or a row is malformed.
    """
    bom = text.startswith(_BOM)
    body = text[1:] if bom else text
    records_csv = parse(body)
    rows = [r for r in records_csv if any(value.strip() for _, value in r[0])]
    if not rows:
        raise WorksheetError('the worksheet is empty')
    header = [value.strip() for _, value in rows[0][0]]
    ident = _identifier_column(header, rows[1:])
    grade = _column(header, 'grade', 'grade')
    maximum = _maximum_column(header)
    modified = _column(header, 'modified', 'last modified (grade)')  # Moodle's importer refuses a file without it
    comments = _feedback_column(header)
    names = _find(header, 'name')
    read_by_moodle = (ident, grade, maximum, modified, comments)
    by_number = {}
    for fields, _ in rows[1:]:
        if len(fields) != len(header):
            raise WorksheetError('a row has %d fields, the header %d (Moodle refuses such a file): %s'
                                 % (len(fields), len(header), ','.join(raw for raw, _ in fields)[:200]))
        for column, field in enumerate(fields):
            if column not in read_by_moodle and cells.needs_quote(field[1]):
                field[:] = [quoted(cells.cell(field[1])), cells.cell(field[1])]
        match = _IDENTIFIER.match(fields[ident][1].strip())
        if match:
            by_number[int(match.group(1))] = fields
    summary = {'graded': [], 'kept': [], 'unmatched': [], 'no_submission': [], 'maxima': [], 'whole_max': []}
    matched = set()
    claims = {}
    for record in records:
        if record.get('participant') is not None:
            claims.setdefault(record['participant'], []).append(record['student'])
    for record in records:
        number = record.get('participant')
        student = record['student']
        if number is None:
            summary['unmatched'].append((student, 'no participant number in the submission\'s name'))
            continue
        if len(claims[number]) > 1:
            matched.add(number)
            summary['unmatched'].append((student, 'participant %d is also %s\'s: two folders of OUT claim one '
                                         'participant, neither is written' % (
                                             number, ' and '.join(s for s in claims[number] if s != student))))
            continue
        fields = by_number.get(number)
        if fields is None:
            summary['unmatched'].append((student, 'participant %d is not in the worksheet' % number))
            continue
        matched.add(number)
        why = whole_grade(record)
        if why:
            summary['kept'].append((student, why))
            continue
        if fields[grade][1].strip() or fields[comments][1].strip():
            summary['kept'].append((student, 'the worksheet already has a grade or a feedback for it'))
            continue
        top = fields[maximum][1].strip()
        comma = ',' in top and '.' not in top
        top_value = _number(top) if top else None
        if top_value is None or top_value <= 0:
            summary['kept'].append((student, 'its maximum grade %r is not a number above 0' % top))
            continue
        if top_value not in summary['maxima']:
            summary['maxima'].append(top_value)
        total = record['total'] * top_value / record['max']
        if total > top_value + 1e-9:
            summary['kept'].append((student, '%s points exceed the maximum grade %s' % (record['total'], top)))
            continue
        points = _points(round(total, 2), comma)
        fields[grade][:] = [quoted(points), points]
        note = cells.cell(feedback(record, top_value))
        fields[comments][:] = [quoted(note), note]
        summary['graded'].append((student, number, points))
        if record['max'] not in summary['whole_max']:
            summary['whole_max'].append(record['max'])
    for number, fields in sorted(by_number.items()):
        if number not in matched:
            summary['no_submission'].append(fields[names][1] if names is not None else 'Participant %d' % number)
    return (_BOM if bom else '') + unparse(records_csv), summary


def _number(text):
    try:
        return float(text.replace(',', '.'))
    except ValueError:
        return None


#: The most a worksheet may hold (Moodle's for a class of thousands is a few MB).
MAX_WORKSHEET_BYTES = 32 << 20


def fill_file(source, target, records):
    """Read the worksheet at ``source`` (kept in OUT: through the contract); write the filled copy at
    ``target`` when it holds a grade, else remove an older one (never a file to upload without a grade
    in it); return the summary."""
    try:
        raw = contract.read_bytes(source, MAX_WORKSHEET_BYTES)
    except contract.ContractError as err:
        raise WorksheetError(str(err))
    try:
        text = raw.decode('utf-8')
    except UnicodeDecodeError as err:
        raise WorksheetError('not UTF-8 (download the worksheet again from Moodle): %s' % err)
    filled, summary = fill(text, records)
    if summary['graded']:
        contract.write_bytes(target, filled.encode('utf-8'))
    elif contract.exists(target):
        os.remove(target)
    return summary


def summary_lines(summary, target):
    """What the teacher reads after the run: the file to upload (or why there is none yet), and every
    row not graded, each student without all hand points with the items missing."""
    name = os.path.basename(target)
    if summary['graded']:
        lines = ['worksheet: %d whole grade(s) (machine + hand points, scaled to the maximum grade %s) in %s: '
                 'upload it in Moodle (Assignment > View all submissions > Grading action: Upload grading '
                 'worksheet)' % (len(summary['graded']), ', '.join(_points(m) for m in summary['maxima']), target)]
    else:
        lines = ['worksheet: no whole grade yet, so no %s to upload (the machine\'s points alone are no grade): '
                 'give the hand points, then make worksheet' % name]
    for student, why in summary['kept']:
        lines.append('  left blank in %s: %s (%s)' % (name, student, why))
    for student, why in summary['unmatched']:
        lines.append('  NOT MATCHED: %s (%s)' % (student, why))
    if summary['no_submission']:
        lines.append('  in the worksheet, no graded submission: %s' % ', '.join(summary['no_submission']))
    return [safe_text.one_line(line) for line in lines]

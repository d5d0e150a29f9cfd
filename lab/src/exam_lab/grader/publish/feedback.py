"""Each student's feedback back in Moodle in one upload: ``OUT/moodle-feedback.zip``. No rospy here.

Moodle's assignment takes a whole class's feedback files in one zip (the file feedback plugin's grading
action "Upload multiple feedback files in a zip", ``uploadzip`` in ``mod/assign/feedback/file/locallib.php``).
The zip holds one folder per student whose grade the teacher releases, named as Moodle names the folders
of "download all submissions" but for the feedback plugin, with one self-contained page in it::

    Jane Doe_1234567_assignfeedback_file_/feedback.html

The page shows what ``make check`` may show a student (:mod:`~exam_lab.grader.publish.student_view`, the
teacher's setting in lab/check_visibility.ini): the points only, or also the evidence and the flight of
the main run; never the threshold run (its plot, its value, its words) nor the teacher's notes. Every
text in it is escaped; it has no script and loads nothing (its Content-Security-Policy says so to the
browser): the plot is inline SVG. It holds nothing that changes from one run to the next but the grade
itself (no date, a fixed SVG id salt): the pages of two runs differ only where a grade or its evidence
moved. Moodle replaces every page of an uploaded zip all the same: its importer compares content hashes
only with the files a plugin lists, and the file feedback plugin lists none (see the rule below).

Released, as the worksheet releases a grade (:data:`exam_lab.grader.publish.moodle.GRADED`): a status
"graded" or "graded with fixes", and either no hand point in hand.csv (the machine's part alone, the page
says so) or every hand point (the whole grade). Every other student is left out, and named with why.
"""
import html
import io
import os
import re
import tempfile
import time
import zipfile

from exam_lab.grader import contract
from exam_lab.grader.publish import flightplot, hand, moodle, student_view
from exam_lab.grader.publish.report import NOT_SCORED
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.identity import identity
from exam_lab.grader.score.sheets import HAND_ITEMS, ITEMS, SHEETS

FILE = 'moodle-feedback.zip'
PAGE = 'feedback.html'
#: The teacher's choice of what a student sees: the same file as ``make check``'s (lab/check_visibility.ini).
SETTING = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.realpath(__file__)))))), 'check_visibility.ini')
#: The plugin a feedback folder names: ``assignfeedback`` + ``file`` (``get_subtype()``, ``get_type()``).
PLUGIN = ('assignfeedback', 'file')

# Moodle's naming rule, from its source (moodle/moodle):
# - mod/assign/classes/downloader.php, get_student_prefix(): prefix = clean_filename(str_replace('_', ' ',
#   fullname($student)) . '_' . get_uniqueid_for_user($student->id)); load_submissionplugin_filelist():
#   folder = clean_filename($prefix . '_' . $subtype . '_' . $type) (Moodle >= 4.1; mod/assign/locallib.php
#   download_submissions() in 3.1-4.0 added a last '_').
# - lib/moodlelib.php clean_filename($string) = clean_param($string, PARAM_FILE); PARAM_FILE
#   (lib/classes/param.php clean_param_value_file(), lib/moodlelib.php clean_param() before 4.4): fix_utf8,
#   then preg_replace('~[[:cntrl:]]|[&<>"`\|\':\\\\/]~u', ...) removes control characters and
#   & < > " ` | ' : \ /, and '.' or '..' alone becomes ''. PHP's /u sets PCRE2_UCP, so [[:cntrl:]] is
#   Unicode's Cc: the C1 controls U+0080-U+009F too (PHP 8.2 removes U+0085).
# - mod/assign/feedback/file/importziplib.php is_valid_filename_for_import(): a file whose name starts with
#   '.' or '~' is ignored; each folder of its path is split explode('_', $part, 5): [1] must be a
#   participant's unique id, [2] and [3] the plugin's subtype and type; the rest is the file's name. The
#   name part ([0]) cannot hold a '_' (hence Moodle's str_replace), and 3.x wants a fifth part: the last
#   '_' is written, which every version reads (importziplib.php at 0203d8f2; 3.1-4.0's splits the whole
#   path). is_file_modified() compares a file's content hash with the plugin's get_files(), which
#   assignfeedback_file leaves as assign_plugin's (mod/assign/assignmentplugin.php: none): each page of
#   an upload is imported, changed or not. The test oracles: lab/test/unit/test_grader_moodle_names.py.
_PARAM_FILE = re.compile('[\x00-\x1f\x7f-\x9f\ud800-\udfff]|[&<>"`|\':\\\\/]')
#: A download folder's (or flat file's) name: Moodle's full name, the participant's id, the plugin.
_DOWNLOAD = re.compile(r'^(.*?)_([0-9]+)_assign(?:submission|feedback)_')


def clean_filename(text):
    """Moodle's ``clean_filename()`` (``PARAM_FILE``): see the rule above."""
    text = _PARAM_FILE.sub('', text)
    return '' if text in ('.', '..') else text


def folder_name(fullname, participant):
    """The feedback folder of a participant, by Moodle's rule (the last '_' included)."""
    prefix = clean_filename('%s_%d' % (fullname.replace('_', ' '), participant))
    return clean_filename('%s_%s_%s_' % ((prefix,) + PLUGIN))


def moodle_name(record, number):
    """The full name as Moodle wrote it in the download folder's name (apostrophes and the like already
    removed by Moodle), else the grader's name of the student."""
    match = _DOWNLOAD.match(record.get('folder') or '')
    if match and int(match.group(2)) == number and match.group(1).strip():
        return match.group(1)
    return record['student']


def released(record, hands, number):
    """``(the record to show, None)`` when the grade is released, else ``(None, why it waits)``."""
    status = record.get('status', 'graded')
    if status not in moodle.GRADED:
        return None, 'status "%s"%s' % (status, ': %s' % record['status_reason'] if record.get('status_reason') else '')
    row = hands.get(hand.key(record))  # by participant number, the name only where there is none
    if row is None or all(v is None for v in row.points.values()):
        return record, None
    whole = hand.combine(record, row)
    if whole['missing']:
        return None, 'hand points not all given in hand.csv (%s)' % ', '.join(whole['missing'])
    return whole, None


def threshold_ran(folder):
    """Whether the threshold run took place for the results in ``folder``: its plan or probe result in
    the logs (as ``make check`` tells); True when the logs are gone (a page is kept: hide rather than
    guess)."""
    logs = os.path.join(folder, 'logs')
    if not os.path.isdir(logs):
        return True
    return any(os.path.exists(os.path.join(logs, name)) for name in ('plan-threshold.json', 'probe-threshold.json'))


def plot_svg(folder):
    """The main run's flight plot as inline SVG text, or None when there is nothing to draw. Only the
    main run: the threshold run's panel names its hidden value. Drawn from the kept measurements only
    (:func:`~exam_lab.grader.publish.flightplot.load_runs`: a record, its text made safe where it was
    made), by matplotlib, which escapes it for XML: nothing here is cleaned again."""
    runs = [(tag, probe) for tag, probe in flightplot.load_runs(folder) if tag == 'main']
    import matplotlib
    with tempfile.TemporaryDirectory(prefix='exam-feedback-') as scratch:
        path = os.path.join(scratch, 'flight.svg')
        with matplotlib.rc_context({'svg.fonttype': 'none', 'svg.hashsalt': 'exam-feedback'}):
            if not flightplot.draw(runs, path):
                return None
        with open(path, encoding='utf-8') as f:
            svg = f.read()
    svg = svg[svg.index('<svg'):]
    svg = re.sub(r'<metadata>.*?</metadata>\s*', '', svg, flags=re.S)  # matplotlib's date: not a change
    svg = svg.replace('<svg ', '<svg role="img" aria-label="the flight of the main run" class="plot" ', 1)
    return svg


def _e(value):
    return html.escape(safe_text.one_line(value), quote=True)


def _points(x):
    return ('%.2f' % x).rstrip('0').rstrip('.')


STYLE = ('body{font-family:sans-serif;max-width:60em;margin:1.5em auto;padding:0 1em;color:#222;line-height:1.4}'
         'h1{font-size:1.5em}h2{font-size:1.2em;margin-top:1.5em}table{border-collapse:collapse;margin:1em 0}'
         'th,td{border:1px solid #bbb;padding:.3em .5em;text-align:left;vertical-align:top}'
         'th{background:#eee}.num{text-align:right;white-space:nowrap}tr.lost td.num{background:#f8d7d7}'
         'tfoot th{background:#ddd}.note{color:#555;font-size:.9em}svg.plot{max-width:100%;height:auto}'
         'p.status{font-weight:bold}')
#: What the page may load: nothing (inline style, data: images only); no script may run.
POLICY = "default-src 'none'; style-src 'unsafe-inline'; img-src data:"


def page(record, name, show, threshold_run, svg=None):
    """The student's ``feedback.html``: what :mod:`student_view` shows with the setting ``show``.

    :param name: the student's name as Moodle wrote it.
    :param threshold_run: the threshold run took place (its words are then the teacher's).
    :param svg: the main run's plot (:func:`plot_svg`), shown with ``evidence`` only.
    """
    if show not in student_view.SHOW:
        raise ValueError('show = %r; expected one of %s' % (show, ', '.join(student_view.SHOW)))
    evidence = show == 'evidence'
    whole = 'machine_total' in record
    sheet = SHEETS.get(record.get('sheet'))
    total = '%s / %s' % (_points(record['total']), _points(record['max']))
    head = ['item', 'what is checked', 'points'] + (['what was measured'] if evidence else [])
    rows = []
    for entry in record['items']:
        what = (ITEMS.get(entry['id']) or HAND_ITEMS.get(entry['id']) or (0, ''))[1]
        by = ' (the teacher\'s)' if entry.get('by') == 'hand' else ''
        cells = ['<td>%s</td>' % _e(entry['id']), '<td>%s%s</td>' % (_e(what), _e(by)),
                 '<td class="num">%s / %s</td>' % (_points(entry['points']), _points(entry['max']))]
        if evidence:
            # The first line, as make check shows it, every form of the threshold run's value hidden.
            cells.append('<td>%s</td>' % _e(student_view.scrub(student_view.student_evidence(entry, threshold_run),
                                                               student_view.hidden(record))))
        rows.append('<tr%s>%s</tr>' % (' class="lost"' if entry['points'] < entry['max'] else '', ''.join(cells)))
    reason = student_view.student_reason(record, show, threshold_run)
    parts = ['<!DOCTYPE html>', '<html lang="en"><head><meta charset="utf-8">',
             '<meta http-equiv="Content-Security-Policy" content="%s">' % POLICY,
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             '<title>%s: %s</title><style>%s</style></head><body>' % (_e(name), total, STYLE),
             '<h1>%s: %s</h1>' % (_e(name), total),
             '<p class="status">Status: %s%s</p>' % (_e(record.get('status', '')), ' - %s' % _e(reason) if reason else ''),
             '<p>Your package was graded by running it: %s.</p>' % (
                 _e('sheet %s (%s, %s)' % (sheet.seed, sheet.name, sheet.drone_pkg)) if sheet else 'no sheet'),
             '<table class="items"><thead><tr>%s</tr></thead><tbody>%s</tbody>' % (
                 ''.join('<th>%s</th>' % h for h in head), ''.join(rows)),
             '<tfoot><tr><th>total</th><th></th><th class="num">%s</th>%s</tr></tfoot></table>' % (
                 total, '<th></th>' if evidence else '')]
    if whole and record.get('remark'):
        parts.append('<p><strong>Your teacher\'s remark:</strong> %s</p>' % _e(record['remark']))
    if evidence and svg:
        parts += ['<h2>Your flight (the main run)</h2>',
                  '<p class="note">What your node published (blue dots) against the value of the equation for '
                  'the inputs the grader sent (grey steps), the threshold (red dashes), each call of the warning '
                  'service (red: WARNING, green: NORMAL) and the legs flown (blue: below the threshold, red: '
                  'above).</p>', '<figure>%s</figure>' % svg]
    if whole:
        parts.append('<p class="note">Every point of the sheets\' 30: the machine\'s items, measured by running '
                     'your package, and your teacher\'s.</p>')
    else:
        parts.append('<p class="note">The machine\'s part only; not scored by the machine (your teacher grades '
                     'them): %s.</p>' % _e(NOT_SCORED))
    parts.append('<p class="note">%s</p></body></html>\n' % (
        'Shown: each item\'s points and what was measured.' if evidence else
        'Shown: each item\'s points (your course shows the points only).'))
    return '\n'.join(parts)


def read_show(path=None):
    """The setting of lab/check_visibility.ini (:func:`student_view.read_setting`)."""
    return student_view.read_setting(path or SETTING)


def write(out, records, single=False, show=None):
    """Write ``out/moodle-feedback.zip`` for ``records`` graded into ``out`` (merging hand.csv's points);
    return lines for the terminal: what was written, and each student left out and why.

    :param single: one submission (its results in ``out`` itself).
    :param show: ``points`` or ``evidence``; None reads lab/check_visibility.ini.
    """
    target = os.path.join(out, FILE)
    try:
        show = read_show() if show is None else show
        hands = hand.read(os.path.join(out, hand.FILE)) if contract.exists(os.path.join(out, hand.FILE)) else {}
    except (ValueError, hand.HandError) as err:
        return _nothing(target, safe_text.one_line(err))
    pages, waiting, numbers = [], [], {}
    for record in records:
        number = identity(record).participant
        shown, why = released(record, hands, number)
        if why is None and number is None:
            why = 'no Moodle participant number in its folder\'s name (%s)' % (record.get('folder') or 'none')
        if why:
            waiting.append((record['student'], why))
            continue
        numbers.setdefault(number, []).append(record['student'])
        pages.append((record, shown, number))
    twice = {n for n, names in numbers.items() if len(names) > 1}
    entries = {}
    for record, shown, number in pages:
        if number in twice:
            waiting.append((record['student'], 'participant %d is also %s' % (
                number, ', '.join(n for n in numbers[number] if n != record['student']))))
            continue
        try:
            folder = out if single else contract.student_folder(out, record['student'])
            ran = threshold_ran(folder)
            svg = plot_svg(folder) if show == 'evidence' else None
            entries[folder_name(moodle_name(record, number), number) + '/' + PAGE] = page(
                shown, moodle_name(record, number), show, ran, svg)
        except Exception as err:  # one student's page; the others are written
            waiting.append((record['student'], 'its page could not be made (a grader bug, please report): %s'
                            % safe_text.one_line('%s: %s' % (type(err).__name__, err))[:300]))
    if not entries:
        lines = _nothing(target, 'no student\'s grade is released yet')
    else:
        made = io.BytesIO()
        stamp = time.localtime()[:6]
        with zipfile.ZipFile(made, 'w', zipfile.ZIP_DEFLATED) as archive:
            for name in sorted(entries):
                info = zipfile.ZipInfo(name, stamp)
                info.compress_type = zipfile.ZIP_DEFLATED
                archive.writestr(info, entries[name].encode('utf-8'))
        contract.write_bytes(target, made.getvalue())
        lines = ['moodle feedback: %s: a page for %d student(s), showing %s (lab/check_visibility.ini); upload it '
                 'in the assignment: View all submissions, "Upload multiple feedback files in a zip"'
                 % (target, len(entries), 'the points and the evidence' if show == 'evidence' else 'the points')]
    if waiting:
        lines.append('moodle feedback: %d student(s) left out (the teacher must still look at them):' % len(waiting))
        lines += ['  %s: %s' % (safe_text.one_line(name), safe_text.one_line(why)) for name, why in waiting]
    return lines


def _nothing(target, why):
    """No zip: an old one would upload stale pages, so it goes."""
    if contract.exists(target):
        os.remove(target)  # the entry itself, a link included
    return ['moodle feedback: %s NOT written: %s' % (target, why)]

"""The teacher's page: ``OUT/index.html``, one static file for the class (or one submission). No rospy.

It opens from the file system (no server, no network: styles and the sorting script are inline, the
plots are PNG files beside it): the students that need the teacher first, a histogram of the totals,
a sortable table of students x items with each one's status, the pairs of submissions the similarity
check flagged, then one section per student with its flight plot, its documents (the PDF report,
listed, not graded) and its grade.md.
"""
import html
import re

from exam_lab.grader.publish import report
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.records import SimilarityRecord
from exam_lab.grader.score.sheets import ITEMS

#: Flagged pairs shown with their fragments; the rest are listed by name and score.
SHOWN_PAIRS = 20
#: Statuses whose points are a grade; the others come first, for the teacher.
GRADED = ('graded', 'graded with fixes')

_STYLE = """
body { font-family: sans-serif; margin: 1.5em; color: #222; max-width: 1300px; }
h1 { font-size: 1.5em; } h2 { border-bottom: 1px solid #ccc; padding-bottom: .2em; margin-top: 2em; }
table { border-collapse: collapse; font-size: .9em; }
th, td { border: 1px solid #ccc; padding: .25em .5em; text-align: left; vertical-align: top; }
table.scores th { background: #eee; cursor: pointer; user-select: none; white-space: nowrap; }
table.scores td.num { text-align: right; }
td.lost { background: #fde2e2; } td.full { background: #e6f4e6; }
.status-graded { color: #1d6b1d; } .status-graded-with-fixes { color: #1d6b1d; }
.status-needs-a-hand-grade, .status-not-graded { color: #b00000; font-weight: bold; }
.problem { color: #b00000; }
.first { background: #fff4e0; border: 1px solid #e8b463; padding: .5em 1em; }
.student { border-top: 3px solid #888; margin-top: 2.5em; }
pre { background: #f6f6f6; padding: .5em; overflow-x: auto; font-size: .85em; }
img.flight { max-width: 100%; border: 1px solid #ddd; }
.pair { display: flex; gap: 1em; } .pair pre { flex: 1; max-height: 28em; overflow: auto; }
.highlight-red { background: #ffd0d0; } .highlight-green { background: #d0ffd0; }
"""

_SCRIPT = """
document.querySelectorAll('table.scores th').forEach(function (th, column) {
  th.addEventListener('click', function () {
    var body = th.closest('table').tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var down = th.getAttribute('data-order') !== 'down';
    th.setAttribute('data-order', down ? 'down' : 'up');
    rows.sort(function (a, b) {
      var x = a.cells[column].getAttribute('data-sort'), y = b.cells[column].getAttribute('data-sort');
      var nx = parseFloat(x), ny = parseFloat(y);
      var c = (!isNaN(nx) && !isNaN(ny)) ? nx - ny : x.localeCompare(y);
      return down ? -c : c;
    });
    rows.forEach(function (row) { body.appendChild(row); });
  });
});
"""


def anchor(student):
    return 'student-' + re.sub(r'[^A-Za-z0-9_-]+', '-', student).strip('-')


def _e(text):
    return html.escape(str(text), quote=True)


def _inline(text):
    """Inline Markdown of grade.md (already escaped): **bold**, `code`."""
    text = re.sub(r'\*\*(.+?)\*\*', r'<strong>\1</strong>', text)
    return re.sub(r'`([^`]+)`', r'<code>\1</code>', text)


def markdown_html(text):
    """grade.md as HTML: the subset :func:`exam_lab.grader.publish.report.markdown` writes (headings,
    paragraphs, tables, lists, code blocks, bold, code). Everything is escaped first."""
    out, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        line = lines[i]
        if line.startswith('```'):
            block = []
            i += 1
            while i < len(lines) and not lines[i].startswith('```'):
                block.append(lines[i])
                i += 1
            out.append('<pre>%s</pre>' % _e('\n'.join(block)))
        elif line.startswith('#'):
            level = min(len(line) - len(line.lstrip('#')) + 2, 6)  # below the page's own headings
            out.append('<h%d>%s</h%d>' % (level, _inline(_e(line.lstrip('#').strip())), level))
        elif line.startswith('|'):
            rows = []
            while i < len(lines) and lines[i].startswith('|'):
                cells = [c.strip().replace('\\|', '|') for c in re.split(r'(?<!\\)\|', lines[i].strip())[1:-1]]
                if not all(re.match(r'^:?-+:?$', c) for c in cells):
                    rows.append(cells)
                i += 1
            i -= 1
            head = ''.join('<th>%s</th>' % _inline(_e(c)) for c in rows[0]) if rows else ''
            body = ''.join('<tr>%s</tr>' % ''.join('<td>%s</td>' % _inline(_e(c)) for c in row) for row in rows[1:])
            out.append('<table><thead><tr>%s</tr></thead><tbody>%s</tbody></table>' % (head, body))
        elif line.startswith('- '):
            items = []
            while i < len(lines) and lines[i].startswith('- '):
                items.append('<li>%s</li>' % _inline(_e(lines[i][2:])))
                i += 1
            i -= 1
            out.append('<ul>%s</ul>' % ''.join(items))
        elif line.strip():
            out.append('<p>%s</p>' % _inline(_e(line)))
        i += 1
    return '\n'.join(out)


def histogram_svg(totals, maximum, width=420, height=170):
    """An inline SVG histogram of the totals, one bar per point (a half point goes to its point)."""
    top = int(round(maximum))
    counts = [0] * (top + 1)
    for total in totals:
        counts[min(max(int(total), 0), top)] += 1
    most = max(counts + [1])
    left, bottom, bar = 28, 24, (width - 36.0) / (top + 1)
    parts = ['<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" role="img" '
             'aria-label="histogram of the totals">' % (width, height)]
    for points, count in enumerate(counts):
        h = (height - bottom - 14.0) * count / most
        x = left + points * bar
        parts.append('<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="#4a7fb5">'
                     '<title>%d point(s): %d student(s)</title></rect>'
                     % (x + 1, height - bottom - h, bar - 2, h, points, count))
        if count:
            parts.append('<text x="%.1f" y="%.1f" font-size="10" text-anchor="middle">%d</text>'
                         % (x + bar / 2, height - bottom - h - 2, count))
        parts.append('<text x="%.1f" y="%d" font-size="10" text-anchor="middle">%d</text>'
                     % (x + bar / 2, height - bottom + 12, points))
    parts.append('<line x1="%d" y1="%d" x2="%d" y2="%d" stroke="#333"/>'
                 % (left, height - bottom, width - 6, height - bottom))
    parts.append('<text x="%d" y="%d" font-size="10">total points</text>' % (width - 80, height - 2))
    parts.append('</svg>')
    return ''.join(parts)


def _status(record):
    return record.get('status', 'graded')


def _status_cell(record):
    status = _status(record)
    return '<span class="status-%s" title="%s">%s</span>' % (
        re.sub(r'\W+', '-', status), _e(record.get('status_reason', '')), _e(status))


def _notes(notes):
    """The desk's lines as a list; a line indented under one ending in ":" (each student a line names:
    "moodle feedback: 3 student(s) left out ...:") is an item of that line's own list, as on the terminal."""
    items = []
    for note in notes:
        if note.startswith('  ') and items and items[-1][0].endswith(':'):
            items[-1][1].append(note.strip())
        else:
            items.append((note.strip(), []))
    return '<ul>%s</ul>' % ''.join('<li>%s%s</li>' % (_e(n), '<ul>%s</ul>' % ''.join('<li>%s</li>' % _e(s) for s in sub)
                                                      if sub else '') for n, sub in items)


def render(records, title, entries, similar=None, notes=None):
    """The page's HTML, of records only: every text it shows was made safe where it was made, and is
    escaped here for HTML, never cleaned again.

    :param records: the grade records (each a :class:`~exam_lab.grader.score.kept.GradeRecord`'s value,
        as :func:`~exam_lab.grader.publish.report.grade_record` or the desk made them: their text
        clean), in the table's order.
    :param title: the page's title, one line made safe by the desk (the class's name, a student's).
    :param entries: per student, made by the desk of its record: ``{"plot": relative path of the PNG
        or None, "grade_md": text, "documents": [{"name", "pages"}], "folder": relative path of its
        results, "problems": what the desk could not make for it (one line each), "plot_failed": its
        plot was not drawn for one of those}``.
    :param similar: the similarity check's :class:`~exam_lab.grader.score.records.SimilarityRecord`
        (its pairs, the detector's highlighted HTML shown as it is: the record allows no other markup),
        or None when it did not run; a plain dict is refused (TypeError).
    :param notes: lines for the top of the page, made safe by the desk (the worksheet's summary, the
        similarity's notes).

    A student whose section cannot be made gets one that says why, and the others theirs.
    """
    if similar is not None and not isinstance(similar, SimilarityRecord):
        raise TypeError('the similarity check is shown from its record (records.SimilarityRecord), not a %s'
                        % type(similar).__name__)
    pairs = None if similar is None or similar.error else similar.pairs or []
    entries = entries or {}
    parts = ['<!DOCTYPE html>', '<html lang="en"><head><meta charset="utf-8">',
             '<title>%s</title>' % _e(title), '<style>%s</style></head><body>' % _STYLE,
             '<h1>%s</h1>' % _e(title)]
    # The machine's statistics count only what it measured: a student nothing of whose package ran
    # (a report only, an upload refused) is listed, never a 0 in the mean or the histogram.
    counted = [r for r in records if not report.ran_nothing(r)]
    totals = [r['total'] for r in counted]
    maximum = max([r['max'] for r in records] + [sum(p for p, _ in ITEMS.values())])
    left_out = len(records) - len(counted)
    parts.append('<p>%d student(s); mean %s / %s over the %d whose package ran%s; machine-scored items only '
                 '(not the comments, the code quality, the report).</p>' % (
                     len(records), '%.1f' % (sum(totals) / len(totals)) if totals else '-', report._points(maximum),
                     len(counted), '; %d not graded (nothing of theirs ran) counted in neither the mean nor the '
                     'histogram' % left_out if left_out else ''))
    first = [r for r in records if _status(r) not in GRADED or r.get('doubts')]
    parts.append('<h2 id="first">Needs the teacher first</h2>')
    if first:
        parts.append('<div class="first"><ul>%s</ul></div>' % ''.join(
            '<li><a href="#%s">%s</a>: %s%s%s</li>' % (
                anchor(r['student']), _e(r['student']), _status_cell(r),
                ' - %s' % _e(r['status_reason']) if r.get('status_reason') else '',
                '<ul>%s</ul>' % ''.join('<li>%s</li>' % _e(d) for d in report.doubts_beyond_reason(r))
                if report.doubts_beyond_reason(r) else '') for r in first))
    else:
        parts.append('<p>Nobody: every submission was graded by the machine.</p>')
    if notes:
        parts.append('<h2 id="notes">Hand points, Moodle worksheet and checks</h2>')
        parts.append(_notes(notes))
    parts.append('<h2 id="histogram">Totals</h2>')
    parts.append(histogram_svg(totals, maximum))
    parts.append('<h2 id="table">Students and items</h2><p>Click a column to sort.</p>')
    parts.append(_table(records))
    if pairs is not None:
        parts.append(_similarity(pairs))
    for record in records:
        try:
            parts.append(_section(record, entries.get(record['student'], {})))
        except Exception as err:  # this student's section says so; the page and the others' stand
            parts.append('<section class="student" id="%s"><h2>%s</h2><p class="problem">This section could '
                         'not be made: %s. Its results are in its folder.</p></section>'
                         % (anchor(record['student']), _e(record['student']), _e(safe_text.one_line(repr(err)))))
    parts.append('<script>%s</script></body></html>' % _SCRIPT)
    return '\n'.join(parts) + '\n'


def _table(records):
    head = ['student', 'participant', 'status'] + list(ITEMS) + ['total']
    rows = []
    for record in records:
        points = {e['id']: e for e in record['items']}
        cells = ['<td data-sort="%s"><a href="#%s">%s</a></td>' % (_e(record['student']), anchor(record['student']),
                                                                  _e(record['student'])),
                 '<td class="num" data-sort="%s">%s</td>' % (record.get('participant') or '',
                                                            record.get('participant') or ''),
                 '<td data-sort="%s">%s</td>' % (_e(_status(record)), _status_cell(record))]
        for item in ITEMS:
            entry = points.get(item)
            if entry is None:
                cells.append('<td data-sort="-1">-</td>')
                continue
            lost = entry['points'] < entry['max']
            why = entry.get('evidence', '').split('\n', 1)[0] if lost else ''
            cells.append('<td class="num %s" data-sort="%s" title="%s">%s</td>' % (
                'lost' if lost else 'full', entry['points'], _e(why), report._points(entry['points'])))
        cells.append('<td class="num" data-sort="%s"><strong>%s</strong> / %s</td>' % (
            record['total'], report._points(record['total']), report._points(record['max'])))
        rows.append('<tr id="row-%s">%s</tr>' % (anchor(record['student']), ''.join(cells)))
    return ('<table class="scores"><thead><tr>%s</tr></thead><tbody>%s</tbody></table>'
            % (''.join('<th>%s</th>' % _e(h) for h in head), '\n'.join(rows)))


def _similarity(pairs):
    parts = ['<h2 id="similarity">Similar submissions</h2>',
             '<p>Pairs whose code is alike once the code every student got (the drones\' packages, '
             'catkin_create_pkg\'s files, the launch file\'s boilerplate) is taken out, by copydetect '
             '(winnowing, in the style of MOSS). A flag, never a grade: read both before you decide.</p>']
    if not pairs:
        parts.append('<p>No pair above the threshold.</p>')
    for pair in pairs[:SHOWN_PAIRS]:
        parts.append('<h3>%s and %s: %.0f %% / %.0f %% alike</h3>' % (
            _e(pair.a), _e(pair.b), 100 * pair.score_a, 100 * pair.score_b))
        for match in pair.files[:3]:
            parts.append('<p>%s (%.0f %%) and %s (%.0f %%)</p><div class="pair"><pre>%s</pre><pre>%s</pre></div>' % (
                _e(match.file_a), 100 * match.sim_a, _e(match.file_b), 100 * match.sim_b,
                match.html_a, match.html_b))
    if len(pairs) > SHOWN_PAIRS:
        parts.append('<p>%d more pair(s), without their fragments (all in similarity.json): %s</p>' % (
            len(pairs) - SHOWN_PAIRS, '; '.join('%s and %s (%.0f %% / %.0f %%)' % (
                _e(p.a), _e(p.b), 100 * p.score_a, 100 * p.score_b) for p in pairs[SHOWN_PAIRS:])))
    return '\n'.join(parts)


def _section(record, entry):
    parts = ['<section class="student" id="%s">' % anchor(record['student']),
             '<h2>%s: %s / %s</h2>' % (_e(record['student']), report._points(record['total']),
                                       report._points(record['max'])),
             '<p>Status: %s%s</p>' % (_status_cell(record), ' - %s' % _e(record['status_reason'])
                                      if record.get('status_reason') else '')]
    for problem in entry.get('problems') or []:
        parts.append('<p class="problem">Not made for this student: %s</p>' % _e(problem))
    if entry.get('folder'):
        parts.append('<p>Results: <a href="%s/grade.md">grade.md</a>, <a href="%s/grade.json">grade.json</a>, '
                     '<a href="%s/logs/">logs</a></p>' % ((_e(entry['folder']),) * 3))
    documents = entry.get('documents') or record.get('documents') or []
    if documents:
        parts.append('<p>Documents handed in (not graded): %s</p>' % ', '.join(
            '%s (%s)' % (_e(d['name']), '%d page%s' % (d['pages'], '' if d['pages'] == 1 else 's')
                         if d.get('pages') is not None else 'pages unknown') for d in documents))
    else:
        parts.append('<p>Documents handed in: no PDF report found.</p>')
    if entry.get('plot'):
        parts.append('<p><img class="flight" src="%s" alt="flight of %s: value published against the '
                     'oracle, threshold, warning calls, legs"></p>' % (_e(entry['plot']), _e(record['student'])))
    elif not entry.get('plot_failed'):  # a plot that failed is said with the problems above
        parts.append('<p>No flight to plot: the node never ran against the probe.</p>')
    parts.append(markdown_html(entry.get('grade_md') or report.markdown(record)))
    parts.append('<p><a href="#table">back to the table</a></p></section>')
    return '\n'.join(parts)

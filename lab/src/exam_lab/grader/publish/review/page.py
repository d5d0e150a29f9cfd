"""The review page's HTML: the class, an item's answer groups, a student's proposals beside its
report and code. No rospy, no I/O: plain data in, text out.

Every text from the data (a student's name, a passage of its report, its code, a file name, the
evidence quoting them) is cleaned (:func:`~exam_lab.grader.score.safe_text.clean`) and escaped, in an
element's text or a quoted attribute, nowhere else; the page has no script at all and its
Content-Security-Policy (:data:`POLICY`, sent by the server) lets none run and nothing load but its own
page images: what a student typed is shown, never run. Forms post to the page itself (its token in
the path); each point a student's form sends carries the cell it was decided on.
"""
import base64
import hashlib
import html

from exam_lab.grader.publish import hand
from exam_lab.grader.publish.review import groups as grouping
from exam_lab.grader.score import safe_text
from exam_lab.grader.score.sheets import HAND_ITEMS

STYLE = """
body { font-family: sans-serif; margin: 1.2em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; border-bottom: 1px solid #ccc; margin-top: 1.6em; }
table { border-collapse: collapse; font-size: .9em; }
th, td { border: 1px solid #ccc; padding: .2em .45em; text-align: left; vertical-align: top; }
th { background: #eee; }
pre { background: #f6f6f6; padding: .4em; overflow-x: auto; font-size: .85em; white-space: pre-wrap; }
.said { background: #e6f4e6; border: 1px solid #7bb87b; padding: .4em .8em; }
.problem { background: #fde2e2; border: 1px solid #d88; padding: .4em .8em; }
.proposed { color: #777; font-style: italic; }
.flag { color: #b00000; font-weight: bold; }
.group { border: 1px solid #bbb; padding: .5em 1em; margin: 1em 0; }
.columns { display: flex; gap: 1.5em; align-items: flex-start; }
.columns > div { flex: 1; min-width: 0; }
.item { border-top: 2px solid #999; margin-top: 1em; padding-top: .4em; }
img.page { max-width: 100%; border: 1px solid #ccc; }
.code { max-height: 40em; overflow: auto; }
form.inline { display: inline; }
input.points { width: 4em; }
"""


def _hash(text):
    return base64.b64encode(hashlib.sha256(text.encode('utf-8')).digest()).decode('ascii')


#: What the browser may do with a page: its own style, its own images, forms to itself; no script.
POLICY = ("default-src 'none'; style-src 'sha256-%s'; img-src 'self'; form-action 'self'; "
          "base-uri 'none'; frame-ancestors 'none'" % _hash(STYLE))


def _e(value):
    return html.escape(safe_text.clean('' if value is None else str(value)), quote=True)


def _points(value):
    return '-' if value is None else hand.points_cell(value)


def _head(title, base):
    return ['<!DOCTYPE html>', '<html lang="en"><head><meta charset="utf-8">',
            '<meta name="referrer" content="same-origin">',
            '<title>%s</title><style>%s</style></head><body>' % (_e(title), STYLE),
            '<p><a href="%s/">the class</a> &middot; %s</p>' % (base, ' &middot; '.join(
                '<a href="%s/item/%s">%s</a>' % (base, item, item) for item in HAND_ITEMS))]


def _said(messages):
    out = []
    for kind, text in messages or ():
        out.append('<p class="%s">%s</p>' % ('problem' if kind == 'problem' else 'said', _e(text)))
    return out


def _cell(student, item, cells):
    """A student's item in the class's table: its point in hand.csv, else the proposal (greyed, ``?``)."""
    now = cells.get(student.key, {}).get(item, '')
    if now:
        return '<td class="given">%s</td>' % _e(now)
    proposal = student.proposals.get(item)
    if proposal is None:
        return '<td></td>'
    flag = ' <span class="flag" title="%s">!</span>' % _e(proposal['state']) if proposal['state'] != 'proposed' else ''
    return '<td class="proposed">%s?%s</td>' % (_e(_points(proposal['points'])), flag)


def _report_state(student):
    report = student.report
    if report is None:
        return 'no report.json'
    if report['state'] == 'read':
        return 'read (%d page(s))' % len(report['pages'])
    return '%s: %s' % (report['state'] or '?', report['why'])


def index(title, base, students, cells, agreement, notes=(), messages=()):
    """The class: each item's groups, every student (its points in hand.csv, its proposals greyed), the
    agreement so far."""
    parts = _head(title, base) + ['<h1>%s</h1>' % _e(title)] + _said(messages)
    parts.append('<p>Nothing here is a point until you confirm it: a proposal is shown greyed with a '
                 '<em>?</em> (<span class="flag">!</span>: to check, no answer found or not read); a point '
                 'given is in hand.csv.</p>')
    parts.append('<h2>Items</h2><table id="items"><thead><tr><th>item</th><th>max</th><th>what</th>'
                 '<th>given</th></tr></thead><tbody>')
    for item, (top, what) in HAND_ITEMS.items():
        given = sum(1 for s in students if cells.get(s.key, {}).get(item))
        parts.append('<tr><td><a href="%s/item/%s">%s</a></td><td>%s</td><td>%s</td><td>%d of %d</td></tr>' % (
            base, item, item, _points(top), _e(what), given, len(students)))
    parts.append('</tbody></table>')
    parts.append('<h2>Students</h2><table id="students"><thead><tr><th>student</th><th>participant</th>'
                 '<th>sheet</th><th>machine</th><th>report</th>%s</tr></thead><tbody>'
                 % ''.join('<th>%s</th>' % item for item in HAND_ITEMS))
    for student in students:
        parts.append('<tr><td><a href="%s/student/%d">%s</a></td><td>%s</td><td>%s</td><td>%s</td><td>%s</td>%s</tr>' % (
            base, student.index, _e(student.name), _e(student.participant or ''), _e(student.sheet),
            _e(student.status), _e(_report_state(student)), ''.join(_cell(student, item, cells) for item in HAND_ITEMS)))
    parts.append('</tbody></table>')
    parts += agreement_table(agreement)
    if notes:
        parts.append('<h2>Notes</h2><ul>%s</ul>' % ''.join('<li>%s</li>' % _e(n) for n in notes))
    parts.append('</body></html>')
    return '\n'.join(parts)


def agreement_table(agreement):
    parts = ['<h2>Agreement with the proposals</h2><table id="agreement"><thead><tr><th>item</th>'
             '<th>decided</th><th>as proposed</th><th>changed</th><th>without a proposal</th></tr></thead><tbody>']
    for entry in agreement:
        changes = '; '.join('%s: %s &rarr; %s' % (_e(s), _e(_points(p)), _e(_points(g))) for s, p, g, _ in entry.changed)
        parts.append('<tr><td>%s</td><td>%d</td><td>%d</td><td>%d%s</td><td>%d</td></tr>' % (
            entry.item, entry.decided, entry.agreed, len(entry.changed), (' (%s)' % changes) if changes else '',
            entry.unproposed))
    parts.append('</tbody></table>')
    return parts


def _group_label(group):
    if group.state == grouping.NO_PROPOSAL:
        return 'no proposal made'
    if group.state:
        return group.state
    return ', '.join('%s (%s)' % (_points(points), state) for points, state in group.proposals)


def item_page(title, base, item, found, students, cells, targets, messages=()):
    """An item's answer groups: each answer once, every member with its point, one form for the group.

    :param found: the item's groups (:func:`~exam_lab.grader.publish.review.groups.groups`).
    :param targets: ``{group id: (to write, kept)}`` (:func:`~exam_lab.grader.publish.review.decisions.group_targets`).
    """
    top, what = HAND_ITEMS[item]
    parts = _head('%s: %s' % (item, title), base) + ['<h1>%s (%s point(s)): %s</h1>' % (item, _points(top), _e(what))]
    parts += _said(messages)
    parts.append('<p>%d group(s) of identical answers (normalised: case, spacing, the run\'s pids, ports and '
                 'URIs aside) for %d student(s).</p>' % (len(found), len(students)))
    for group in found:
        members = [students[i] for i in group.members]
        write, kept = targets[group.id]
        proposed = grouping.proposed_points(group)
        parts.append('<div class="group" id="group-%s"><h2>%d student(s): %s</h2>' % (
            group.id, len(members), _e(_group_label(group))))
        if group.answer:
            parts.append('<pre class="answer">%s</pre>' % _e(group.answer))
        else:
            parts.append('<p class="flag">no answer to read (%s)</p>' % _e(group.state))
        if len(group.proposals) > 1:
            parts.append('<p class="flag">the proposals differ within this answer: type the points</p>')
        parts.append('<ul class="members">')
        for student in members:
            proposal = student.proposals.get(item)
            now = cells.get(student.key, {}).get(item, '')
            parts.append('<li><a href="%s/student/%d#item-%s">%s</a> (%s): %s%s</li>' % (
                base, student.index, item, _e(student.name), _e(student.sheet),
                ('<strong>%s in hand.csv</strong>' % _e(now)) if now else 'no point yet',
                ('; %s' % _e(proposal['evidence'])) if proposal and proposal['evidence'] else ''))
        parts.append('</ul>')
        if kept:
            parts.append('<p>Kept as they are (decided alone, or typed in hand.csv): %s</p>' % ', '.join(
                '%s (%s)' % (_e(s.name), _e(cell)) for s, cell in kept))
        given = [cell for _, cell in write if cell]
        if write:
            # a group decided already: its points are shown, to change them once more
            value = given[0] if given and len(set(given)) == 1 else ('' if proposed is None else _points(proposed))
            label = ('points for the %d student(s) (%d given by this group)' % (len(write), len(given)) if given
                     else 'points for the %d student(s) without one' % len(write))
            parts.append('<form method="post" action="%s/item/%s/%s">' % (base, item, group.id) +
                         '<label>%s: <input class="points" name="points" id="points-%s" value="%s" '
                         'inputmode="decimal"></label> ' % (label, group.id, _e(value)) +
                         '<button type="submit" id="give-%s">%s</button></form>' % (
                             group.id, 'Change' if given else ('Confirm' if proposed is not None else 'Give')))
        parts.append('</div>')
    parts.append('</body></html>')
    return '\n'.join(parts)


def student_page(title, base, student, cells, code, messages=(), count=0):
    """A student: each item's proposal (its evidence, checks, the passage) with its form, beside the
    report's page images and the code.

    :param code: :func:`~exam_lab.grader.publish.review.folder.code_files`' answer.
    :param count: how many students the class has (the links to the previous and the next).
    """
    parts = _head('%s: %s' % (student.name, title), base)
    parts.append('<h1>%s</h1><p>participant %s, sheet %s, the machine: %s (%s / 17)</p>' % (
        _e(student.name), _e(student.participant or '-'), _e(student.sheet), _e(student.status),
        _e(_points(student.record.get('total')))))
    parts += _said(messages)
    parts.append('<p>%s</p>' % ' &middot; '.join(
        '<a href="%s/student/%d" id="%s">%s student</a>' % (base, index, rel, rel)
        for index, rel in ((student.index - 1, 'previous'), (student.index + 1, 'next')) if 0 <= index < count))
    parts.append('<div class="columns"><div>')
    for item, (top, what) in HAND_ITEMS.items():
        proposal = student.proposals.get(item)
        now = cells.get(student.key, {}).get(item, '')
        parts.append('<div class="item" id="item-%s"><h2>%s (%s): %s</h2>' % (item, item, _points(top), _e(what)))
        if proposal is None:
            parts.append('<p class="flag">no proposal</p>')
        else:
            flag = '' if proposal['state'] == 'proposed' else ' class="flag"'
            page = proposal['page']
            parts.append('<p>proposed: <strong>%s</strong> <span%s>(%s)</span>%s</p>' % (
                _e(_points(proposal['points'])), flag, _e(proposal['state']),
                (' &middot; <a href="#page-%d">page %d</a>' % (page, page)) if page is not None else ''))
            if proposal['evidence']:
                parts.append('<p class="evidence">%s</p>' % _e(proposal['evidence']))
            if proposal['checks']:
                parts.append('<ul class="checks">%s</ul>' % ''.join(
                    '<li>%s %s: %s</li>' % ({True: '&#10003;', False: '&#10007;'}.get(c['ok'], '?'), _e(c['name']),
                                            _e(c['detail'])) for c in proposal['checks']))
            if proposal['passage']:
                parts.append('<pre class="passage">%s</pre>' % _e(proposal['passage']))
        value = now or ('' if proposal is None or proposal['points'] is None else _points(proposal['points']))
        parts.append('<form method="post" action="%s/student/%d/%s"><input type="hidden" name="was" value="%s">'
                     '<label>%s: <input class="points" name="points" id="points-%s" value="%s" inputmode="decimal">'
                     '</label> <button type="submit" id="save-%s">%s</button> %s</form></div>' % (
                         base, student.index, item, _e(now), 'in hand.csv' if now else 'points', item, _e(value), item,
                         'Save' if now else ('Confirm' if value else 'Give'),
                         '' if now else '<span class="proposed">not given yet</span>'))
    parts.append('</div><div>')
    parts += _report(base, student)
    parts += _code(code)
    parts.append('</div></div></body></html>')
    return '\n'.join(parts)


def _report(base, student):
    report = student.report
    parts = ['<h2>Report</h2>']
    if report is None:
        return parts + ['<p class="flag">no report.json: the report was not read for this run</p>']
    parts.append('<p>%s</p>' % _e(_report_state(student)))
    if report['files']:
        parts.append('<ul>%s</ul>' % ''.join('<li>%s (%s%s, %s page(s))%s</li>' % (
            _e(f['name']), _e(f['kind']), ', converted' if f['converted'] else '', _e(_points(f['pages'])),
            (': ' + _e(f['note'])) if f['note'] else '') for f in report['files']))
    if report['notes']:  # what the reader left out or could not read: said, never a silent cut
        parts.append('<ul class="flag">%s</ul>' % ''.join('<li>%s</li>' % _e(n) for n in report['notes']))
    for index, page in enumerate(report['pages']):
        label = 'page %d%s, %s%s' % (page['number'], (' of file %d' % (page['file'] + 1)) if len(report['files']) > 1
                                     else '', page['source'],
                                     (', confidence %.0f' % page['confidence']) if page['confidence'] is not None else '')
        anchor = 'page-%d' % page['number'] if not page['file'] else 'page-%d-%d' % (page['file'], page['number'])
        parts.append('<h3 id="%s">%s</h3>' % (anchor, _e(label)))
        if page['unsure']:
            parts.append('<p class="flag">read with low confidence: %s</p>' % _e(', '.join(page['unsure'])))
        if page['image']:
            parts.append('<img class="page" alt="%s" src="%s/image/%d/%d">' % (_e(label), base, student.index, index))
        else:
            parts.append('<pre>%s</pre>' % _e(page['text']))
    return parts


def _code(code):
    parts = ['<h2>Code</h2>']
    if not code:
        return parts + ['<p>no code kept for this student (OUT/&lt;student&gt;/code/)</p>']
    for path, text, why in code:
        if text is None:
            parts.append('<p><code>%s</code>: %s</p>' % (_e(path), _e(why)))
            continue
        lines = text.split('\n')
        width = len(str(len(lines)))
        numbered = '\n'.join('%*d  %s' % (width, n, line) for n, line in enumerate(lines, start=1))
        parts.append('<h3><code>%s</code></h3><pre class="code">%s</pre>' % (_e(path), _e(numbered)))
    return parts


def problem(title, base, why):
    """A page that says why the review cannot go on (hand.csv or review.json unreadable): nothing written."""
    return '\n'.join(_head(title, base) + ['<h1>%s</h1>' % _e(title), '<p class="problem">%s</p>' % _e(why),
                                           '<p>Nothing is written until it is fixed; then reload.</p></body></html>'])

"""The teacher's desk: what a class run leaves besides the grades. No rospy here.

After grading, :func:`finish` writes, in ``OUT``: each student's Gradescope ``results.json`` and
flight plot, the similarity check across the class, the Moodle worksheet filled (when one is given),
and ``index.html`` (:mod:`exam_lab.grader.publish.page`).
"""
import json
import os

from exam_lab.grader.publish import flightplot, gradescope, moodle, page


def _grade_md(folder, record):
    path = os.path.join(folder, 'grade.md')
    text = open(path).read() if os.path.isfile(path) else ''
    return '\n'.join(l for l in text.splitlines() if not l.startswith('# ')) if text else ''


def finish(out, records, single=False, similar=None, worksheet=None, scale=False, title=None):
    """Write the desk's files for ``records`` graded into ``out``; return lines for the terminal.

    :param single: one submission (its results are in ``out`` itself, not ``out/<student>``).
    :param similar: the similarity check's result (:func:`exam_lab.grader.boxed.similarity.check`) or None.
    :param worksheet: the Moodle worksheet to fill, or None.
    :param scale: scale the grades to the worksheet's maximum grade (:func:`moodle.fill`).
    :param title: the class's name (:func:`moodle.class_name`); the output folder's name when None.
    """
    lines, notes, entries = [], [], {}
    for record in records:
        folder = out if single else os.path.join(out, record['student'])
        gradescope.write(folder, record)
        plot = os.path.join(folder, 'flight.png')
        drawn = flightplot.draw(flightplot.load_runs(os.path.join(folder, 'logs')), plot, record['student'])
        relative = '.' if single else os.path.relpath(folder, out)
        entries[record['student']] = {'plot': os.path.join(relative, 'flight.png') if drawn else None,
                                      'grade_md': _grade_md(folder, record), 'folder': relative,
                                      'documents': record.get('documents')}
    if worksheet:
        base = os.path.splitext(os.path.basename(worksheet))[0]
        target = os.path.join(out, '%s-filled.csv' % base)
        try:
            summary = moodle.fill_file(worksheet, target, records, scale)
            lines += moodle.summary_lines(summary, target)
            with open(os.path.join(out, 'worksheet.json'), 'w') as f:
                json.dump(summary, f, indent=1, sort_keys=True)
        except (moodle.WorksheetError, OSError) as err:
            lines.append('worksheet NOT filled: %s' % err)
        notes += lines
    pairs = None
    if similar is not None:
        pairs = similar.get('pairs', [])
        if similar.get('error'):
            notes.append('similarity check not run: %s' % similar['error'])
            lines.append('similarity: not run: %s' % similar['error'])
            pairs = None
        else:
            lines.append('similarity: %d pair(s) flagged of %d student(s) (%s)'
                         % (len(pairs), similar.get('students', 0), os.path.join(out, 'index.html#similarity')))
    title = 'Exam grades: %s' % (records[0]['student'] if single and records else title or os.path.basename(out))
    with open(os.path.join(out, 'index.html'), 'w') as f:
        f.write(page.render(records, title, entries, pairs, notes))
    lines.append('page: %s' % os.path.join(out, 'index.html'))
    return lines

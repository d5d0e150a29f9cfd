"""The teacher's desk: what a class run leaves besides the grades. No rospy here.

After grading, :func:`finish` writes, in ``OUT``: each student's Gradescope ``results.json`` and
flight plot, the similarity check across the class, the Moodle worksheet filled (when one is given),
and ``index.html`` (:mod:`exam_lab.grader.page`). :func:`submission_facts` is what the runner adds to
each grade record from the submission's own folder: the Moodle participant number and the PDF
reports handed in (listed with their page count, never graded).
"""
import json
import os
import re
import shutil
import zlib

from exam_lab.grader import flightplot, gradescope, moodle, page, similarity, unpack

#: Bytes of a PDF read to count its pages, and most bytes one of its streams may inflate to.
PDF_READ_BYTES = 50 * 1024 * 1024
PDF_STREAM_BYTES = 5 * 1024 * 1024
#: A page tree node's dictionary (no nested dictionary in it): its /Count is the pages below it.
_PAGE_TREE = re.compile(rb'<<((?:(?!<<|>>).)*?/Type\s*/Pages\b(?:(?!<<|>>).)*)>>', re.S)
#: PDFs listed per submission, and how deep in its folder they are looked for.
MAX_DOCUMENTS = 10
MAX_DEPTH = 3


def pdf_pages(path):
    """The page count of a PDF, or None when the file does not read as one.

    The page tree's ``/Count`` (its root holds the total), else the ``/Type /Page`` objects; object
    streams (PDF 1.5) are inflated, each to at most PDF_STREAM_BYTES.
    """
    try:
        with open(path, 'rb') as f:
            data = f.read(PDF_READ_BYTES)
    except OSError:
        return None
    if not data.startswith(b'%PDF'):
        return None
    texts = [data]
    for match in re.finditer(rb'stream\r?\n', data):
        try:
            texts.append(zlib.decompressobj().decompress(data[match.end():match.end() + PDF_STREAM_BYTES],
                                                         PDF_STREAM_BYTES))
        except zlib.error:
            continue
    counts, pages = [], 0
    for text in texts:
        for tree in _PAGE_TREE.findall(text):
            counts += [int(n) for n in re.findall(rb'/Count\s+(\d+)', tree)]
        pages += len(re.findall(rb'/Type\s*/Page(?![A-Za-z])', text))
    if counts:
        return max(counts)
    return pages or None


def documents(path):
    """``[{"name", "pages"}]`` of the PDFs in a submission (a folder; a lone file when it is one)."""
    found = []
    if os.path.isfile(path):
        candidates = [path] if path.lower().endswith('.pdf') else []
        base = os.path.dirname(path)
    else:
        candidates, base = [], path
        for dirpath, dirnames, filenames in os.walk(path):
            depth = os.path.relpath(dirpath, path).count(os.sep)
            dirnames[:] = sorted(d for d in dirnames if not d.startswith('.')) if depth < MAX_DEPTH else []
            candidates += [os.path.join(dirpath, n) for n in sorted(filenames) if n.lower().endswith('.pdf')]
    for full in candidates[:MAX_DOCUMENTS]:
        if os.path.islink(full):
            continue
        found.append({'name': os.path.relpath(full, base), 'pages': pdf_pages(full)})
    return found


def submission_facts(path):
    """What a grade record takes from the submission itself: ``participant`` (Moodle's number in the
    folder's name, or None), ``folder`` (that name), ``documents`` (the PDFs handed in)."""
    name = os.path.basename(os.path.abspath(path).rstrip('/'))
    return {'participant': moodle.participant_number(name), 'folder': name, 'documents': documents(path)}


def class_similarity(klass, out, records):
    """The similarity check over a class's submissions (unpacked anew, as the runner did), each
    named as its grade record names it; ``{"error"}`` when it could not run (the grades stand)."""
    scratch = os.path.join(out, '.similarity-class')
    try:
        by_folder = {r.get('folder'): r['student'] for r in records}
        submissions = [(by_folder.get(os.path.basename(folder), name), folder)
                       for name, folder in unpack.list_students(klass, scratch)]
        return similarity.check(submissions, out)
    except Exception as err:  # a bug of the check must not cost the class its page
        return {'error': repr(err)}
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


def _grade_md(folder, record):
    path = os.path.join(folder, 'grade.md')
    text = open(path).read() if os.path.isfile(path) else ''
    return '\n'.join(l for l in text.splitlines() if not l.startswith('# ')) if text else ''


def finish(out, records, single=False, similar=None, worksheet=None):
    """Write the desk's files for ``records`` graded into ``out``; return lines for the terminal.

    :param single: one submission (its results are in ``out`` itself, not ``out/<student>``).
    :param similar: the similarity check's result (:func:`exam_lab.grader.similarity.check`) or None.
    :param worksheet: the Moodle worksheet to fill, or None.
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
            summary = moodle.fill_file(worksheet, target, records)
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
    title = 'Exam grades: %s' % (records[0]['student'] if single and records else os.path.basename(out))
    with open(os.path.join(out, 'index.html'), 'w') as f:
        f.write(page.render(records, title, entries, pairs, notes))
    lines.append('page: %s' % os.path.join(out, 'index.html'))
    return lines

"""What a grade record takes from the submission itself, besides the grading: the Moodle participant
number in its folder's name and the PDF reports handed in (listed with their page count, never
graded). No rospy here; the runner adds :func:`submission_facts` to each record.
"""
import os
import re
import zlib

from exam_lab.grader.publish import moodle

#: Bytes of a PDF read to count its pages (and inflated from its streams, all together), and most
#: bytes one of its streams may inflate to.
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
    texts, budget = [data], PDF_READ_BYTES
    for match in re.finditer(rb'stream\r?\n', data):
        if budget <= 0:
            break  # a PDF made to inflate without end: its first pages' worth is counted
        try:
            texts.append(zlib.decompressobj().decompress(data[match.end():match.end() + PDF_STREAM_BYTES],
                                                         min(PDF_STREAM_BYTES, budget)))
        except zlib.error:
            continue
        budget -= len(texts[-1])
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

"""What a grade record takes from the submission itself, besides the grading: the Moodle participant
number in its folder's name and the PDF reports handed in (listed with their page count, never
graded). No rospy here; the runner adds :func:`submission_facts` to each record.
"""
import os
import re
import zlib

from exam_lab.grader.boxed import archives, bounds
from exam_lab.grader.score.identity import participant_number

#: Bytes of a PDF read to count its pages, and the work spent on its streams, all together: bytes
#: fed to zlib plus bytes inflated (a stream that fails still costs what was fed). Most bytes one
#: stream may inflate to, and the piece fed at a time.
PDF_READ_BYTES = 50 * 1024 * 1024
PDF_STREAM_BYTES = 5 * 1024 * 1024
_PIECE = 4096
#: Every pattern here is matched in time linear in the PDF's size (a student's bytes: one regular
#: expression that backtracked over a page tree without its ">>" took 76 s on a 325 KB file).
_DICT_EDGES = re.compile(rb'<<|>>')
_PAGES_TYPE = re.compile(rb'/Type\s*/Pages\b')
_COUNT = re.compile(rb'/Count\s+(\d{1,9})(?!\d)')
_PAGE = re.compile(rb'/Type\s*/Page(?![A-Za-z])')
_STREAM = re.compile(rb'stream\r?\n')
#: PDFs listed per submission, and how deep in its folder they are looked for.
MAX_DOCUMENTS = 10
MAX_DEPTH = 3


def pdf_pages(path, notes=None, name=None):
    """The page count of a PDF, or None when the file does not read as one.

    The page tree's ``/Count`` (its root holds the total), else the ``/Type /Page`` objects; object
    streams (PDF 1.5) are inflated, within PDF_READ_BYTES of work in all. Linear in the file's size.
    A file larger, or whose streams inflate to more, is counted on what was read, said in ``notes``
    (the file named ``name``).
    """
    try:
        with open(path, 'rb') as f:
            data, size = f.read(PDF_READ_BYTES), os.fstat(f.fileno()).st_size
    except OSError:
        return None
    if not data.startswith(b'%PDF'):
        return None
    shown = archives.shown_name(name or os.path.basename(path))
    if size > PDF_READ_BYTES:
        _said(notes, '%s: %d bytes, its pages counted on the first %d (the most read of a PDF)'
              % (shown, size, PDF_READ_BYTES))
        notes = None  # one sentence for the one cap
    texts, budget, view = [data], PDF_READ_BYTES, memoryview(data)
    for match in _STREAM.finditer(data):
        if budget <= 0:  # a PDF made to inflate without end: its first pages' worth is counted
            _said(notes, '%s: its streams inflate past the %d bytes of work spent counting its pages: counted '
                         'on those read' % (shown, PDF_READ_BYTES))
            break
        text, cost = _inflate(view, match.end(), budget)
        budget -= cost
        if text:
            texts.append(text)
    counts, pages = [], 0
    for text in texts:
        counts += _page_tree_counts(text)
        pages += sum(1 for _ in _PAGE.finditer(text))
    if counts:
        return max(counts)
    return pages or None


def _inflate(view, start, budget):
    """``(bytes inflated from the zlib stream at view[start:], or b'' when it is none, cost)``; the
    cost is the bytes fed plus the bytes inflated, at most about ``budget`` + one piece."""
    inflater = zlib.decompressobj()
    end = min(len(view), start + PDF_STREAM_BYTES)
    limit = min(PDF_STREAM_BYTES, budget)
    out, size, position = [], 0, start
    try:
        while position < end and size < limit and not inflater.eof:
            piece = view[position:min(position + _PIECE, end)]
            position += len(piece)
            out.append(inflater.decompress(piece, limit - size))
            size += len(out[-1])
    except zlib.error:
        return b'', position - start
    return b''.join(out), position - start + size


def _page_tree_counts(text):
    """The ``/Count`` of every page tree node in ``text``: a dictionary without a nested one that says
    ``/Type /Pages``. One pass: each byte is inside at most one innermost ``<< >>``."""
    counts, opened = [], None
    for edge in _DICT_EDGES.finditer(text):
        if edge.group() == b'<<':
            opened = edge.end()
        elif opened is not None:
            inner = text[opened:edge.start()]
            if _PAGES_TYPE.search(inner):
                counts += [int(n) for n in _COUNT.findall(inner)]
            opened = None
    return counts


def _said(notes, sentence):
    if notes is not None:
        notes.append(sentence)


def documents(path, notes=None):
    """``[{"name", "pages"}]`` of the PDFs in a submission (a folder; a lone file when it is one), the
    first MAX_DOCUMENTS of them (said in ``notes``)."""
    found = []
    if os.path.isfile(path):
        candidates = [path] if path.lower().endswith('.pdf') else []
        base = os.path.dirname(path)
    else:
        candidates, base, below = [], path, []
        for dirpath, dirnames, filenames in os.walk(path):
            depth = os.path.relpath(dirpath, path).count(os.sep)
            dirnames[:] = sorted(d for d in dirnames if not d.startswith('.'))
            if depth >= MAX_DEPTH:
                below += [os.path.join(dirpath, d) for d in dirnames]
                dirnames[:] = []
            candidates += [os.path.join(dirpath, n) for n in sorted(filenames) if n.lower().endswith('.pdf')]
        deeper = bounds.found_deeper(below, lambda p: p.lower().endswith('.pdf'))
        if deeper:
            _said(notes, '%s is %d folders deep: PDFs are listed %d folders deep at most'
                  % (archives.shown_name(os.path.relpath(deeper, path)), os.path.relpath(deeper, path).count(os.sep),
                     MAX_DEPTH + 1))
    candidates = [full for full in candidates if not os.path.islink(full)]
    for full in bounds.kept(candidates, 'PDF files', notes if notes is not None else [], MAX_DOCUMENTS,
                            verb='listed', text=None):
        name = os.path.relpath(full, base)
        found.append({'name': name, 'pages': pdf_pages(full, notes, name)})
    return found


def submission_facts(path, notes=None):
    """What a grade record takes from the submission itself: ``participant`` (Moodle's number in the
    folder's name, or None), ``folder`` (that name), ``documents`` (the PDFs handed in; their caps
    said in ``notes``)."""
    name = os.path.basename(os.path.abspath(path).rstrip('/'))
    return {'participant': participant_number(name), 'folder': name, 'documents': documents(path, notes)}

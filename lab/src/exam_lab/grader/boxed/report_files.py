"""Which files of a submission are its report, and of what kind: as the report reader's box's uid
(:mod:`~exam_lab.grader.boxed.report_reader`). No rospy, no tool run.
"""
import hashlib
import os
import re
import zipfile

from exam_lab.grader.boxed import archives, bounds
from exam_lab.grader.score.records import REPORT_FILES

#: Bytes of one file read as a report; how deep in the folder and in archives reports are looked for.
FILE_BYTES = 50 << 20
MAX_DEPTH = 4
MAX_NESTING = 2
#: Report files by their name's ending: a document in an archive; a picture only at the folder's top.
DOCUMENT_ENDINGS = ('.pdf', '.odt', '.docx', '.doc', '.rtf')
PICTURE_ENDINGS = ('.png', '.jpg', '.jpeg')


def kind_of(path):
    """The kind of a file, from its first bytes: one of records.REPORT_KINDS."""
    try:
        with open(path, 'rb') as f:
            head = f.read(1024)
    except OSError:
        return 'other'
    if head.startswith(b'\x89PNG\r\n\x1a\n') or head.startswith(b'\xff\xd8\xff'):
        return 'image'
    if head.startswith(b'{\\rtf'):
        return 'rtf'
    if head.startswith(b'\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1'):
        return 'doc'
    if head.startswith(b'PK\x03\x04'):
        try:
            with zipfile.ZipFile(path) as zf:
                # Every entry's name (ZipFile read them all with the central directory): a docx whose
                # document.xml came after the 1000th entry was once "not a document" for a cap of no use.
                names = set(zf.namelist())
                if 'word/document.xml' in names:
                    return 'docx'
                if 'mimetype' in names and zf.read('mimetype')[:100].startswith(b'application/vnd.oasis.opendocument.text'):
                    return 'odt'
        except (zipfile.BadZipFile, OSError, KeyError, RuntimeError, NotImplementedError, EOFError):
            pass
        return 'other'  # a zip holding a PDF stored as is holds "%PDF-" too: an archive, searched
    if b'%PDF-' in head:  # (a PDF may start with up to 1 kB of anything)
        return 'pdf'
    return 'other'


def copy_name(index, name):
    """The name of a file's copy in report/: its index and its own name, of safe characters only."""
    base = re.sub(r'[^A-Za-z0-9._ -]', '_', os.path.basename(name)).strip(' .') or 'report'
    return '%d-%s' % (index + 1, base[-150:])


def _document(path):
    return kind_of(path) in ('pdf', 'odt', 'docx', 'doc', 'rtf') or path.lower().endswith(DOCUMENT_ENDINGS)


def find_reports(upload, scratch, notes, beyond=None):
    """``[(name as the teacher knows it, path)]`` of the report files of a submission (a folder, or
    one file: a document, a picture, an archive): its own files first, then the documents of its
    archives (unpacked below ``scratch``, all within one budget), the same bytes once. When there is
    none, a document beyond MAX_DEPTH folders or an archive beyond MAX_NESTING is said as that cap, in
    ``notes`` and ``beyond``."""
    budget, found, seen = archives.Budget(), [], {}
    counter, below, nested = [0], [], []

    def look(root, shown, nesting, pictures):
        if os.path.isfile(root):
            entries = [(root, shown)]
        else:
            entries = []
            for dirpath, dirnames, filenames in os.walk(root):
                depth = os.path.relpath(dirpath, root).count(os.sep)
                dirnames[:] = sorted(d for d in dirnames if d not in archives.SKIPPED_DIRS and not d.startswith('.')
                                     and not os.path.islink(os.path.join(dirpath, d)))
                if depth >= MAX_DEPTH:
                    below.extend((os.path.join(dirpath, d), root, shown) for d in dirnames)
                    dirnames[:] = []
                for name in sorted(filenames):
                    full = os.path.join(dirpath, name)
                    if not os.path.islink(full) and os.path.isfile(full) and not name.startswith('.'):
                        rel = os.path.relpath(full, root)
                        entries.append((full, rel if shown is None else '%s/%s' % (shown, rel)))
        inner = []
        for full, name in entries:
            lower = name.lower()
            kind = kind_of(full)
            if kind in ('pdf', 'odt', 'docx', 'doc', 'rtf') or lower.endswith(DOCUMENT_ENDINGS) or \
                    (pictures and (kind == 'image' or lower.endswith(PICTURE_ENDINGS))):
                found.append((name, full))
            elif kind == 'other' and archives.archive_kind(full):
                (inner if nesting < MAX_NESTING else nested).append((full, name))
        for full, name in inner:
            target = os.path.join(scratch, 'unpacked%d' % counter[0])
            counter[0] += 1
            try:
                archives.safe_extract(full, target, budget=budget, notes=[], fixes=[])
            except archives.UnpackError as err:
                notes.append('%s: not searched for a report (%s)' % (archives.shown_name(name), err))
                continue
            look(target, name, nesting + 1, False)
    look(upload, os.path.basename(upload) if os.path.isfile(upload) else None, 0, True)
    if not found:
        said = beyond if beyond is not None else []
        for folder, root, shown in below:
            deeper = bounds.found_deeper([folder], _document)
            if deeper:
                relative = os.path.relpath(deeper, root)
                said.append('%s is %d folders deep (the reader looks for a report %d folders deep at most)'
                            % (archives.shown_name(relative if shown is None else '%s/%s' % (shown, relative)),
                               relative.count(os.sep), MAX_DEPTH + 1))
                break
        said.extend('%s is an archive inside archives, not searched for a report (the reader opens archives %d '
                    'deep at most)' % (archives.shown_name(name), MAX_NESTING) for _, name in nested[:1])
        notes.extend(said)
    unique = []
    for name, full in found:
        digest = _digest(full)
        if digest is not None and digest in seen:
            notes.append('%s: the same file as %s, read once' % (archives.shown_name(name), archives.shown_name(seen[digest])))
            continue
        seen[digest] = name
        unique.append((name, full))
    if len(unique) > REPORT_FILES:
        notes.append('%d report files (at most %d): the first %d are read' % (len(unique), REPORT_FILES, REPORT_FILES))
    return unique[:REPORT_FILES]


def _digest(path):
    try:
        with open(path, 'rb') as f:
            return hashlib.sha256(f.read(FILE_BYTES + 1)).hexdigest()
    except OSError:
        return None

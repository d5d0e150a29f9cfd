"""The only reader of what a box hands back: capped, never followed, a record checked by its schema.

Root reads what a box leaves only here: its record (:func:`read_record`), its logs and the files
kept for the teacher (:func:`read_capped`, :func:`copy_results`). Every file is opened with
``O_NOFOLLOW | O_NONBLOCK`` (a link, even to a root-only file, is refused; a FIFO never blocks) and must
be a regular file. A record is at most ``max_bytes`` and its bytes go to the record type's
``from_json`` (:mod:`exam_lab.grader.score.records`), which raises
:class:`~exam_lab.grader.score.records.RecordError` on anything unexpected; a log keeps its first and
last ``LOG_PART`` bytes.
"""
import errno
import os
import stat

from exam_lab.grader.score.records import RecordError

#: Most bytes of a box's record (PrairieLearn caps its results.json at 1 MB too).
MAX_RECORD_BYTES = 1 << 20
#: What of a log reaches the results: its first and last LOG_PART bytes.
LOG_PART = 256 << 10
#: Most bytes of a file other than a log (JSON) copied to the results.
FILE_CAP = 4 << 20
#: How a file a box wrote is opened: never through a link, never waiting on a FIFO.
_READ_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK


def read_record(path, record_type, max_bytes=MAX_RECORD_BYTES):
    """The record of type ``record_type`` in the file ``path`` (written by a box); raises
    :class:`RecordError` when it is missing, not a regular file, larger than ``max_bytes`` or not a
    record of that type."""
    name = os.path.basename(path)
    try:
        fd = os.open(path, _READ_FLAGS)
    except OSError as err:
        why = {errno.ELOOP: 'a link, not followed', errno.ENOENT: 'missing'}.get(err.errno, err.strerror)
        raise RecordError('%s: %s' % (name, why))
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise RecordError('%s: not a regular file' % name)
        if info.st_size > max_bytes:
            raise RecordError('%s: %d bytes (at most %d)' % (name, info.st_size, max_bytes))
        chunks, size = [], 0
        while size <= max_bytes:  # the file may still grow if something of the box lives: never past the cap
            chunk = os.read(fd, max_bytes + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    finally:
        os.close(fd)
    return record_type.from_json(b''.join(chunks), max_bytes)


def read_capped(path, part=LOG_PART):
    """A file's text, its middle cut when longer than ``2 * part`` bytes (saying so); None when
    ``path`` is not a regular file (a link, FIFO or device is never followed or opened for reading:
    opened with O_NOFOLLOW | O_NONBLOCK and checked with fstat)."""
    try:
        fd = os.open(path, _READ_FLAGS)
    except OSError as err:
        if err.errno in (errno.ELOOP, errno.ENXIO, errno.ENOENT, errno.EACCES):
            return None
        raise
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            return None
        with os.fdopen(os.dup(fd), 'rb') as f:
            if info.st_size <= 2 * part:
                data = f.read(2 * part)
            else:
                head = f.read(part)
                f.seek(info.st_size - part)
                cut = info.st_size - 2 * part
                data = head + ('\n[... %d bytes cut by the grader: this log keeps its first and last %d KB '
                               'of %d bytes ...]\n' % (cut, part >> 10, info.st_size)).encode() + f.read(part)
        return data.decode('utf-8', 'replace')
    finally:
        os.close(fd)


def copy_results(source, target, suffixes=('.log', '.json', '.md'), part=LOG_PART):
    """Copy the regular files of ``source`` (not its sub-folders) ending in ``suffixes`` to ``target``,
    each capped by :func:`read_capped`; a link, FIFO or device is skipped. Returns the names skipped."""
    os.makedirs(target, exist_ok=True)
    skipped = []
    for name in sorted(os.listdir(source)):
        if not name.endswith(suffixes) or '\n' in name:
            continue
        text = read_capped(os.path.join(source, name), part if name.endswith('.log') else FILE_CAP)
        if text is None:
            skipped.append(name)
            continue
        with open(os.path.join(target, name), 'w') as f:
            f.write(text)
    return skipped


def read_bytes(path, max_bytes):
    """The bytes of the regular file ``path`` (a box's), or None when it is missing, not a regular file
    (never followed, never blocking) or over ``max_bytes``: a file kept for the teacher whole or not at all."""
    try:
        fd = os.open(path, _READ_FLAGS)
    except OSError:
        return None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode) or info.st_size > max_bytes:
            return None
        chunks, size = [], 0
        while size <= max_bytes:
            chunk = os.read(fd, max_bytes + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
        return b''.join(chunks) if size <= max_bytes else None
    finally:
        os.close(fd)


def copy_tree(source, target, max_files, max_bytes):
    """Copy the folder ``source`` (a box's) to ``target``: its folders and regular files, each read by
    :func:`read_bytes`, at most ``max_files`` files and ``max_bytes`` in all; links, FIFOs, devices and
    files past the caps are left out. Returns the relative names left out."""
    skipped, budget = [], {'files': max_files, 'bytes': max_bytes}
    os.makedirs(target)
    for dirpath, dirnames, filenames in os.walk(source):
        rel = os.path.relpath(dirpath, source)
        for name in sorted(dirnames):
            if os.path.islink(os.path.join(dirpath, name)) or '\n' in name:
                skipped.append(os.path.normpath(os.path.join(rel, name)))
                dirnames.remove(name)
            else:
                os.mkdir(os.path.join(target, rel, name))
        dirnames.sort()
        for name in sorted(filenames):
            shown = os.path.normpath(os.path.join(rel, name))
            data = None if budget['files'] <= 0 or '\n' in name else \
                read_bytes(os.path.join(dirpath, name), budget['bytes'])
            if data is None:
                skipped.append(shown)
                continue
            budget['files'] -= 1
            budget['bytes'] -= len(data)
            with open(os.path.join(target, rel, name), 'xb') as f:
                f.write(data)
    return skipped

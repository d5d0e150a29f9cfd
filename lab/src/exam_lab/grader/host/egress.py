"""The only reader of what a box hands back: one capped file, never followed, checked by its schema.

Root reads a box's output folder only here (and its logs only through
:func:`~exam_lab.grader.host.sandbox.read_capped`): the file is opened with ``O_NOFOLLOW | O_NONBLOCK``
(a link, even to a root-only file, is refused; a FIFO never blocks), must be a regular file of at most
``max_bytes``, and its bytes go to the record type's ``from_json`` (:mod:`exam_lab.grader.score.records`),
which raises :class:`~exam_lab.grader.score.records.RecordError` on anything unexpected.
"""
import errno
import os
import stat

from exam_lab.grader.score.records import RecordError

#: Most bytes of a box's record (PrairieLearn caps its results.json at 1 MB too).
MAX_RECORD_BYTES = 1 << 20


def read_record(path, record_type, max_bytes=MAX_RECORD_BYTES):
    """The record of type ``record_type`` in the file ``path`` (written by a box); raises
    :class:`RecordError` when it is missing, not a regular file, larger than ``max_bytes`` or not a
    record of that type."""
    name = os.path.basename(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
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

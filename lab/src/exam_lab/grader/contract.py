"""The contract between the trust levels: the one way root reads a file it did not write in this
process, and the one way root writes a file in OUT. No rospy here.

What root did not write in this process is foreign, whoever wrote it: a box's or the judge's record
and logs, and every file kept in OUT (grade.json, measurements.json, similarity.json, hand.csv, the
desk's page.json, the report's and the proposals' records). An OUT restored from an archive or handed
over by a colleague is as foreign as a box's output. So every one of them is read here, and only here:

- **no link followed**: the file is opened with ``O_NOFOLLOW``, and so is every folder between the
  folder it is read *under* (``under``: OUT, a box's out folder, the teacher's path, followed; by
  default the file's own folder, itself no link) and the file, each relative to the one above (``dir_fd``): a student's folder of OUT that is a link to
  elsewhere is refused, never read through;
- **regular files only** (``fstat`` of what was opened, never a ``stat`` before it), **never blocking**
  (``O_NONBLOCK``: a FIFO in place of grade.json is refused at once, never waited on);
- **capped**: never more than the caller's cap is read, whatever the file's size says (it may grow);
- **checked against its type**: a record's bytes go to its type's ``from_json`` (capped, checked by its
  schema, its text cleaned once, there); a text (hand.csv) is decoded here once, strictly.

Every refusal is a :class:`ContractError` (a :class:`~exam_lab.grader.score.records.RecordError`)
naming the file and why, so a caller says "that student's file" and goes on.

Every file root writes in OUT is written by :func:`write_bytes` (and its :func:`write_text`,
:func:`write_record`): a temporary file made in the same folder (``O_EXCL | O_NOFOLLOW``), filled,
then ``os.replace``\\ d onto the name, relative to that folder's descriptor: a reader finds the whole
file or the one before it, and an entry already there (a ``grade.md`` that is a link to a file of the
teacher's) is replaced, never written through. A student's folder is one of the folders listed in OUT
(:func:`folders`, :func:`student_folder`), never one a record's field names.
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
_CLOEXEC = getattr(os, 'O_CLOEXEC', 0)
#: How a foreign file is opened: never through a link, never waiting on a FIFO.
_READ_FLAGS = os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK | _CLOEXEC
#: How a folder on the way is opened: a folder, never through a link.
_DIR_FLAGS = os.O_RDONLY | os.O_DIRECTORY | os.O_NOFOLLOW | _CLOEXEC
_WHY = {errno.ELOOP: 'a link, not followed', errno.ENOENT: 'missing', errno.ENOTDIR: 'a link or no folder on its way, not followed',
        errno.ENXIO: 'not a regular file', errno.EACCES: 'not readable'}


class ContractError(RecordError):
    """A foreign file refused: the file and why."""


def _shown(path, under):
    return os.path.relpath(path, under) if under else os.path.basename(path)


def _parts(path, under):
    """The names from ``under`` down to ``path``'s folder, and ``path``'s own name."""
    path, under = os.path.abspath(path), os.path.abspath(under)
    relative = os.path.relpath(path, under)
    parts = relative.split(os.sep)
    if relative.startswith('..') or os.path.isabs(relative) or '..' in parts or relative == '.':
        raise ContractError('%s: not below %s' % (path, under))
    return parts[:-1], parts[-1]


def _folder_fd(path, under):
    """``(descriptor of path's folder, path's name)``: ``under`` opened as the caller named it (the
    teacher's path, followed), each folder below it without following a link."""
    if under is None:  # the file's own folder, itself no link
        fd = os.open(os.path.dirname(os.path.abspath(path)), _DIR_FLAGS)
        return fd, os.path.basename(path)
    between, name = _parts(path, under)
    fd = os.open(under, os.O_RDONLY | os.O_DIRECTORY | _CLOEXEC)
    try:
        for part in between:
            inner = os.open(part, _DIR_FLAGS, dir_fd=fd)
            os.close(fd)
            fd = inner
    except OSError:
        os.close(fd)
        raise
    return fd, name


def _open(path, under):
    """A descriptor of the regular file ``path`` (see the module's rules); raises ContractError."""
    try:
        folder, name = _folder_fd(path, under)
    except OSError as err:
        raise ContractError('%s: %s' % (_shown(path, under), _WHY.get(err.errno, err.strerror)))
    try:
        fd = os.open(name, _READ_FLAGS, dir_fd=folder)
    except OSError as err:
        raise ContractError('%s: %s' % (_shown(path, under), _WHY.get(err.errno, err.strerror)))
    finally:
        os.close(folder)
    info = os.fstat(fd)
    if not stat.S_ISREG(info.st_mode):
        os.close(fd)
        raise ContractError('%s: not a regular file' % _shown(path, under))
    return fd, info


def exists(path, under=None):
    """Whether there is an entry at ``path`` (of any kind: a link or a FIFO is there, for a reader to
    refuse with why), the folders from ``under`` down followed by no link."""
    try:
        folder, name = _folder_fd(path, under)
    except (OSError, ContractError):
        return False
    try:
        os.stat(name, dir_fd=folder, follow_symlinks=False)
        return True
    except OSError:
        return False
    finally:
        os.close(folder)


def read_bytes(path, cap, under=None):
    """The bytes of the foreign file ``path``, at most ``cap``; raises ContractError (a link, not a
    regular file, missing, larger than ``cap``)."""
    fd, info = _open(path, under)
    try:
        if info.st_size > cap:
            raise ContractError('%s: %d bytes (at most %d)' % (_shown(path, under), info.st_size, cap))
        chunks, size = [], 0
        while size <= cap:  # the file may still grow if something of the box lives: never past the cap
            chunk = os.read(fd, cap + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    finally:
        os.close(fd)
    raw = b''.join(chunks)
    if len(raw) > cap:
        raise ContractError('%s: more than %d bytes' % (_shown(path, under), cap))
    return raw


def read_record(path, record_type, max_bytes=None, under=None):
    """The record of type ``record_type`` in the foreign file ``path``: read by :func:`read_bytes` up
    to ``max_bytes`` (the type's ``MAX_BYTES`` when None), then its type's ``from_json`` (checked, its
    text cleaned); raises RecordError naming the file."""
    cap = record_type.MAX_BYTES if max_bytes is None else max_bytes
    return record_type.from_json(read_bytes(path, cap, under), cap)  # its errors name the file's fields


def read_text(path, cap, under=None):
    """The UTF-8 text of the foreign file ``path`` (a byte-order mark dropped: a spreadsheet adds one),
    at most ``cap`` bytes; raises ContractError, also for bytes that are not UTF-8."""
    raw = read_bytes(path, cap, under)
    try:
        return raw.decode('utf-8-sig')
    except UnicodeDecodeError as err:
        raise ContractError('%s: not UTF-8 text (byte %d)' % (_shown(path, under), err.start))


def read_capped(path, part=LOG_PART, under=None):
    """A foreign log's text, its middle cut when longer than ``2 * part`` bytes (saying so); None when
    ``path`` is missing or not a regular file (a link, FIFO or device is never followed nor waited on)."""
    try:
        fd, info = _open(path, under)
    except ContractError:
        return None
    with os.fdopen(fd, 'rb') as f:
        if info.st_size <= 2 * part:
            data = f.read(2 * part)
        else:
            head = f.read(part)
            f.seek(info.st_size - part)
            cut = info.st_size - 2 * part
            data = head + ('\n[... %d bytes cut by the grader: this log keeps its first and last %d KB '
                           'of %d bytes ...]\n' % (cut, part >> 10, info.st_size)).encode() + f.read(part)
    return data.decode('utf-8', 'replace')


def copy_results(source, target, suffixes=('.log', '.json', '.md'), part=LOG_PART):
    """Copy the regular files of the foreign folder ``source`` (not its sub-folders) ending in
    ``suffixes`` to ``target``, each capped by :func:`read_capped` and written by :func:`write_text`; a
    link, FIFO or device is skipped. Returns the names skipped."""
    make_folder(target)
    skipped = []
    for name in sorted(os.listdir(source)):
        if not name.endswith(suffixes) or '\n' in name:
            continue
        text = read_capped(os.path.join(source, name), part if name.endswith('.log') else FILE_CAP)
        if text is None:
            skipped.append(name)
            continue
        write_text(os.path.join(target, name), text)
    return skipped


def copy_tree(source, target, max_files, max_bytes):
    """Copy a box's folder ``source`` to the new folder ``target``: its folders and regular files, each
    read by :func:`read_bytes`, at most ``max_files`` files and ``max_bytes`` in all; links, FIFOs,
    devices and files past the caps are left out. Returns the relative names left out."""
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
            try:
                if budget['files'] <= 0 or '\n' in name:
                    raise ContractError(shown)
                data = read_bytes(os.path.join(dirpath, name), budget['bytes'])
            except ContractError:
                skipped.append(shown)
                continue
            budget['files'] -= 1
            budget['bytes'] -= len(data)
            write_bytes(os.path.join(target, rel, name), data)
    return skipped


def folders(out):
    """The names of the folders in ``out``, sorted: real folders only (a link, even to a folder, is
    none); the folders a reader of OUT takes students from."""
    names = []
    for name in sorted(os.listdir(out)):
        try:
            if stat.S_ISDIR(os.lstat(os.path.join(out, name)).st_mode):
                names.append(name)
        except OSError:
            continue
    return names


def student_folder(out, name):
    """``out/name`` when ``name`` is one folder's name of ``out`` (one component, no link); raises
    ContractError otherwise: a name a record holds never becomes a path elsewhere."""
    if not name or name in ('.', '..') or '/' in name or '\0' in name:
        raise ContractError('%r is not a folder of %s' % (name, out))
    path = os.path.join(out, name)
    if os.path.islink(path):
        raise ContractError('%s: a link, not followed' % name)
    return path


def make_folder(path, under=None):
    """Make the folder ``path`` (and those above it, below ``under``) as :func:`os.makedirs`, but
    refuse one on the way that is a link (ContractError): nothing is written through it."""
    if under is None:  # the folder's own parent followed (the caller's), the folder itself no link
        under = os.path.dirname(os.path.abspath(path))
    if os.path.abspath(path) == os.path.abspath(under):
        os.makedirs(path, exist_ok=True)
        if os.path.islink(path):
            raise ContractError('%s: a link, not followed' % path)
        return
    between, name = _parts(path, under)
    os.makedirs(under, exist_ok=True)
    fd = os.open(under, os.O_RDONLY | os.O_DIRECTORY | _CLOEXEC)
    try:
        for part in between + [name]:
            try:
                os.mkdir(part, 0o755, dir_fd=fd)
            except FileExistsError:
                pass
            try:
                inner = os.open(part, _DIR_FLAGS, dir_fd=fd)
            except OSError as err:
                raise ContractError('%s: %s' % (_shown(path, under), _WHY.get(err.errno, err.strerror)))
            os.close(fd)
            fd = inner
    finally:
        os.close(fd)


def write_bytes(path, data, under=None, mode=0o644):
    """Write ``data`` as the file ``path`` of OUT, whole or not at all: a temporary file in its folder,
    then ``os.replace`` onto the name (an entry there, a link included, is replaced, never written
    through). The folders from ``under`` (default: ``path``'s own folder) down are made when missing
    and followed by no link (ContractError)."""
    make_folder(os.path.dirname(os.path.abspath(path)), under)
    try:
        fd, name = _folder_fd(path, under)
    except OSError as err:
        raise ContractError('%s: %s' % (_shown(path, under), _WHY.get(err.errno, err.strerror)))
    try:
        temporary = '.%s.%d.part' % (name, os.getpid())
        try:
            os.unlink(temporary, dir_fd=fd)
        except FileNotFoundError:
            pass
        out = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | _CLOEXEC, mode, dir_fd=fd)
        try:
            with os.fdopen(out, 'wb') as f:
                f.write(data)
            os.replace(temporary, name, src_dir_fd=fd, dst_dir_fd=fd)
        except BaseException:
            try:
                os.unlink(temporary, dir_fd=fd)
            except OSError:
                pass
            raise
    finally:
        os.close(fd)


def write_text(path, text, under=None):
    """:func:`write_bytes` of ``text`` in UTF-8 (a name in bytes that are not UTF-8 kept as they were)."""
    write_bytes(path, text.encode('utf-8', 'surrogateescape'), under)


def write_record(path, record, under=None):
    """:func:`write_bytes` of a record's JSON (``record.to_json()``), one line at its end."""
    write_text(path, record.to_json() + '\n', under)

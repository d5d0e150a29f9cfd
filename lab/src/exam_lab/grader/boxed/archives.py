"""One archive a student uploaded, unpacked after checking every entry. No rospy here.

Nothing in a submission is trusted. An archive (zip, tar, tar.gz/tgz, tar.bz2, tar.xz) is refused as
a whole, with the reason for the teacher, when an entry would land outside the target (``../``, an
absolute path, a drive letter), when a name holds a control character or is beyond the file system's
limits, or when the submission's one budget of bytes and files (every archive of it, nested ones
included) would be exceeded or an entry expands like a zip bomb. What students really upload is not
refused for its form: Windows names (backslashes) and missing Unix modes are read as meant, a zip's
names as its maker wrote them (:func:`zip_name`), its folders' own entries as folders
(:func:`zip_entries`), macOS's ``__MACOSX/`` and ``._`` copies are skipped, a whole workspace's build
products (``build/``, ``devel/``...) are dropped, links (catkin's ``src/CMakeLists.txt``) and special
files are dropped, never followed; each is noted.

Every archive is read in two passes: its entries are planned (:class:`Plan`: checked, charged,
what is dropped noted) before anything is written (:func:`write_plan`).
"""
import os
import re
import stat
import struct
import tarfile
import zipfile
import zlib

# The names both sides of the box read alike, and the refusal both raise: the box's modules take them here.
from exam_lab.grader.score.names import (  # noqa: F401
    ARCHIVE_ENDINGS, BUILD_PRODUCTS, SKIPPED_DIRS, SKIPPED_ON_UNPACK, without_ending)
from exam_lab.grader.score.records import UnpackError  # noqa: F401

#: Most files one submission may unpack, all its archives together (a package has tens).
MAX_FILES = 5000
#: Most bytes one submission may unpack, all its archives together.
MAX_BYTES = 200 * 1024 * 1024
#: Highest ratio of unpacked to packed size of one zip entry (text compresses ~5x; bombs 1000x), judged
#: only for an entry larger than RATIO_FROM_BYTES: below it the budget bounds what an entry costs, and
#: a log or a one-colour screenshot of a few MB compresses 1000x without being a bomb.
MAX_RATIO = 200
RATIO_FROM_BYTES = 16 * 1024 * 1024
#: Linux limits on a name: bytes of one path component, bytes of a whole path.
NAME_MAX = 255
PATH_MAX = 4096
#: Most folders one entry's path may hold (a package is a few deep; a workspace's a few more).
MAX_PARTS = 64
#: The magic bytes of the archives the grader cannot open.
_UNSUPPORTED = ((b'Rar!\x1a\x07', 'a RAR archive'), (b'7z\xbc\xaf\x27\x1c', 'a 7-Zip archive'),
                (b'\x1f\x8b', 'a gzip file that holds no tar'), (b'BZh', 'a bzip2 file that holds no tar'),
                (b'\xfd7zXZ\x00', 'an xz file that holds no tar'), (b'%PDF', 'a PDF document'))
_KIND_WORDS = {'zip': 'zip', 'tar': 'tar archive'}
#: What reading an entry's bytes raises when the archive cannot give them: encrypted (a password-protected
#: zip), corrupt (a bad CRC, a cut file), or compressed as zipfile cannot read.
UNREADABLE = (zipfile.BadZipFile, tarfile.TarError, zlib.error, EOFError, OSError, RuntimeError, NotImplementedError)
#: A byte that is not UTF-8 as repr() shows its surrogate escape (``\\udcff``).
_ESCAPED_BYTE = re.compile(r'(?<!\\)((?:\\\\)*)\\udc([89a-f][0-9a-f])')  # not after an escaped backslash
#: At most this many notes of one kind (links dropped, duplicates) are listed; the rest are counted.
MAX_LISTED = 5
#: A zip entry's general purpose bit 11: its name (and comment) are UTF-8 (APPNOTE.TXT 4.4.4).
_ZIP_UTF8 = 0x800
#: The Info-ZIP Unicode Path Extra Field (APPNOTE.TXT 4.6.9): version 1, the CRC-32 of the name field
#: it stands for, the name in UTF-8.
_ZIP_UNICODE_PATH = 0x7075


class Budget(object):
    """What one submission may unpack, every archive of it together, nested ones included: a zip of
    zips cannot multiply the limits by the number of inner archives."""

    def __init__(self, max_bytes=MAX_BYTES, max_files=MAX_FILES):
        self.bytes_left = max_bytes
        self.files_left = max_files
        self.max_bytes = max_bytes
        self.max_files = max_files

    def take(self, files, nbytes, what):
        """Charge an archive's files and bytes, or raise UnpackError (nothing charged) if too many."""
        if files > self.files_left:
            raise UnpackError('%s: %d more files, beyond the %d a submission may unpack'
                              % (what, files, self.max_files))
        if nbytes > self.bytes_left:
            raise UnpackError('%s: %d more bytes, beyond the %d a submission may unpack'
                              % (what, nbytes, self.max_bytes))
        self.files_left -= files
        self.bytes_left -= nbytes


def shown_name(name, limit=80):
    """An archive entry's name as it may be printed: escaped (a newline cannot inject a line; a byte
    that is not UTF-8, kept by surrogateescape, reads ``\\xNN`` as everywhere else), cut."""
    text = _ESCAPED_BYTE.sub(r'\1\\x\2', repr(name))
    return text if len(text) <= limit else text[:limit - 5] + '...' + text[-2:]


def listed(names):
    """The first MAX_LISTED of ``names``, and how many more."""
    shown = ', '.join(names[:MAX_LISTED])
    return shown + (' and %d more' % (len(names) - MAX_LISTED) if len(names) > MAX_LISTED else '')


def name_parts(name):
    """The parts of an archive entry's name as written, before any check, and whether it is rooted (an
    absolute path, a drive letter). Archives made on Windows sometimes use backslashes: separators too
    (a Linux name holding one is no student's)."""
    path = name.replace('\\', '/')
    return [p for p in path.split('/') if p not in ('', '.')], path.startswith('/') or path[1:2] == ':'


def entry_path(name):
    """The parts of an archive entry's path, or raise UnpackError if it is unsafe or unwritable."""
    if any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise UnpackError('entry %s has a control character in its name' % shown_name(name))
    parts, rooted = name_parts(name)
    if rooted:
        raise UnpackError('entry %s has an absolute path' % shown_name(name))
    if '..' in parts:
        raise UnpackError('entry %s climbs out of the folder (..)' % shown_name(name))
    if len(parts) > MAX_PARTS:
        raise UnpackError('entry %s is %d folders deep (at most %d)' % (shown_name(name), len(parts), MAX_PARTS))
    if len(name.encode('utf-8', 'surrogateescape')) > PATH_MAX:
        raise UnpackError('entry %s has a path of more than %d bytes' % (shown_name(name), PATH_MAX))
    for part in parts:
        if len(part.encode('utf-8', 'surrogateescape')) > NAME_MAX:
            raise UnpackError('entry %s has a name of more than %d bytes' % (shown_name(name), NAME_MAX))
    return parts


class Plan(object):
    """The entries of one archive (or of one student's part of a class archive) that will be written,
    and what was dropped, before writing any."""

    def __init__(self, label):
        self.label = label
        self.files = []        # (member, parts, size)
        self.dirs = []         # parts
        self.products = {}     # the path of a dropped build-product folder -> entries in it
        self.links = []        # (name, target)
        self.special = []      # names of FIFOs, devices
        self.seen = {}         # parts -> count
        self.folded = {}       # lower-cased parts -> parts first seen

    @property
    def nbytes(self):
        """Bytes the planned files declare."""
        return sum(size for _, _, size in self.files)

    def add(self, member, name, kind, size, link_target=''):
        parts = entry_path(name)
        if not parts or parts[0] == '__MACOSX':
            return
        skipped = [i for i, p in enumerate(parts) if p in SKIPPED_ON_UNPACK]
        if skipped:
            i = skipped[0]
            if parts[i] in BUILD_PRODUCTS:
                key = '/'.join(parts[:i + 1]) + '/'
                self.products[key] = self.products.get(key, 0) + 1
            return
        if kind == 'link':
            self.links.append(('/'.join(parts), link_target))
            return
        if kind == 'special':
            self.special.append('/'.join(parts))
            return
        if kind == 'dir':
            self.dirs.append(parts)
            return
        key = tuple(parts)
        self.seen[key] = self.seen.get(key, 0) + 1
        folded = tuple(p.lower() for p in parts)
        self.folded.setdefault(folded, set()).add(key)
        self.files.append((member, parts, size))

    def notes(self):
        """What the teacher should know of this archive: what was dropped, duplicates, case clashes."""
        out = []
        if self.products:
            out.append('%s: build products of a workspace not unpacked: %s' % (self.label, ', '.join(
                '%s (%d entries)' % (k, n) for k, n in sorted(self.products.items()))))
        if self.special:
            out.append('%s: %d special file(s) (FIFO, device) dropped: %s' % (
                self.label, len(self.special), listed([shown_name(n) for n in self.special])))
        duplicates = sorted('/'.join(k) for k, n in self.seen.items() if n > 1)
        if duplicates:
            out.append('%s: %d entr(ies) appear more than once, the last one kept: %s' % (
                self.label, len(duplicates), listed([shown_name(n) for n in duplicates])))
        clashes = sorted(' / '.join(sorted('/'.join(k) for k in keys)) for keys in self.folded.values()
                         if len(keys) > 1)
        if clashes:
            out.append('%s: names that differ only by case (one file on Windows or macOS): %s' % (
                self.label, listed(clashes)))
        return out

    def link_notes(self):
        """The links dropped: a change to what the student uploaded (catkin's own link is harmless)."""
        catkin = [n for n, _ in self.links if n.endswith('src/CMakeLists.txt') or n == 'CMakeLists.txt']
        other = [(n, t) for n, t in self.links if n not in catkin]
        out = []
        if catkin:
            out.append('%s: catkin\'s link %s dropped (links are never followed; the grader makes its '
                       'own workspace)' % (self.label, ', '.join(shown_name(n) for n in catkin)))
        if other:
            out.append('%s: %d link(s) dropped, never followed: %s' % (self.label, len(other), listed(
                ['%s -> %s' % (shown_name(n), shown_name(t, 60)) for n, t in other])))
        return out


def archive_kind(path):
    """'zip', 'tar', or None when ``path`` is neither (also when it cannot be read)."""
    try:
        if zipfile.is_zipfile(path):
            return 'zip'
        if tarfile.is_tarfile(path):
            return 'tar'
    except OSError:
        pass
    return None


def what_it_is(path):
    """Words for a file the grader cannot open ("a RAR archive"), or None when unknown."""
    try:
        with open(path, 'rb') as f:
            head = f.read(8)
    except OSError:
        return None
    for magic, words in _UNSUPPORTED:
        if head.startswith(magic):
            return words
    return None


def open_archive(path, label):
    """``(kind, the open zipfile.ZipFile or tarfile.TarFile)`` of the archive ``path``; UnpackError,
    saying what it is and what the grader opens, when it is neither or cannot be read."""
    kind = archive_kind(path)
    try:
        if kind == 'zip':
            return kind, zipfile.ZipFile(path)
        if kind == 'tar':
            return kind, tarfile.open(path, 'r:*')
    except (zipfile.BadZipFile, tarfile.TarError, OSError, EOFError) as err:
        raise UnpackError('%s is not a readable %s: %s' % (label, _KIND_WORDS[kind], err))
    except UnicodeDecodeError as err:  # zipfile reads every name as it opens: one flagged UTF-8 that is not
        raise UnpackError('%s is not a readable zip: an entry\'s name is said to be UTF-8 and is not (byte \\x%02x; '
                          'made by a tool whose locale was not the names\' own): ask for it zipped again'
                          % (label, err.object[err.start]))
    raise UnpackError('%s is %s: the grader opens zip and tar archives (%s); ask for a zip'
                      % (label, what_it_is(path) or 'not a readable zip or tar archive', ', '.join(ARCHIVE_ENDINGS)))


def zip_entries(zf, links=True):
    """``(member, name, kind, size, link target)`` of each entry of the open zip ``zf``; kind 'file',
    'dir' or 'link' (the target read only when ``links``, else '?'); the name is :func:`zip_name`'s.

    A folder's own entry (``zip -r``, Windows' "compressed folder", 7-Zip, macOS's ``ditto`` all write
    one, its name ending with ``/``, ``\\`` on some Windows tools) is a 'dir', never a file. The
    ``._<name>`` copy macOS's ``ditto`` writes beside an entry ``<name>`` (an AppleDouble file: its
    Finder data, no content of the student's) is skipped, as its ``__MACOSX/`` folder is."""
    infos = [(info, zip_name(info)) for info in zf.infolist()]
    doubles = _apple_doubles([name for _, name in infos])
    for info, name in infos:
        if name in doubles:
            continue
        if stat.S_ISLNK(_zip_mode(info, 0o170000)):
            yield info, name, 'link', 0, _zip_link_target(zf, info) if links else '?'
        elif name.endswith(('/', '\\')):
            yield info, name, 'dir', 0, ''
        else:
            yield info, name, 'file', info.file_size, ''


def zip_name(info):
    """The name of the zip entry ``info`` as its maker meant it, whatever Python's zipfile made of it.

    A name flagged UTF-8 (bit 11) is UTF-8. Without the flag, APPNOTE.TXT says cp437 (zipfile decodes it
    so), but the usual tools write the bytes of their own system: Info-ZIP's ``zip`` on Linux and macOS
    writes UTF-8 unflagged when it finds no UTF-8 locale, tools on Windows a code page, 7-Zip (and
    Info-ZIP's zip on Windows) with an Info-ZIP Unicode Path Extra Field holding the UTF-8 name. So:
    that field when it is valid (version 1, its CRC-32 that of the name field, UTF-8), else the bytes as
    UTF-8 when they are, else cp437. The name is zipfile's ``orig_filename``, whatever the Python
    (3.12's reads that field itself) and not cut at a NUL byte (:func:`entry_path` refuses it)."""
    if info.flag_bits & _ZIP_UTF8:
        return info.orig_filename
    raw = info.orig_filename.encode('cp437')  # zipfile decoded the name field as cp437: its bytes again
    for name in (_unicode_path(info.extra, raw), raw):
        if name is not None:
            try:
                return name.decode('utf-8')
            except UnicodeDecodeError:
                pass
    return info.orig_filename


def _unicode_path(extra, raw):
    """The UTF-8 bytes of the Unicode Path Extra Field among a zip entry's ``extra`` fields that stands
    for the name field ``raw``, or None (none, another version, or one written for another name: a tool
    that renamed the entry and left the field)."""
    while len(extra) >= 4:
        kind, size = struct.unpack('<HH', extra[:4])
        data, extra = extra[4:4 + size], extra[4 + size:]
        if kind == _ZIP_UNICODE_PATH and len(data) > 5 and data[0] == 1 and \
                struct.unpack('<L', data[1:5])[0] == zlib.crc32(raw) & 0xffffffff:
            return data[5:]
    return None


def _apple_doubles(names):
    """The names among an archive's ``names`` that are macOS's AppleDouble copies: ``<folder>/._<name>``
    where ``<folder>/<name>`` is an entry (or a folder) of the same archive."""
    split = [(name, tuple(name_parts(name)[0])) for name in names]
    paths = set(parts[:i] for _, parts in split for i in range(1, len(parts) + 1))
    return set(name for name, parts in split
               if parts and parts[-1].startswith('._') and parts[:-1] + (parts[-1][2:],) in paths)


def tar_entries(tf):
    """``(member, name, kind, size, link target)`` of each entry of the open tar ``tf``, read as it is
    listed (a compressed tar is decompressed only as far as the caller goes)."""
    for member in tf:
        kind = 'link' if member.issym() or member.islnk() else 'dir' if member.isdir() else \
            'file' if member.isfile() else 'special'
        yield member, member.name, kind, member.size if kind == 'file' else 0, member.linkname


def _zip_mode(info, mask=0o777):
    """The Unix mode bits of a zip entry under ``mask``; 0 when the zip was not made on Unix."""
    return (info.external_attr >> 16) & mask if info.create_system == 3 else 0


def _tar_mode(member):
    """The permission bits of a tar entry."""
    return member.mode & 0o777


def _zip_link_target(zf, info):
    """What a zip's link points to, for the teacher's note; '?' when it is long or cannot be read."""
    if info.file_size > 4096:
        return '?'
    try:
        return zf.read(info).decode('utf-8', 'replace')
    except UNREADABLE:
        return '?'


def safe_extract(archive, target, max_files=MAX_FILES, max_bytes=MAX_BYTES, max_ratio=MAX_RATIO,
                 budget=None, notes=None, fixes=None):
    """Unpack the zip or tar ``archive`` into ``target`` after checking every entry; return the number
    of files written.

    The whole archive is refused (UnpackError) before anything is written if any entry is unsafe or the
    ``budget`` (a new one of ``max_files`` / ``max_bytes`` when None) cannot pay for it; an entry whose
    bytes cannot be read (:data:`UNREADABLE`: a password, a bad CRC) refuses it while it is written,
    what was written left in ``target`` (a scratch folder no caller searches once refused). ``notes``
    receives what was dropped (build products, special files) and duplicates; ``fixes`` the dropped
    links (``notes`` when None).
    """
    budget = budget or Budget(max_bytes, max_files)
    notes = [] if notes is None else notes
    fixes = notes if fixes is None else fixes
    label = os.path.basename(archive)
    kind, opened = open_archive(archive, label)
    with opened:
        plan = _plan_zip(opened, label, max_ratio) if kind == 'zip' else _plan_tar(opened, label, budget)
        budget.take(len(plan.files), plan.nbytes, label)
        try:
            write_plan(plan, target, kind, opened)
        except UNREADABLE as err:
            raise UnpackError('%s cannot be unpacked: %s' % (label, unreadable_why(err)))
    notes.extend(plan.notes())
    fixes.extend(plan.link_notes())
    return len(plan.files)


def unreadable_why(err):
    """Words for the teacher on an error of :data:`UNREADABLE`."""
    if isinstance(err, RuntimeError) and 'encrypted' in str(err):  # zipfile: "File ... is encrypted, ..."
        return 'it is encrypted (made with a password): ask for it without one'
    return str(err)


def _plan_zip(zf, label, max_ratio):
    plan = Plan(label)
    for entry in zip_entries(zf):
        plan.add(*entry)
    for info, _, size in plan.files:
        if size > RATIO_FROM_BYTES and size > max_ratio * max(info.compress_size, 1024):
            raise UnpackError('entry %s unpacks %d bytes from %d, more than %d times its size (the most an '
                              'entry over %d MB may): a zip bomb?' % (shown_name(zip_name(info)), size, info.compress_size,
                                                                     max_ratio, RATIO_FROM_BYTES >> 20))
    return plan


def _plan_tar(tf, label, budget):
    """Member by member, charging as it goes: a compressed tar is read (decompressed) only as far as the
    budget allows, dropped build products included."""
    plan, read = Plan(label), 0
    try:
        for entry in tar_entries(tf):
            read += entry[0].size
            if read > budget.bytes_left or len(plan.files) > budget.files_left:
                budget.take(len(plan.files) + 1, read, label)  # raises with the reason
            plan.add(*entry)
    except (tarfile.TarError, OSError, EOFError) as err:
        raise UnpackError('%s is not a readable tar archive: %s' % (label, err))
    return plan


def write_plan(plan, target, kind, opened):
    """Write the files of ``plan`` (entries of ``opened``, the open archive of ``kind``: 'zip' or 'tar')
    below ``target``, each capped at the size its entry declares. A file keeps the permission bits its
    entry records, always readable and writable by its owner: whether a script was executable is a
    fact of the grade, so a class archive keeps them as a student's does (they are set, so no umask
    takes them away). An entry that records none (a zip made on Windows) is left as the umask makes it."""
    open_member, mode_of = (opened.open, _zip_mode) if kind == 'zip' else (opened.extractfile, _tar_mode)
    os.makedirs(target, exist_ok=True)
    for parts in plan.dirs:
        _dest(target, parts, make=True)
    for member, parts, size in plan.files:
        dest = _dest(target, parts)
        with open_member(member) as src:
            _copy_capped(src, dest, size, '/'.join(parts))
        mode = mode_of(member)
        if mode:
            os.chmod(dest, mode | 0o600)


def _dest(target, parts, make=False):
    """The path of an entry below ``target``; a file where a folder must go (or the reverse) is an
    UnpackError, never a crash."""
    dest = os.path.join(target, *parts)
    try:
        os.makedirs(dest if make else os.path.dirname(dest), exist_ok=True)
        if not make and os.path.isdir(dest):
            raise UnpackError('entry %s is both a folder and a file' % shown_name('/'.join(parts)))
    except OSError as err:
        raise UnpackError('entry %s cannot be written: %s' % (shown_name('/'.join(parts)), err.strerror))
    return dest


def _copy_capped(src, dest, size, name):
    """Copy what really comes out of an entry: a forged header cannot smuggle more than it declares."""
    written = 0
    try:
        with open(dest, 'wb') as out:
            while True:
                chunk = src.read(65536)
                if not chunk:
                    break
                written += len(chunk)
                if written > size:
                    raise UnpackError('entry %s unpacks to more than it declares' % shown_name(name))
                out.write(chunk)
    except OSError as err:
        raise UnpackError('entry %s cannot be written: %s' % (shown_name(name), err.strerror))

"""What students upload, made safe to look at: checked unpacking, finding the package, a class.

No rospy here. Nothing in a submission is trusted. An archive (zip, tar, tar.gz/tgz, tar.bz2, tar.xz)
is refused as a whole, with the reason for the teacher, when an entry would land outside the target
(``../``, an absolute path, a drive letter), when a name holds a control character or is beyond the
file system's limits, or when the submission's one budget of bytes and files (every archive of it,
nested ones included) would be exceeded or an entry expands like a zip bomb. What students really
upload is not refused for its form: Windows names (backslashes) and missing Unix modes are read as
meant, macOS's ``__MACOSX/`` is skipped, a whole workspace's build products (``build/``, ``devel/``...)
are dropped, links (catkin's ``src/CMakeLists.txt``) and special files are dropped, never followed;
each is noted. Copies of folders never follow links.
"""
import datetime
import os
import re
import shutil
import stat
import tarfile
import xml.etree.ElementTree as ET
import zipfile
import zlib

from exam_lab.grader.score.sheets import PACKAGE, drone_packages

#: Most files one submission may unpack, all its archives together (a package has tens).
MAX_FILES = 5000
#: Most bytes one submission may unpack, all its archives together.
MAX_BYTES = 200 * 1024 * 1024
#: A class archive ("download all submissions") holds every student's uploads: its bounds as a whole
#: (entries, bytes of the students it unpacks); each student's files are paid from MAX_FILES / MAX_BYTES.
CLASS_FILES = 100000
CLASS_BYTES = 4 * 1024 * 1024 * 1024
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
#: How many archives deep a package may sit (a zip holding the package's zip, holding ...).
MAX_NESTING = 2
#: Folders of a catkin workspace that the student's build made: never unpacked, never copied.
BUILD_PRODUCTS = ('build', 'devel', 'install', 'build_isolated', 'devel_isolated', 'install_isolated',
                  '.catkin_tools')
#: Folders never unpacked: build products, version control, caches, macOS's resource forks.
SKIPPED_ON_UNPACK = BUILD_PRODUCTS + ('.git', '.svn', '__pycache__', '__MACOSX')
#: Folders never copied into a workspace: the above and the editors' and loggers' own.
SKIPPED_DIRS = SKIPPED_ON_UNPACK + ('log', 'logs', '.vscode', '.idea')
#: How deep below a submission the package may sit (the zip's top, one folder down, a workspace's src).
MAX_DEPTH = 4
#: Packages that are the simulators, never a student's answer (a whole workspace holds them too).
SIMULATORS = ('node_kit', 'drone_sim') + tuple(drone_packages())
#: File name endings of archives the grader opens, and the magic bytes of those it cannot.
ARCHIVE_ENDINGS = ('.zip', '.tar', '.tar.gz', '.tgz', '.tar.bz2', '.tbz2', '.tar.xz', '.txz')
_UNSUPPORTED = ((b'Rar!\x1a\x07', 'a RAR archive'), (b'7z\xbc\xaf\x27\x1c', 'a 7-Zip archive'),
                (b'\x1f\x8b', 'a gzip file that holds no tar'), (b'BZh', 'a bzip2 file that holds no tar'),
                (b'\xfd7zXZ\x00', 'an xz file that holds no tar'), (b'%PDF', 'a PDF document'))
#: A version number at the end of an upload's name (its archive ending off): exam_v2, exam-2,
#: exam (2) as Moodle or a browser names a second copy, examV3.
_VERSION = re.compile(r'(?:^|[^0-9])(?:[vV]|[_ -]|\()(\d{1,3})\)?$')
#: Zip's "no date" (MS-DOS time starts in 1980): a date on or before it says nothing.
_NO_DATE = datetime.datetime(1980, 1, 2)
#: A byte that is not UTF-8 as repr() shows its surrogate escape (``\\udcff``).
_ESCAPED_BYTE = re.compile(r'(?<!\\)((?:\\\\)*)\\udc([89a-f][0-9a-f])')  # not after an escaped backslash
#: At most this many notes of one kind (links dropped, duplicates) are listed; the rest are counted.
MAX_LISTED = 5


class UnpackError(Exception):
    """A submission that cannot be opened safely; the message says why, for the teacher."""


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


def _entry_path(name):
    """The parts of an archive entry's path, or raise UnpackError if it is unsafe or unwritable."""
    if any(ord(c) < 32 or ord(c) == 127 for c in name):
        raise UnpackError('entry %s has a control character in its name' % shown_name(name))
    path = name.replace('\\', '/')  # archives made on Windows sometimes use backslashes
    if path.startswith('/') or (len(path) > 1 and path[1] == ':'):
        raise UnpackError('entry %s has an absolute path' % shown_name(name))
    parts = [p for p in path.split('/') if p not in ('', '.')]
    if '..' in parts:
        raise UnpackError('entry %s climbs out of the folder (..)' % shown_name(name))
    if len(parts) > MAX_PARTS:
        raise UnpackError('entry %s is %d folders deep (at most %d)' % (shown_name(name), len(parts), MAX_PARTS))
    if len(path.encode('utf-8', 'surrogateescape')) > PATH_MAX:
        raise UnpackError('entry %s has a path of more than %d bytes' % (shown_name(name), PATH_MAX))
    for part in parts:
        if len(part.encode('utf-8', 'surrogateescape')) > NAME_MAX:
            raise UnpackError('entry %s has a name of more than %d bytes' % (shown_name(name), NAME_MAX))
    return parts


class _Plan(object):
    """The entries of one archive that will be written, and what was dropped, before writing any."""

    def __init__(self, label):
        self.label = label
        self.files = []        # (member, parts, size)
        self.dirs = []         # parts
        self.products = {}     # the path of a dropped build-product folder -> entries in it
        self.links = []        # (name, target)
        self.special = []      # names of FIFOs, devices
        self.seen = {}         # parts -> count
        self.folded = {}       # lower-cased parts -> parts first seen

    def add(self, member, name, kind, size, link_target=''):
        parts = _entry_path(name)
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


def listed(names):
    """The first MAX_LISTED of ``names``, and how many more."""
    shown = ', '.join(names[:MAX_LISTED])
    return shown + (' and %d more' % (len(names) - MAX_LISTED) if len(names) > MAX_LISTED else '')


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


def safe_extract(archive, target, max_files=MAX_FILES, max_bytes=MAX_BYTES, max_ratio=MAX_RATIO,
                 budget=None, notes=None, fixes=None):
    """Unpack the zip or tar ``archive`` into ``target`` after checking every entry; return the number
    of files written.

    The whole archive is refused (UnpackError) before anything is written if any entry is unsafe or the
    ``budget`` (a new one of ``max_files`` / ``max_bytes`` when None) cannot pay for it. ``notes``
    receives what was dropped (build products, special files) and duplicates; ``fixes`` the dropped
    links (``notes`` when None).
    """
    budget = budget or Budget(max_bytes, max_files)
    notes = [] if notes is None else notes
    fixes = notes if fixes is None else fixes
    label = os.path.basename(archive)
    kind = archive_kind(archive)
    if kind == 'zip':
        written = _extract_zip(archive, target, label, budget, max_ratio, notes, fixes)
    elif kind == 'tar':
        written = _extract_tar(archive, target, label, budget, notes, fixes)
    else:
        words = what_it_is(archive)
        raise UnpackError('%s is %s: the grader opens zip and tar archives (%s); ask for a zip'
                          % (label, words or 'not a readable zip or tar archive', ', '.join(ARCHIVE_ENDINGS)))
    return written


def _extract_zip(archive, target, label, budget, max_ratio, notes, fixes):
    try:
        zf = zipfile.ZipFile(archive)
    except (zipfile.BadZipFile, OSError) as err:
        raise UnpackError('%s is not a readable zip: %s' % (label, err))
    with zf:
        plan = _Plan(label)
        for info in zf.infolist():
            mode = info.external_attr >> 16 if info.create_system == 3 else 0  # Unix modes, else none
            if stat.S_ISLNK(mode):
                plan.add(info, info.filename, 'link', 0, _zip_link_target(zf, info))
            elif info.is_dir() or info.filename.endswith('\\'):
                plan.add(info, info.filename, 'dir', 0)
            else:
                plan.add(info, info.filename, 'file', info.file_size)
        for info, _, size in plan.files:
            if size > RATIO_FROM_BYTES and size > max_ratio * max(info.compress_size, 1024):
                raise UnpackError('entry %s unpacks %d bytes from %d: a zip bomb?'
                                  % (shown_name(info.filename), size, info.compress_size))
        budget.take(len(plan.files), sum(size for _, _, size in plan.files), label)
        _make_dirs(target, plan)
        for info, parts, size in plan.files:
            dest = _dest(target, parts)
            with zf.open(info) as src:
                _copy_capped(src, dest, size, info.filename)
            mode = (info.external_attr >> 16) & 0o777 if info.create_system == 3 else 0
            if mode:
                os.chmod(dest, mode | 0o600)
    notes.extend(plan.notes())
    fixes.extend(plan.link_notes())
    return len(plan.files)


def _zip_link_target(zf, info):
    if info.file_size > 4096:
        return '?'
    return zf.read(info).decode('utf-8', 'replace')


def _extract_tar(archive, target, label, budget, notes, fixes):
    try:
        tf = tarfile.open(archive, 'r:*')
    except (tarfile.TarError, OSError, EOFError) as err:
        raise UnpackError('%s is not a readable tar archive: %s' % (label, err))
    with tf:
        plan = _Plan(label)
        read = 0
        try:
            # Member by member, charging as it goes: a compressed tar is read (decompressed) only as far
            # as the budget allows, dropped build products included.
            for member in tf:
                read += member.size
                if read > budget.bytes_left or len(plan.files) > budget.files_left:
                    budget.take(len(plan.files) + 1, read, label)  # raises with the reason
                if member.issym() or member.islnk():
                    plan.add(member, member.name, 'link', 0, member.linkname)
                elif member.isdir():
                    plan.add(member, member.name, 'dir', 0)
                elif member.isfile():
                    plan.add(member, member.name, 'file', member.size)
                else:
                    plan.add(member, member.name, 'special', 0)
        except (tarfile.TarError, OSError, EOFError) as err:
            raise UnpackError('%s is not a readable tar archive: %s' % (label, err))
        budget.take(len(plan.files), sum(size for _, _, size in plan.files), label)
        _make_dirs(target, plan)
        try:
            for member, parts, size in plan.files:
                dest = _dest(target, parts)
                src = tf.extractfile(member)
                _copy_capped(src, dest, size, member.name)
                if member.mode & 0o777:
                    os.chmod(dest, (member.mode & 0o777) | 0o600)
        except (tarfile.TarError, EOFError) as err:
            raise UnpackError('%s is not a readable tar archive: %s' % (label, err))
    notes.extend(plan.notes())
    fixes.extend(plan.link_notes())
    return len(plan.files)


def _make_dirs(target, plan):
    os.makedirs(target, exist_ok=True)
    for parts in plan.dirs:
        _dest(target, parts, make=True)


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


def package_name(package_xml):
    """The ``<name>`` of a package.xml, or None when it cannot be read."""
    try:
        return ET.parse(package_xml).getroot().findtext('name', '').strip() or None
    except (ET.ParseError, OSError):
        return None


def find_packages(root, name=PACKAGE, max_depth=MAX_DEPTH):
    """Folders below ``root`` (itself included) holding a package.xml named ``name`` (any name when
    None), shallowest first. Build products and hidden folders are not searched; links are not followed.
    """
    found = []
    base_depth = root.rstrip(os.sep).count(os.sep)
    for dirpath, dirnames, filenames in os.walk(root):
        depth = dirpath.rstrip(os.sep).count(os.sep) - base_depth
        dirnames[:] = sorted(d for d in dirnames if d not in SKIPPED_DIRS and not d.startswith('.')
                             and not os.path.islink(os.path.join(dirpath, d)))
        if depth >= max_depth:
            dirnames[:] = []
        if 'package.xml' in filenames:
            found_name = package_name(os.path.join(dirpath, 'package.xml'))
            if name is None or found_name == name:
                found.append(dirpath)
            dirnames[:] = []  # a package does not hold another one
    return sorted(found, key=lambda p: (p.count(os.sep), p))


def _student_packages(root):
    """Packages below ``root`` that may be the answer: ``exam`` first; else any that is no simulator,
    those with ``exam`` in their name first."""
    exact = find_packages(root)
    if exact:
        return exact
    others = [p for p in find_packages(root, name=None)
              if package_name(os.path.join(p, 'package.xml')) not in SIMULATORS]
    return sorted(others, key=lambda p: ('exam' not in (package_name(os.path.join(p, 'package.xml')) or ''),
                                         p.count(os.sep), p))


def archive_date(path):
    """The newest modification date of the files in an archive (what the student's machine wrote when
    it made it), or None when it has none the grader can read."""
    dates = []
    try:
        if archive_kind(path) == 'zip':
            with zipfile.ZipFile(path) as zf:
                dates = [datetime.datetime(*info.date_time) for info in zf.infolist() if not info.is_dir()]
        elif archive_kind(path) == 'tar':
            with tarfile.open(path, 'r:*') as tf:
                dates = [datetime.datetime.utcfromtimestamp(m.mtime) for m in tf if m.isfile()]
    except (zipfile.BadZipFile, tarfile.TarError, OSError, EOFError, ValueError, OverflowError):
        return None
    dates = [d for d in dates if d > _NO_DATE]
    return max(dates) if dates else None


def version_number(name):
    """The version number at the end of an upload's name (``exam_v2.zip``: 2), or None."""
    stem = os.path.basename(name)
    for ending in sorted(ARCHIVE_ENDINGS, key=len, reverse=True):
        if stem.lower().endswith(ending):
            stem = stem[:-len(ending)]
            break
    match = _VERSION.search(stem)
    return int(match.group(1)) if match else None


def choose_upload(uploads):
    """Which of several uploads of one student to grade: the newest by its files' dates, then by the
    version number in its name.

    :param uploads: ``[(name, date or None, version or None)]``.
    :returns: ``(index, why, ambiguous)``; ``ambiguous`` when neither the dates nor the names tell the
        last one apart, or when they disagree (the teacher must look; the index is then the one the
        dates, else the names, else the name's order favour).
    """
    def shown(i):
        name, date, version = uploads[i]
        return '%s (%s)' % (name, 'files dated %s' % date.strftime('%Y-%m-%d %H:%M') if date else 'no dates')
    indices = list(range(len(uploads)))
    dated = [i for i in indices if uploads[i][1] is not None]
    versions = [i for i in indices if uploads[i][2] is not None]
    by_version = max(versions, key=lambda i: uploads[i][2]) if versions else None
    unique_version = by_version is not None and \
        [uploads[i][2] for i in versions].count(uploads[by_version][2]) == 1 and \
        all(uploads[i][2] is not None or uploads[by_version][2] > 1 for i in indices)
    listed = ', '.join(shown(i) for i in indices)
    if len(dated) == len(uploads):
        newest = max(dated, key=lambda i: uploads[i][1])
        if [uploads[i][1] for i in dated].count(uploads[newest][1]) == 1:
            if unique_version and by_version != newest:
                return newest, ('the dates and the names disagree on which is the last: %s; graded %s, the '
                                'newest by its dates' % (listed, uploads[newest][0])), True
            return newest, 'graded %s, the newest by its files\' dates, of %s' % (uploads[newest][0], listed), False
    if unique_version:
        return by_version, ('graded %s, the highest version number in its name (the dates do not tell: %s)'
                            % (uploads[by_version][0], listed)), False
    chosen = max(dated, key=lambda i: uploads[i][1]) if dated else sorted(indices, key=lambda i: uploads[i][0])[-1]
    return chosen, ('neither the dates nor the names tell which upload is the last: %s; graded %s'
                    % (listed, uploads[chosen][0])), True


def open_submission(path, scratch, notes, fixes=None, budget=None, uploads=None):
    """The folder of the student's package in a submission: a folder, an archive, a folder of
    archives, archives in archives (``MAX_NESTING`` deep), a whole workspace.

    Archives are unpacked (checked) below ``scratch``, all paid from one ``budget``. ``notes`` receives
    what the teacher should know (other candidates, refused archives, what was dropped); ``fixes`` the
    changes to what the student uploaded (links dropped, a package not named ``exam``); ``uploads``
    one ``{"files", "chosen", "why", "ambiguous"}`` per choice among several uploads holding a package
    (:func:`choose_upload`). Raises UnpackError when there is no package, saying what was found instead.
    """
    uploads = [] if uploads is None else uploads
    budget = budget or Budget()
    fixes = notes if fixes is None else fixes
    path = os.path.abspath(path)
    counter = [0]
    seen = []
    if os.path.isfile(path):
        root = _unpack_one(path, scratch, notes, fixes, budget, counter)
    else:
        root = path
    found = _search(root, scratch, notes, fixes, budget, counter, 0, seen, uploads)
    if not found:
        refused = [s for s in seen if '(refused: ' in s or 'cannot be opened' in s]
        if refused:  # the reason is the archive that could not be opened, not a missing package
            raise UnpackError(listed(refused))
        raise UnpackError('no catkin package (package.xml) in %s%s' % (
            os.path.basename(path), '; found: %s' % listed(seen) if seen else ' (it is empty)'))
    chosen = found[0]
    name = package_name(os.path.join(chosen, 'package.xml'))
    if name != PACKAGE:
        fixes.append('the package is named %s, not %s (question 9 asks for %s): graded as it is'
                     % (shown_name(name or '?'), PACKAGE, PACKAGE))
    parent = os.path.dirname(chosen)
    if os.path.basename(parent) == 'src':
        notes.append('a whole catkin workspace was uploaded: graded its package %s' % _shown(chosen, scratch, path))
    if len(found) > 1:
        notes.append('several candidate packages found; graded %s, ignored %s'
                     % (_shown(chosen, scratch, path), ', '.join(_shown(f, scratch, path) for f in found[1:])))
    return chosen


def _unpack_one(archive, scratch, notes, fixes, budget, counter):
    target = os.path.join(scratch, 'unpacked%d' % counter[0])
    counter[0] += 1
    safe_extract(archive, target, budget=budget, notes=notes, fixes=fixes)
    return target


def _search(root, scratch, notes, fixes, budget, counter, depth, seen, uploads):
    """Packages in ``root``, else in the archives it holds (each unpacked once, nested ones too); of
    several archives holding a package, only the chosen one's (:func:`choose_upload`)."""
    found = _student_packages(root)
    if found or depth >= MAX_NESTING:
        return found
    holding = []
    for archive in sorted(_archives_in(root)):
        rel = os.path.relpath(archive, root)
        if archive_kind(archive) is None:
            words = what_it_is(archive)
            notes.append('%s cannot be opened: it is %s; the grader opens zip and tar archives'
                         % (shown_name(rel), words or 'not a readable archive'))
            seen.append('%s cannot be opened: it is %s' % (shown_name(rel), words or 'not a readable archive'))
            continue
        try:
            inner = _unpack_one(archive, scratch, notes, fixes, budget, counter)
        except UnpackError as err:
            notes.append('%s refused: %s' % (shown_name(rel), err))
            seen.append('%s (refused: %s)' % (rel, err))
            continue
        got = _search(inner, scratch, notes, fixes, budget, counter, depth + 1, seen, uploads)
        if not got:
            seen.append('%s (no package inside)' % shown_name(rel))
        else:
            holding.append((rel, archive, got))
        found.extend(got)
    if len(holding) > 1:
        index, why, ambiguous = choose_upload([(shown_name(rel), archive_date(archive), version_number(rel))
                                               for rel, archive, _ in holding])
        uploads.append({'files': [rel for rel, _, _ in holding], 'chosen': holding[index][0], 'why': why,
                        'ambiguous': ambiguous})
        notes.append('%d uploads hold a package: %s' % (len(holding), why))
        found = holding[index][2]
    if not found:
        seen.extend(shown_name(n) for n in sorted(os.listdir(root))[:MAX_LISTED]
                    if not any(n in s for s in seen))
    return found


def _archives_in(folder):
    """Files below ``folder`` that look like archives (by their name, or any file at the top: the
    platform may keep the student's file name, whatever it is)."""
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames[:] = [d for d in dirnames if d not in SKIPPED_DIRS
                       and not os.path.islink(os.path.join(dirpath, d))]
        for filename in filenames:
            full = os.path.join(dirpath, filename)
            if os.path.islink(full) or not os.path.isfile(full):
                continue
            lower = filename.lower()
            if lower.endswith(ARCHIVE_ENDINGS) or what_it_is(full) in ('a RAR archive', 'a 7-Zip archive') \
                    or (dirpath == folder and '.' not in filename and archive_kind(full)):
                yield full


def _shown(path, *bases):
    """``path`` as the teacher knows it: inside the upload, not inside the grader's scratch folder."""
    for base in bases:
        if path.startswith(base):
            rel = os.path.relpath(path, base)
            first = rel.split(os.sep, 1)
            return first[1] if len(first) == 2 and first[0].startswith('unpacked') else rel
    return path


def copy_package(source, target, notes):
    """Copy the package folder to ``target``: regular files only, without build products, hidden
    folders, links or special files (each link noted)."""
    def ignore(dirpath, names):
        skipped = set(n for n in names if n in SKIPPED_DIRS or (n.startswith('.') and
                                                              os.path.isdir(os.path.join(dirpath, n))))
        for n in names:
            full = os.path.join(dirpath, n)
            if os.path.islink(full):
                skipped.add(n)
                notes.append('link %s not copied' % shown_name(os.path.relpath(full, source)))
            elif not (os.path.isfile(full) or os.path.isdir(full)):
                skipped.add(n)
        return skipped
    shutil.copytree(source, target, ignore=ignore)


def list_students(class_path, scratch, refused=None):
    """``[(student, folder or archive)]`` of a class: one sub-folder per student, as "download all"
    gives.

    ``class_path`` may be an archive of that, unpacked below ``scratch`` by :func:`unpack_class`: the
    class's bounds as a whole, each student's files by the student's own; a student whose files are
    refused is listed all the same (an empty folder or file in its place) and ``refused`` (a dict)
    receives ``{its path: why}``. A class whose top holds archives instead of folders counts each
    archive as one student (named after it).
    """
    class_path = os.path.abspath(class_path)
    if os.path.isfile(class_path):
        class_path = unpack_class(class_path, os.path.join(scratch, 'class'), {} if refused is None else refused)
    students = []
    for entry in sorted(os.listdir(class_path)):
        full = os.path.join(class_path, entry)
        if entry.startswith('.') or entry in SKIPPED_DIRS or os.path.islink(full):
            continue
        if os.path.isdir(full):
            students.append((student_name(entry), full))
        elif entry.lower().endswith(ARCHIVE_ENDINGS):
            students.append((student_name(_without_ending(entry)), full))
    return students


def _without_ending(name):
    for ending in sorted(ARCHIVE_ENDINGS, key=len, reverse=True):
        if name.lower().endswith(ending):
            return name[:-len(ending)]
    return name


def _class_entries(archive, label):
    """``[(member, name, kind, size, link target)]`` of a class archive, read as far as the class's
    bounds allow (a compressed tar is decompressed while it is listed); raises UnpackError past them."""
    entries = []
    kind = archive_kind(archive)
    if kind == 'zip':
        try:
            with zipfile.ZipFile(archive) as zf:
                infos = zf.infolist()
                if len(infos) > CLASS_FILES:
                    raise UnpackError('%s holds %d entries (at most %d for a class)' % (label, len(infos), CLASS_FILES))
                for info in infos:
                    mode = info.external_attr >> 16 if info.create_system == 3 else 0
                    if stat.S_ISLNK(mode):
                        entries.append((info, info.filename, 'link', 0, '?'))
                    elif info.is_dir() or info.filename.endswith('\\'):
                        entries.append((info, info.filename, 'dir', 0, ''))
                    else:
                        entries.append((info, info.filename, 'file', info.file_size, ''))
        except (zipfile.BadZipFile, OSError) as err:
            raise UnpackError('%s is not a readable zip: %s' % (label, err))
        return entries
    if kind == 'tar':
        read = 0
        try:
            with tarfile.open(archive, 'r:*') as tf:
                for member in tf:
                    read += member.size
                    if len(entries) >= CLASS_FILES or read > CLASS_BYTES:
                        raise UnpackError('%s holds more than %d entries or %d bytes (the bounds of a class)'
                                          % (label, CLASS_FILES, CLASS_BYTES))
                    what = 'link' if member.issym() or member.islnk() else 'dir' if member.isdir() else \
                        'file' if member.isfile() else 'special'
                    entries.append((member, member.name, what, member.size if what == 'file' else 0,
                                    member.linkname))
        except (tarfile.TarError, OSError, EOFError) as err:
            raise UnpackError('%s is not a readable tar archive: %s' % (label, err))
        return entries
    words = what_it_is(archive)
    raise UnpackError('%s is %s: the grader opens zip and tar archives (%s); ask for a zip'
                      % (label, words or 'not a readable zip or tar archive', ', '.join(ARCHIVE_ENDINGS)))


def _raw_parts(name):
    """The parts of an entry's name as written (before any check), and whether it is rooted."""
    path = name.replace('\\', '/')
    rooted = path.startswith('/') or (len(path) > 1 and path[1] == ':')
    return [p for p in path.split('/') if p not in ('', '.')], rooted


def unpack_class(archive, target, refused):
    """Unpack a class archive into ``target``; return the folder that holds one entry per student.

    The class is bounded as a whole: CLASS_FILES entries, CLASS_BYTES unpacked, and an entry that
    cannot be said to belong to one student (``../``, an absolute path at the top) refuses it. Each
    student's files (everything below its top folder, or its archive at the top) are checked and paid
    by the student's own bounds (:class:`Budget`, :func:`_entry_path`): one that fails them is not
    unpacked, and ``refused`` receives ``{the student's path: why}`` (an empty folder, or an empty file
    for an archive, holds its place). No ratio of Moodle's compression is judged: a student's
    one-colour screenshot or log is no bomb, and the student's bytes are bounded by its budget."""
    label = os.path.basename(archive)
    groups = {}
    for entry in _class_entries(archive, label):
        parts, rooted = _raw_parts(entry[1])
        if rooted or (parts and parts[0] == '..'):
            raise UnpackError('entry %s of the class archive lies outside it' % shown_name(entry[1]))
        if not parts or parts[0] == '__MACOSX':
            continue
        groups.setdefault(parts[0], []).append((entry, parts))
    base = ''
    if len(groups) == 1:  # the archive holds the class folder (unless that folder is one package)
        (top, members), = groups.items()
        if all(len(parts) > 1 for _, parts in members) and \
                not any(parts[1:] == ['package.xml'] or parts[2:] == ['package.xml'] for _, parts in members):
            base = top
            groups = {}
            for entry, parts in members:
                if len(parts) > 1:
                    groups.setdefault(parts[1], []).append((entry, parts[1:]))
    os.makedirs(target, exist_ok=True)
    top = os.path.join(target, base) if base else target
    plans, total = [], 0
    for key, members in sorted(groups.items()):
        place = os.path.join(top, key)
        try:
            plan = _Plan(key)
            for (member, name, kind, size, link), parts in members:
                if len(parts) == 1 and kind != 'dir':
                    plan.add(member, parts[0], kind, size, link)
                else:
                    plan.add(member, '/'.join(parts[1:]), kind, size, link)
            single = [p for _, p in members if len(p) == 1]
            if single and any(len(p) > 1 for _, p in members):
                raise UnpackError('%s is both a file and a folder' % shown_name(key))
            Budget(MAX_BYTES, MAX_FILES).take(len(plan.files), sum(size for _, _, size in plan.files),
                                              'the files of %s' % shown_name(key))
        except UnpackError as err:
            refused[place] = str(err)
            plans.append((key, place, None, members))
            continue
        total += sum(size for _, _, size in plan.files)
        plans.append((key, place, plan, members))
    if total > CLASS_BYTES:
        raise UnpackError('the students\' files in %s come to %d bytes (at most %d for a class)'
                          % (label, total, CLASS_BYTES))
    kind = archive_kind(archive)
    with (zipfile.ZipFile(archive) if kind == 'zip' else tarfile.open(archive, 'r:*')) as opened:
        for key, place, plan, members in plans:
            archive_at_top = all(len(p) == 1 for _, p in members) and members[0][0][2] != 'dir'
            if plan is not None:
                try:
                    _write_student(opened, kind, place, plan, archive_at_top)
                    continue
                except UnpackError as err:
                    refused[place] = str(err)
                    shutil.rmtree(place, ignore_errors=True)
                    if os.path.isfile(place):
                        os.unlink(place)
            try:
                if archive_at_top:
                    open(place, 'wb').close()
                else:
                    os.makedirs(place, exist_ok=True)
            except OSError as err:
                raise UnpackError('%s of the class archive cannot be written: %s' % (shown_name(key), err.strerror))
    return top


def _write_student(opened, kind, place, plan, archive_at_top):
    """Write one student's planned files below ``place`` (its archive at ``place`` itself)."""
    try:
        if not archive_at_top:
            _make_dirs(place, plan)
        for member, parts, size in plan.files:
            dest = place if archive_at_top else _dest(place, parts)
            src = opened.open(member) if kind == 'zip' else opened.extractfile(member)
            with src:
                _copy_capped(src, dest, size, '/'.join(parts))
    except (zipfile.BadZipFile, tarfile.TarError, zlib.error, EOFError, OSError, RuntimeError,
            NotImplementedError) as err:  # encrypted, corrupt, or compressed as zipfile cannot read
        raise UnpackError('%s cannot be unpacked: %s' % (shown_name(plan.label), err))


#: Endings of the files a class's run writes in OUT beside the students' folders (grades.csv, index.html,
#: hand.csv, similarity.json, the filled worksheet...): a student's folder never has one.
OUTPUT_ENDINGS = ('.csv', '.html', '.json', '.jsonl', '.md', '.png', '.txt', '.log', '.zip')


def student_name(folder):
    """A name usable as a folder and a CSV cell: Moodle's ``Jane Doe_1234_assignsubmission_file_``
    becomes ``Jane Doe``; anything but letters, digits, space, ``-._`` becomes ``_``. A name that ends
    like one of the class's outputs (OUTPUT_ENDINGS: ``grades.csv``, ``index.html``) has its last dot
    made ``_`` (``grades_csv``): a student's folder and the class's files can never be one path."""
    name = folder.split('_assignsubmission')[0]
    parts = name.rsplit('_', 1)
    if len(parts) == 2 and parts[1].isdigit():
        name = parts[0]
    cleaned = ''.join(c if c.isalnum() or c in ' -._' else '_' for c in name).strip(' .')
    if cleaned.lower().endswith(OUTPUT_ENDINGS):
        stem, ending = cleaned.rsplit('.', 1)
        cleaned = '%s_%s' % (stem, ending)
    return cleaned or 'student'

"""What students upload, made safe to look at: checked unzipping, finding the ``exam`` package, a class.

No rospy here. Nothing in a submission is trusted: an archive is refused as a whole (with the reason,
for the teacher) when an entry would land outside the target (``../``, an absolute path, a drive
letter), is a link, or when the archive is too big or has too many files (a zip bomb). Copies of
folders never follow links.
"""
import os
import shutil
import stat
import xml.etree.ElementTree as ET
import zipfile

#: Most files one archive may hold (a package has tens; a workspace with build/ a few thousand).
MAX_FILES = 5000
#: Most bytes one archive may unpack to, all files together.
MAX_BYTES = 200 * 1024 * 1024
#: Highest ratio of unpacked to packed size of one entry (text compresses ~5x; bombs 1000x).
MAX_RATIO = 200
#: Folders never copied into a workspace: build products and version control of the student's side.
SKIPPED_DIRS = ('build', 'devel', 'install', 'log', '.git', '.svn', '__pycache__', '__MACOSX',
                '.catkin_tools', '.vscode', '.idea')
#: How deep below a submission the package may sit (the zip's top, one folder down, a workspace's src).
MAX_DEPTH = 4


class UnpackError(Exception):
    """A submission that cannot be opened safely; the message says why, for the teacher."""


def _entry_path(name):
    """The parts of an archive entry's path, or raise UnpackError if it would escape the target."""
    path = name.replace('\\', '/')  # archives made on Windows sometimes use backslashes
    if path.startswith('/') or (len(path) > 1 and path[1] == ':'):
        raise UnpackError('entry %r has an absolute path' % name)
    parts = [p for p in path.split('/') if p not in ('', '.')]
    if '..' in parts:
        raise UnpackError('entry %r climbs out of the folder (..)' % name)
    return parts


def _is_link(info):
    """True when a zip entry is a symbolic link (Unix mode in the high bits of external_attr)."""
    return stat.S_ISLNK(info.external_attr >> 16)


def safe_extract(archive, target, max_files=MAX_FILES, max_bytes=MAX_BYTES, max_ratio=MAX_RATIO):
    """Extract the zip ``archive`` into ``target`` after checking every entry; return the file count.

    The whole archive is refused (UnpackError) before anything is written if any entry is unsafe.
    Entries of macOS's ``__MACOSX/`` resource forks are skipped.
    """
    try:
        zf = zipfile.ZipFile(archive)
    except (zipfile.BadZipFile, OSError) as err:
        raise UnpackError('%s is not a readable zip: %s' % (os.path.basename(archive), err))
    with zf:
        entries = []
        total = 0
        for info in zf.infolist():
            parts = _entry_path(info.filename)
            if not parts or parts[0] == '__MACOSX':
                continue
            if _is_link(info):
                raise UnpackError('entry %r is a symbolic link' % info.filename)
            total += info.file_size
            if info.file_size > max_ratio * max(info.compress_size, 1024):
                raise UnpackError('entry %r unpacks %d bytes from %d: a zip bomb?'
                                  % (info.filename, info.file_size, info.compress_size))
            entries.append((info, parts))
        if len(entries) > max_files:
            raise UnpackError('%d entries, more than the %d allowed' % (len(entries), max_files))
        if total > max_bytes:
            raise UnpackError('unpacks to %d bytes, more than the %d allowed' % (total, max_bytes))
        os.makedirs(target, exist_ok=True)
        for info, parts in entries:
            dest = os.path.join(target, *parts)
            if info.is_dir() or info.filename.endswith(('/', '\\')):
                os.makedirs(dest, exist_ok=True)
                continue
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            written = 0
            with zf.open(info) as src, open(dest, 'wb') as out:
                # Count what really comes out: a forged header cannot smuggle more than it declares.
                while True:
                    chunk = src.read(65536)
                    if not chunk:
                        break
                    written += len(chunk)
                    if written > info.file_size:
                        raise UnpackError('entry %r unpacks to more than it declares' % info.filename)
                    out.write(chunk)
            mode = (info.external_attr >> 16) & 0o777
            if mode:
                os.chmod(dest, mode | 0o600)
        return len(entries)


def package_name(package_xml):
    """The ``<name>`` of a package.xml, or None when it cannot be read."""
    try:
        return ET.parse(package_xml).getroot().findtext('name', '').strip() or None
    except (ET.ParseError, OSError):
        return None


def find_packages(root, name='exam', max_depth=MAX_DEPTH):
    """Folders below ``root`` (itself included) holding a package.xml named ``name``, shallowest first.

    Build products and hidden folders are not searched; links are not followed.
    """
    found = []
    base_depth = root.rstrip(os.sep).count(os.sep)
    for dirpath, dirnames, filenames in os.walk(root):
        depth = dirpath.rstrip(os.sep).count(os.sep) - base_depth
        dirnames[:] = sorted(d for d in dirnames if d not in SKIPPED_DIRS and not d.startswith('.')
                             and not os.path.islink(os.path.join(dirpath, d)))
        if depth >= max_depth:
            dirnames[:] = []
        if 'package.xml' in filenames and package_name(os.path.join(dirpath, 'package.xml')) == name:
            found.append(dirpath)
            dirnames[:] = []  # a package does not hold another one
    return sorted(found, key=lambda p: (p.count(os.sep), p))


def open_submission(path, scratch, notes):
    """The folder of the ``exam`` package in a submission (a folder, a zip, or a folder of zips).

    Zips are extracted (checked) below ``scratch``. ``notes`` receives what the teacher should know
    (other candidates, refused archives). Raises UnpackError when there is no package.
    """
    path = os.path.abspath(path)
    if os.path.isfile(path):
        if not zipfile.is_zipfile(path):
            raise UnpackError('%s is neither a folder nor a zip' % os.path.basename(path))
        target = os.path.join(scratch, 'unzipped')
        safe_extract(path, target)
        return open_submission(target, scratch, notes)
    found = find_packages(path)
    if not found:
        # A student folder from the course platform: the package is in one of its zips.
        refused = []
        for zip_path in sorted(_zips_in(path)):
            target = os.path.join(scratch, 'zip%d' % len(refused + found))
            try:
                safe_extract(zip_path, target)
            except UnpackError as err:
                refused.append('%s refused: %s' % (os.path.relpath(zip_path, path), err))
                continue
            found.extend(find_packages(target))
        notes.extend(refused)
        if not found:
            raise UnpackError('no catkin package named exam in %s%s'
                              % (os.path.basename(path), ' (%s)' % '; '.join(refused) if refused else ''))
    if len(found) > 1:
        notes.append('several exam packages found; graded %s, ignored %s'
                     % (_shown(found[0], scratch, path), ', '.join(_shown(f, scratch, path) for f in found[1:])))
    return found[0]


def _zips_in(folder):
    for dirpath, dirnames, filenames in os.walk(folder):
        dirnames[:] = [d for d in dirnames if not os.path.islink(os.path.join(dirpath, d))]
        for filename in filenames:
            full = os.path.join(dirpath, filename)
            if filename.lower().endswith('.zip') and not os.path.islink(full):
                yield full


def _shown(path, *bases):
    for base in bases:
        if path.startswith(base):
            return os.path.relpath(path, base)
    return path


def copy_package(source, target, notes):
    """Copy the package folder to ``target`` without build products, hidden folders or links."""
    def ignore(dirpath, names):
        skipped = set(n for n in names if n in SKIPPED_DIRS or (n.startswith('.') and
                                                              os.path.isdir(os.path.join(dirpath, n))))
        for n in names:
            if os.path.islink(os.path.join(dirpath, n)):
                skipped.add(n)
                notes.append('link %s not copied' % os.path.relpath(os.path.join(dirpath, n), source))
        return skipped
    shutil.copytree(source, target, ignore=ignore)


def list_students(class_path, scratch):
    """``[(student, folder)]`` of a class: one sub-folder per student, as "download all" gives.

    ``class_path`` may be a zip of that (extracted safely below ``scratch``). A class whose top holds
    zips instead of folders counts each zip as one student (named after the zip).
    """
    class_path = os.path.abspath(class_path)
    if os.path.isfile(class_path):
        target = os.path.join(scratch, 'class')
        safe_extract(class_path, target)
        class_path = target
        entries = [e for e in os.listdir(class_path) if not e.startswith('.')]
        if len(entries) == 1 and os.path.isdir(os.path.join(class_path, entries[0])) \
                and not find_packages(os.path.join(class_path, entries[0]), max_depth=1):
            class_path = os.path.join(class_path, entries[0])  # the zip holds the class folder
    students = []
    for entry in sorted(os.listdir(class_path)):
        full = os.path.join(class_path, entry)
        if entry.startswith('.') or entry in SKIPPED_DIRS or os.path.islink(full):
            continue
        if os.path.isdir(full):
            students.append((student_name(entry), full))
        elif entry.lower().endswith('.zip'):
            students.append((student_name(entry[:-4]), full))
    return students


def student_name(folder):
    """A name usable as a folder and a CSV cell: Moodle's ``Jane Doe_1234_assignsubmission_file_``
    becomes ``Jane Doe``; anything but letters, digits, space, ``-._`` becomes ``_``."""
    name = folder.split('_assignsubmission')[0]
    parts = name.rsplit('_', 1)
    if len(parts) == 2 and parts[1].isdigit():
        name = parts[0]
    cleaned = ''.join(c if c.isalnum() or c in ' -._' else '_' for c in name).strip(' .')
    return cleaned or 'student'

"""What root lays out for a box before it runs: the upload, copied byte for byte without reading it,
and the box's own work folder.
"""
import os
import shutil
import stat
import subprocess
import tempfile

#: Most bytes and entries of one upload staged for a box (unpacking's own budget applies inside).
UPLOAD_BYTES = 256 << 20
UPLOAD_FILES = 20000
UPLOAD_DEPTH = 32


class UploadRefused(ValueError):
    """An upload too large or too deep to stage for its box (:func:`stage_upload`): that student's row."""


def stage_upload(source, target, max_bytes=UPLOAD_BYTES, max_files=UPLOAD_FILES):
    """Copy the upload ``source`` (a file or a folder) to ``target`` for a box to read, byte for byte and
    without reading anything of it: regular files (opened with O_NOFOLLOW; executable ones stay so:
    whether a script was, is a fact of the grade), folders and links (as
    links, never followed); FIFOs, devices and sockets are left out. Everything is root's and
    world-readable, nothing writable by a box. An upload over ``max_bytes``, ``max_files`` or
    :data:`UPLOAD_DEPTH` folders deep raises :class:`UploadRefused`."""
    budget = {'bytes': max_bytes, 'files': max_files}

    def take(size):
        budget['files'] -= 1
        budget['bytes'] -= size
        if budget['files'] < 0 or budget['bytes'] < 0:
            raise UploadRefused('the upload is larger than the grader takes (%d MB, %d files)'
                                % (max_bytes >> 20, max_files))

    def copy_file(src, dest):
        fd = os.open(src, os.O_RDONLY | os.O_NOFOLLOW | os.O_NONBLOCK)
        try:
            info = os.fstat(fd)
            if not stat.S_ISREG(info.st_mode):
                return
            take(info.st_size)
            with os.fdopen(os.dup(fd), 'rb') as f, open(dest, 'xb') as g:
                os.chmod(dest, 0o755 if info.st_mode & 0o111 else 0o644)  # a script keeps its x bit
                shutil.copyfileobj(f, g)
        finally:
            os.close(fd)

    def copy(src, dest, depth=0):
        if depth > UPLOAD_DEPTH:
            raise UploadRefused('the upload has folders more than %d deep' % UPLOAD_DEPTH)
        info = os.lstat(src)
        if stat.S_ISLNK(info.st_mode):
            take(0)
            os.symlink(os.readlink(src), dest)
        elif stat.S_ISDIR(info.st_mode):
            take(0)
            os.mkdir(dest, 0o755)
            os.chmod(dest, 0o755)
            for name in sorted(os.listdir(src)):
                copy(os.path.join(src, name), os.path.join(dest, name), depth + 1)
        elif stat.S_ISREG(info.st_mode):
            copy_file(src, dest)

    copy(source.rstrip('/') or '/', target)


def work_folder(folder, src, copy_src, uid=None, size=None):
    """Make a box's work folder ``folder`` (0700): ``ws/`` with ``build/``, ``devel/`` and ``src/``, a
    mount point for the read-only package folder ``src`` or, when ``copy_src`` (unsandboxed), a copy of
    it (links kept as links) and the box's HOME, ``home/``. With ``uid`` (as root), a tmpfs of ``size``
    bytes where root can mount one, and everything owned by ``uid``. Returns whether the tmpfs was
    mounted."""
    os.makedirs(folder, mode=0o700)
    mounted = uid is not None and _tmpfs(folder, size, uid)
    if uid is not None and not mounted:
        os.chown(folder, uid, uid)
        os.chmod(folder, 0o700)
    for sub in ('ws', 'ws/build', 'ws/devel'):
        os.mkdir(os.path.join(folder, sub))
    if copy_src:
        shutil.copytree(src, os.path.join(folder, 'ws', 'src'), symlinks=True)
        os.mkdir(os.path.join(folder, 'home'))
    else:
        os.mkdir(os.path.join(folder, 'ws', 'src'))
    if uid is not None:
        for dirpath, dirnames, filenames in os.walk(folder):
            for name in [dirpath] + [os.path.join(dirpath, n) for n in dirnames + filenames]:
                os.lchown(name, uid, uid)
    return mounted


def remove_work_folder(folder, mounted):
    """Remove what :func:`work_folder` made (its tmpfs unmounted first when ``mounted``)."""
    if mounted:
        subprocess.run(['umount', '-l', folder], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=30)
    shutil.rmtree(folder, ignore_errors=True)


def _tmpfs(path, size, uid):
    """Mount a tmpfs of ``size`` bytes owned by ``uid`` on ``path``; False where root cannot mount."""
    done = subprocess.run(['mount', '-t', 'tmpfs', '-o', 'size=%d,mode=0700,uid=%d,gid=%d,nosuid,nodev'
                           % (size, uid, uid), 'exam-box', path],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=30)
    return done.returncode == 0


def new_work(prefix, parent=None):
    """A new work folder for a box, in ``parent``: by default the system's temp folder, not under OUT
    (which may be private), for the box's user must reach ``<work>/upload``, ``<work>/ws`` and
    ``<work>/box``; 0711, so it may not list ``<work>``. Laid out by :func:`stage_work`; the caller
    removes it, whatever staging did: the box's logs are kept from it."""
    work = tempfile.mkdtemp(prefix=prefix, dir=parent)
    os.chmod(work, 0o711)
    return work


def stage_work(work, sources, bounds=None, refused=None):
    """Lay out the work folder ``work`` (:func:`new_work`) for a box: each ``(name, path)`` of
    ``sources`` staged read-only as ``<work>/upload/<index>/<name>`` (a path followed only as far as
    the caller resolved it), within ``bounds`` (``(bytes, files)``; one upload's when None), and the
    workspace ``<work>/ws/src`` the inspection writes the package to; returns the staged paths. With
    ``refused`` (a dict), a source over its bounds is not staged (None in its place) and ``refused``
    receives ``{its path: why}``; otherwise it raises :class:`UploadRefused`."""
    staged = []
    for sub in ('upload', 'ws', 'ws/src'):
        os.mkdir(os.path.join(work, sub), 0o755)
    for index, (name, path) in enumerate(sources):
        os.mkdir(os.path.join(work, 'upload', str(index)), 0o755)
        staged.append(os.path.join(work, 'upload', str(index), name if name not in ('', '.', '..') else 'upload'))
        try:
            stage_upload(path, staged[-1], *(bounds or ()))
        except UploadRefused as err:
            if refused is None:
                raise
            refused[path] = str(err)
            shutil.rmtree(os.path.dirname(staged[-1]), ignore_errors=True)
            staged[-1] = None
    return staged

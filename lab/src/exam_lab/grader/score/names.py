"""What the grader's file names mean, on both sides of the box: the archives it opens (by their
ending), the folders it never unpacks, copies nor takes for a student, and what a folder's entries
are (:func:`entry_kinds`, by lstat: the one look at a file system here, names and kinds, nothing
opened). No rospy.

The box reads an upload with them (:mod:`~exam_lab.grader.boxed.archives`); root lists a class folder
with them (:mod:`~exam_lab.grader.host.classfolder`, by names only): one definition for both.
"""
import os
import stat

#: Folders of a catkin workspace that the student's build made: never unpacked, never copied.
BUILD_PRODUCTS = ('build', 'devel', 'install', 'build_isolated', 'devel_isolated', 'install_isolated',
                  '.catkin_tools')
#: Folders never unpacked: build products, version control, caches, macOS's resource forks.
SKIPPED_ON_UNPACK = BUILD_PRODUCTS + ('.git', '.svn', '__pycache__', '__MACOSX')
#: Folders never copied into a workspace nor searched: the above and the editors' and loggers' own.
SKIPPED_DIRS = SKIPPED_ON_UNPACK + ('log', 'logs', '.vscode', '.idea')
#: File name endings of archives the grader opens.
ARCHIVE_ENDINGS = ('.zip', '.tar', '.tar.gz', '.tgz', '.tar.bz2', '.tbz2', '.tar.xz', '.txz')


def without_ending(name):
    """``name`` without its archive ending (``exam_v2.tar.gz``: ``exam_v2``)."""
    for ending in sorted(ARCHIVE_ENDINGS, key=len, reverse=True):
        if name.lower().endswith(ending):
            return name[:-len(ending)]
    return name


#: What the similarity check compares of a package: its code, never its data (YAML, maps, logs, bags).
CODE_SUFFIXES = ('.py', '.cpp', '.cc', '.cxx', '.c', '.h', '.hpp', '.launch', '.xml')
CODE_NAMES = ('CMakeLists.txt',)
#: The similarity detector, copydetect from PyPI, pinned: root installs it, the box runs it.
VERSION = '0.5.0'

#: A class archive ("download all submissions") holds every student's uploads: its bounds as a whole
#: (entries, bytes of the students it unpacks); each student's files are paid from MAX_FILES / MAX_BYTES.
CLASS_FILES = 100000
CLASS_BYTES = 4 * 1024 * 1024 * 1024


def entry_kinds(folder):
    """``[(name, kind)]`` of a folder's entries, sorted, by lstat (never following a link): ``dir``,
    ``file``, ``link`` or ``other``: all a class listing reads (:func:`~exam_lab.grader.score.identity.class_listing`)."""
    found = []
    for name in sorted(os.listdir(folder)):
        mode = os.lstat(os.path.join(folder, name)).st_mode
        found.append((name, 'link' if stat.S_ISLNK(mode) else 'dir' if stat.S_ISDIR(mode) else
                      'file' if stat.S_ISREG(mode) else 'other'))
    return found

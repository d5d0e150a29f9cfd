"""A class's students: one sub-folder (or archive) per student, as Moodle's "download all
submissions" gives, from a folder or from an archive of it. No rospy here.

A class archive is bounded as a whole (CLASS_FILES entries, CLASS_BYTES unpacked, CLASS_READ_BYTES read
through to list a tar); each student's
files are checked and paid by the student's own bounds (:class:`~exam_lab.grader.boxed.archives.Budget`,
the checks of :class:`~exam_lab.grader.boxed.archives.Plan`), so one student's bad files refuse that
student only. Names are cleaned by :func:`~exam_lab.grader.score.identity.student_name`.
"""
import os
import shutil
import tarfile

from exam_lab.grader.boxed import archives
from exam_lab.grader.boxed.archives import (UNREADABLE, Plan, UnpackError, open_archive,
                                            shown_name, tar_entries, unreadable_why, write_plan,
                                            zip_entries)
from exam_lab.grader.score import identity
from exam_lab.grader.score.names import entry_kinds
from exam_lab.grader.score.identity import LINKED, moodle_span  # noqa: F401 (LINKED: the listing's words)

# A class's bounds as a whole, root's staging and this box's unpacking alike (score.names).
from exam_lab.grader.score.names import CLASS_BYTES, CLASS_FILES  # noqa: E402,F401
#: What listing a class tar may read through, the members of students refused by their own bounds
#: included: a compressed tar is decompressed to find each next entry, so a student's file over its own
#: bounds (a 5 GB recording) is read, never kept, up to this bound of the class's.
CLASS_READ_BYTES = 4 * CLASS_BYTES
#: Characters kept at the end of the parts of a name too long to be a folder's (:func:`_fitting`): of
#: the student's name before Moodle's ``_<participant>_assignsubmission_<plugin>_``, and of the
#: student's own file name after it (an archive's ending).
_KEPT_END = 16


def list_students(class_path, scratch, refused=None):
    """``[(student, folder or archive)]`` of a class: one sub-folder per student, as "download all"
    gives.

    ``class_path`` may be an archive of that, unpacked below ``scratch`` by :func:`unpack_class`: the
    class's bounds as a whole, each student's files by the student's own; a student whose files are
    refused is listed all the same (an empty folder or file in its place) and ``refused`` (a dict)
    receives ``{its path: why}``. A class whose top holds archives instead of folders counts each
    archive as one student (named after it). A link is never followed; one named as Moodle names a
    student's folder is listed and refused (:data:`~exam_lab.grader.score.identity.LINKED`) when ``refused`` is given.
    """
    class_path = os.path.abspath(class_path)
    if os.path.isfile(class_path):
        class_path = unpack_class(class_path, os.path.join(scratch, 'class'), {} if refused is None else refused)
    return identity.class_listing(class_path, entry_kinds(class_path), refused)


def _class_entries(kind, opened, label):
    """``[(member, name, kind, size, link target)]`` of an open class archive, read as far as the
    class's bounds allow; raises UnpackError past them. Each student's entries are judged afterwards by
    that student's bounds (:func:`_student_plan`), a zip's and a tar's alike: a tar's member over them
    is read through (a compressed tar is decompressed while it is listed) within CLASS_READ_BYTES, and
    refuses its student only."""
    if kind == 'zip':
        count = len(opened.infolist())
        if count > CLASS_FILES:
            raise UnpackError('%s holds %d entries (at most %d for a class)' % (label, count, CLASS_FILES))
        return list(zip_entries(opened, links=False))
    entries, read = [], 0
    try:
        for entry in tar_entries(opened):
            read += entry[0].size
            if len(entries) >= CLASS_FILES:
                raise UnpackError('%s holds more than %d entries (at most %d for a class)' % (label, CLASS_FILES, CLASS_FILES))
            if read > CLASS_READ_BYTES:
                raise UnpackError('%s: listing it would read %d bytes (at most %d for a class, students '
                                  'refused by their own bounds included)' % (label, read, CLASS_READ_BYTES))
            entries.append(entry)
    except (tarfile.TarError, OSError, EOFError) as err:
        raise UnpackError('%s is not a readable tar archive: %s' % (label, err))
    return entries


def unpack_class(archive, target, refused):
    """Unpack a class archive into ``target``; return the folder that holds one entry per student.

    The class is bounded as a whole: CLASS_FILES entries, CLASS_BYTES unpacked, and an entry that
    cannot be said to belong to one student (``../``, an absolute path at the top) refuses it. Each
    student's files (everything below its top folder, or its archive at the top) are checked and paid
    by the student's own bounds (:class:`~exam_lab.grader.boxed.archives.Budget`,
    :func:`~exam_lab.grader.boxed.archives.entry_path`): one that fails them is not unpacked, and
    ``refused`` receives ``{the student's path: why}`` (an empty folder, or an empty file for an
    archive, holds its place). No ratio of Moodle's compression is judged: a student's one-colour
    screenshot or log is no bomb, and the student's bytes are bounded by its budget."""
    label = os.path.basename(archive)
    kind, opened = open_archive(archive, label)
    with opened:
        groups, base = _students_of(_class_entries(kind, opened, label))
        os.makedirs(target, exist_ok=True)
        top = os.path.join(target, base) if base else target
        plans, total = [], 0
        for key, members in sorted(groups.items()):
            place = os.path.join(top, _fitting(key))
            try:
                plan = _student_plan(key, members)
            except UnpackError as err:
                refused[place] = str(err)
                plans.append((key, place, None, members))
                continue
            total += plan.nbytes
            plans.append((key, place, plan, members))
        if total > CLASS_BYTES:
            raise UnpackError('the students\' files in %s come to %d bytes (at most %d for a class)'
                              % (label, total, CLASS_BYTES))
        for key, place, plan, members in plans:
            archive_at_top = all(_file_at_top(*member) for member in members)
            if plan is not None:
                try:
                    _write_student(opened, kind, top if archive_at_top else place, plan)
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


def _fitting(key):
    """A student's top entry as a name this file system takes: one of more than NAME_MAX bytes (Moodle
    allows 100 characters each for a first and a last name: 300 bytes and more in Cyrillic or Chinese;
    a flat download's entry ends with the student's own file name) loses characters from the middle of
    the student's file name, then from the middle of the student's name, so that one long name stops no
    one else. Moodle's part, ``_<participant>_assignsubmission_<plugin>_``, is kept whole and first: the
    participant number read from the name (:func:`~exam_lab.grader.score.identity.participant_number`)
    is the one Moodle wrote, never one of the student's file name."""
    if _size(key) <= archives.NAME_MAX:
        return key
    span = moodle_span(key)
    if span is None:
        return _shortened(key, archives.NAME_MAX)
    head, moodle, tail = key[:span[0]], key[span[0]:span[1]], key[span[1]:]
    room = archives.NAME_MAX - _size(moodle)
    tail = _shortened(tail, room - _size(head))  # the student's file name first, then its name
    return _shortened(head, room - _size(tail)) + moodle + tail


def _size(name):
    return len(name.encode('utf-8', 'surrogateescape'))


def _shortened(part, room):
    """``part`` in at most ``room`` bytes when it can be: its middle cut (``-``), its last _KEPT_END
    characters kept."""
    if _size(part) <= room or not part:
        return part
    start, end = part[:-_KEPT_END], part[-_KEPT_END:]
    while start and _size(start + '-' + end) > room:
        start = start[:-1]
    return start + '-' + end


def _students_of(entries):
    """``({student's key: [(entry, parts below the class)]}, the class folder at the archive's top or
    '')``: the entries grouped by their top folder, or by the one below when the archive holds the class
    folder (unless that folder is one package, or one student's as Moodle names it). The class folder's
    own entry (``zip -r``) is a folder's, not a student's (:func:`_file_at_top`)."""
    groups = {}
    for entry in entries:
        parts, rooted = archives.name_parts(entry[1])
        if rooted or (parts and parts[0] == '..'):
            raise UnpackError('entry %s of the class archive lies outside it' % shown_name(entry[1]))
        if not parts or parts[0] == '__MACOSX':
            continue
        groups.setdefault(parts[0], []).append((entry, parts))
    if len(groups) == 1:
        (top, members), = groups.items()
        below = [(entry, parts) for entry, parts in members if len(parts) > 1]
        if below and not any(_file_at_top(entry, parts) for entry, parts in members) and \
                identity.participant_number(top) is None and \
                not any(parts[1:] == ['package.xml'] or parts[2:] == ['package.xml'] for _, parts in below):
            inner = {}
            for entry, parts in below:
                inner.setdefault(parts[1], []).append((entry, parts[1:]))
            return inner, top
    return groups, ''


def _file_at_top(entry, parts):
    """Whether a class archive's entry (its ``parts`` below the class) is a file at the class's top (an
    archive a student is), not a folder's own entry nor a file below a folder."""
    return len(parts) == 1 and entry[2] != 'dir'


def _student_plan(key, members):
    """The checked plan of one student's files, paid by its own budget; UnpackError when they fail."""
    if all(len(parts) == 1 and entry[2] in ('link', 'special') for entry, parts in members):
        raise UnpackError('%s is a %s in the class archive, not a folder or an archive: never followed'
                          % (shown_name(key), members[0][0][2]))
    plan = Plan(key)
    for (member, name, kind, size, link), parts in members:
        if len(parts) == 1 and kind != 'dir':
            plan.add(member, parts[0], kind, size, link)
        else:
            plan.add(member, '/'.join(parts[1:]), kind, size, link)
    if any(_file_at_top(*member) for member in members) and not all(_file_at_top(*member) for member in members):
        raise UnpackError('%s is both a file and a folder' % shown_name(key))
    budget = archives.Budget(archives.MAX_BYTES, archives.MAX_FILES)  # read now: a test may lower them
    budget.take(len(plan.files), plan.nbytes, 'the files of %s' % shown_name(key))
    return plan


def _write_student(opened, kind, target, plan):
    """Write one student's planned files below ``target`` (the class's folder for an archive at its top:
    the plan's one file is the student's key)."""
    try:
        write_plan(plan, target, kind, opened)
    except UNREADABLE as err:
        raise UnpackError('%s cannot be unpacked: %s' % (shown_name(plan.label), unreadable_why(err)))

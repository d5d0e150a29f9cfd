"""Who a submission is, from the name Moodle gave it: the participant number, Moodle's folder, the
student's name. Pure: no rospy, no I/O.

Moodle's "download all submissions" zip holds one folder per student, ``Jane Doe_1234567_
assignsubmission_file_`` (or, flat, files named with that prefix): the number is the participant's
unique id, the same as in the offline grading worksheet's ``Participant 1234567``. One definition
here for everyone who tells students apart: the box that lists a class (its folders' names), the
runner (the grade record's ``participant`` and ``folder``), and the outputs sent back to Moodle
(the worksheet, hand.csv, the feedback pages).
"""
import collections
import os
import re

from exam_lab.grader.score.names import ARCHIVE_ENDINGS, SKIPPED_DIRS, without_ending

#: The participant's number in a "download all submissions" name (folder or flat file): ASCII digits, as
#: Moodle's importer takes it (PHP's is_numeric: a name with another script's digits is no number).
_FOLDER_NUMBER = re.compile(r'_([0-9]+)_assign(?:submission|feedback)_')
#: The whole prefix Moodle gives a student's folder (or flat file) in that zip: the folder of Moodle 3.1 to
#: 4.0 and a flat file's prefix end in '_', a folder of Moodle 4.1 on ends with the plugin's name.
_MOODLE_FOLDER = re.compile(r'^(.*?_[0-9]+_assign(?:submission|feedback)_[a-z]+(?:_|$))')
#: Moodle's own part of a "download all submissions" name, from the number to the plugin's name.
_MOODLE_PART = re.compile(r'_[0-9]+_assign(?:submission|feedback)_[a-z]+(?:_|$)')
#: Endings of the files a class's run writes in OUT beside the students' folders (grades.csv, index.html,
#: hand.csv, similarity.json, the filled worksheet...): a student's folder never has one.
OUTPUT_ENDINGS = ('.csv', '.html', '.json', '.jsonl', '.md', '.png', '.txt', '.log', '.zip')

#: Why a student's entry of a class folder that is a link is not graded (:func:`class_listing`).
LINKED = ('a link in the class folder, not a folder: the grader follows no link inside a class (put the '
          'folder itself there, or grade it alone: make grade SUBMISSION=...)')

#: Who a grade record is (:func:`identity`).
Identity = collections.namedtuple('Identity', 'participant folder key')


def participant_number(name):
    """The participant's unique id in a Moodle "download all submissions" name, or None."""
    match = _FOLDER_NUMBER.search(name + '_' if not name.endswith('_') else name)
    return int(match.group(1)) if match else None


def moodle_span(name):
    """``(start, end)`` of Moodle's part of a "download all submissions" name (``_1234_assignsubmission_
    file_``: the participant number, :func:`participant_number`'s), or None: what a name shortened to
    fit a folder keeps whole."""
    match = _MOODLE_PART.search(name)
    return match.span() if match else None


def identity(record):
    """Who a grade record is, for everything kept across runs and everything sent back to Moodle.

    :returns: :class:`Identity`: ``participant``, Moodle's participant number (the record's, read from
        the "download all submissions" name) or None; ``folder``, the name Moodle gave the student's
        folder in that zip (``Jane Doe_1234567_assignsubmission_file_``; for a flat download, the same
        prefix of the file's name) or None when the name is not Moodle's; ``key``, what identifies the
        student across runs: ``('participant', 1234567)`` where there is a number, else ``('name',
        student)``. The student's name is for display only where there is a number: two students with
        the same or nearly the same name (``Jane Doe`` and ``Jane Doe.``, both cleaned to ``Jane Doe``)
        have two keys.
    """
    number = record.get('participant')
    name = record.get('folder') or ''
    if number is None:
        number = participant_number(name)
    match = _MOODLE_FOLDER.match(name) if number is not None else None
    folder = match.group(1) if match and participant_number(match.group(1)) == number else None
    return Identity(number, folder, ('participant', number) if number is not None else ('name', record['student']))


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


def class_listing(folder, entries, refused=None):
    """``[(student, path)]`` of a class folder from its entries' names and kinds only (``[(name, kind)]``,
    kind ``dir``, ``file``, ``link`` or ``other``: nothing is opened), as "download all" gives: one
    sub-folder or archive per student (named after it), and each student of a flat download (Moodle's
    "Download submissions in folders" off: ``<name>_<number>_assignsubmission_<plugin>_<file>`` at the
    top) none of whose files is an archive (a report only, an online text: its first file its
    submission, graded "not graded" saying what it handed in, never left out unsaid). ``folder`` is
    joined to each name, never read. A link is never followed; one named as Moodle names a student's
    folder is listed, and refused (:data:`LINKED`) in ``refused`` (a dict ``{path: why}``) when it is
    given; a path already in ``refused`` (a student refused by its own bounds: an empty file holds its
    place) is listed whatever its name. Root lists a class folder with it
    (:func:`~exam_lab.grader.host.classfolder.list_students`), the intake's box an unpacked class."""
    students, flat = [], []
    for name, kind in sorted(entries):
        full = os.path.join(folder, name)
        if _hidden(name) or name in SKIPPED_DIRS:
            continue
        if kind == 'link':
            # Never followed (what it names is nobody's upload); but one named as Moodle names a
            # student's folder is that student's row, not graded, and why: never a student lost unsaid.
            if refused is not None and participant_number(name) is not None:
                students.append((student_name(without_ending(name)), full))
                refused[full] = LINKED
        elif kind == 'dir':
            students.append((student_name(name), full))
        elif name.lower().endswith(ARCHIVE_ENDINGS) or (refused is not None and full in refused):
            students.append((student_name(without_ending(name)), full))
        elif kind == 'file':
            flat.append((name, full))
    numbers = set(participant_number(os.path.basename(path)) for _, path in students)
    for name, full in flat:
        number = participant_number(name)
        if number is not None and number not in numbers:
            numbers.add(number)
            students.append((student_name(name), full))
    return students


def _hidden(entry):
    """A hidden name the listing passes over (``.DS_Store``, ``.git``, the ``._`` copies macOS leaves
    beside each file), but never a folder Moodle named after a student whose full name starts with a dot:
    ``.Anna Roy_77_assignsubmission_file_`` (Moodle's name never starts with ``._``: it writes ``_`` as
    a space)."""
    return entry.startswith('.') and (entry.startswith('._') or participant_number(entry) is None)

"""Which of a student's several uploads is the last: by the dates of its files, then by the version
number in its name; said ambiguous when neither tells, or when they disagree. No rospy here.
"""
import datetime
import os
import re
import tarfile
import zipfile

from exam_lab.grader.boxed.archives import archive_kind, without_ending, zip_entries

#: A version number at the end of an upload's name (its archive ending off): exam_v2, exam-2,
#: exam (2) as Moodle or a browser names a second copy, examV3.
_VERSION = re.compile(r'(?:^|[^0-9])(?:[vV]|[_ -]|\()(\d{1,3})\)?$')
#: Zip's "no date" (MS-DOS time starts in 1980): a date on or before it says nothing.
_NO_DATE = datetime.datetime(1980, 1, 2)


def archive_date(path):
    """The newest modification date of the files in an archive (what the student's machine wrote when
    it made it: its folders' entries and macOS's copies, as :func:`zip_entries` reads them, are none), or
    None when it has none the grader can read."""
    dates = []
    try:
        if archive_kind(path) == 'zip':
            with zipfile.ZipFile(path) as zf:
                dates = [datetime.datetime(*info.date_time) for info, _, kind, _, _ in zip_entries(zf, links=False)
                         if kind == 'file']
        elif archive_kind(path) == 'tar':
            with tarfile.open(path, 'r:*') as tf:
                dates = [datetime.datetime.utcfromtimestamp(m.mtime) for m in tf if m.isfile()]
    except (zipfile.BadZipFile, tarfile.TarError, OSError, EOFError, ValueError, OverflowError):
        return None
    dates = [d for d in dates if d > _NO_DATE]
    return max(dates) if dates else None


def version_number(name):
    """The version number at the end of an upload's name (``exam_v2.zip``: 2), or None."""
    match = _VERSION.search(without_ending(os.path.basename(name)))
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

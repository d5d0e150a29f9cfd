"""Unpack a class archive ("download all submissions"), as a box's uid: one folder or archive per student.

The class run (:mod:`exam_lab.grader.class_run`) starts it in a box of its own, without network,
bounded in time and memory::

    python3 -m exam_lab.grader.boxed.intake --class /box/upload/<class.zip> --out /box/out

and reads back ``OUT/intake.json``, an :class:`~exam_lab.grader.score.records.IntakeRecord`: each
student's name and the path of its submission relative to ``OUT``, and why its files were refused when
they were (:func:`~exam_lab.grader.boxed.classlist.unpack_class`: that student's row says so, the others
are graded). (A class that is a folder is not
unpacked: root lists its entries by name, and stages each student's upload for that student's box.)
"""
import argparse
import os
import sys

from exam_lab.grader.boxed import archives, bounds, classlist
from exam_lab.grader.score import records

#: Most characters of why a student's files were refused: a class of MAX_STUDENTS refused students, with
#: their names and folders, stays within intake.json's bytes (the reasons are one sentence, their names
#: cut to 80 characters).
MAX_REFUSED = 500


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--class', dest='klass', required=True, help='the class archive')
    parser.add_argument('--out', required=True, help='the folder to unpack into, and to write intake.json in')
    args = parser.parse_args(argv)
    if os.getuid() == 0:
        sys.stderr.write('intake: refusing to unpack a class archive as root\n')
        return 2
    refused = {}
    try:
        students = classlist.list_students(args.klass, args.out, refused)
    except archives.UnpackError as err:
        sys.stderr.write('intake: the class archive cannot be opened safely: %s\n' % err)
        return 3
    if len(students) > records.IntakeRecord.MAX_STUDENTS:  # a class's bound, as its entries and bytes are
        sys.stderr.write('intake: the class archive holds %d students (at most %d for a class)\n'
                         % (len(students), records.IntakeRecord.MAX_STUDENTS))
        return 3
    try:
        records.write(args.out, records.IntakeRecord, bounds.fit({
            'uid': os.getuid(), 'students': [dict({'name': name, 'path': os.path.relpath(path, args.out)},
                                                  **({'refused': bounds.cut(refused[path], MAX_REFUSED)}
                                                     if path in refused else {}))
                                             for name, path in students]}, records.IntakeRecord, None))
    except records.RecordError as err:  # a sentence for the teacher, not a traceback
        sys.stderr.write('intake: its record exceeds a bound: %s\n' % err)
        return 4
    return 0


if __name__ == '__main__':
    sys.exit(main())

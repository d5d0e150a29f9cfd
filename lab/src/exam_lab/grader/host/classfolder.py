"""A class given as a folder, listed by root: its entries' names and kinds (lstat, never following a
link), nothing of them opened. The students are the pure listing's
(:func:`~exam_lab.grader.score.identity.class_listing`), the same the intake's box gives of an archive
it unpacked: root never runs the box's code (boxed/) to list a class.
"""
import os

from exam_lab.grader.score import identity
from exam_lab.grader.score.names import entry_kinds


def list_students(class_path, refused=None):
    """``[(student, folder or archive)]`` of the class folder ``class_path`` (see
    :func:`~exam_lab.grader.score.identity.class_listing`; ``refused``: ``{path: why}`` of the entries
    that are links named as Moodle names a student's folder)."""
    class_path = os.path.abspath(class_path)
    return identity.class_listing(class_path, entry_kinds(class_path), refused)

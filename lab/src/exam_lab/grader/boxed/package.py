"""The student's package in one submission: found in a folder, an archive, archives in archives, a
whole workspace, and copied for the build. No rospy here.

Archives are unpacked by :func:`~exam_lab.grader.boxed.archives.safe_extract`, every one of a
submission paid from one budget; of several uploads holding a package, the last one is graded
(:func:`~exam_lab.grader.boxed.uploads.choose_upload`). Copies of folders never follow links.
"""
import os
import shutil
import xml.etree.ElementTree as ET

from exam_lab.grader.boxed.archives import (ARCHIVE_ENDINGS, MAX_LISTED, MAX_PARTS, SKIPPED_DIRS, Budget,
                                            UnpackError, archive_kind, listed, safe_extract, shown_name, what_it_is)
from exam_lab.grader.boxed.uploads import archive_date, choose_upload, version_number
from exam_lab.grader.score.sheets import PACKAGE, drone_packages

#: How deep below a submission the package may sit (the zip's top, one folder down, a workspace's src).
MAX_DEPTH = 4
#: How many archives deep a package may sit (a zip holding the package's zip, holding ...).
MAX_NESTING = 2
#: What is said of a package beyond MAX_DEPTH, of an archive beyond MAX_NESTING: the cap that left it out.
_TOO_DEEP = 'the grader looks for the package %d folders deep at most' % MAX_DEPTH
_TOO_NESTED = 'the grader opens archives %d deep at most' % MAX_NESTING
_BEYOND = (_TOO_DEEP + ')', _TOO_NESTED + ')')
#: Packages that are the simulators, never a student's answer (a whole workspace holds them too).
SIMULATORS = ('node_kit', 'drone_sim') + tuple(drone_packages())


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


def _student_packages(root, max_depth=MAX_DEPTH):
    """Packages below ``root`` that may be the answer: ``exam`` first; else any that is no simulator,
    those with ``exam`` in their name first."""
    exact = find_packages(root, max_depth=max_depth)
    if exact:
        return exact
    others = [p for p in find_packages(root, name=None, max_depth=max_depth)
              if package_name(os.path.join(p, 'package.xml')) not in SIMULATORS]
    return sorted(others, key=lambda p: ('exam' not in (package_name(os.path.join(p, 'package.xml')) or ''),
                                         p.count(os.sep), p))


def open_submission(path, scratch, notes, fixes=None, budget=None, uploads=None):
    """The folder of the student's package in a submission: a folder, an archive, a folder of
    archives, archives in archives (``MAX_NESTING`` deep), a whole workspace.

    Archives are unpacked (checked) below ``scratch``, all paid from one ``budget``. ``notes`` receives
    what the teacher should know (other candidates, refused archives, what was dropped); ``fixes`` the
    changes to what the student uploaded (links dropped, a package not named ``exam``); ``uploads``
    one ``{"files", "chosen", "why", "ambiguous"}`` per choice among several uploads holding a package
    (:func:`~exam_lab.grader.boxed.uploads.choose_upload`). Raises UnpackError when there is no
    package, saying what was found instead.
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
        refused = [s for s in seen if '(refused: ' in s or 'cannot be opened' in s or s.endswith(_BEYOND)]
        if refused:  # the reason is the archive that could not be opened, or a cap, not a missing package
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
    if not found:  # one deeper than the search goes is said as that cap, not as no package at all
        seen.extend('%s is %d folders deep (%s)' % (shown_name(os.path.relpath(os.path.join(p, 'package.xml'), root)),
                                                   os.path.relpath(p, root).count(os.sep) + 1, _TOO_DEEP)
                    for p in _student_packages(root, MAX_PARTS)[:1])
    if found or depth >= MAX_NESTING:
        if not found:
            seen.extend('%s is an archive inside archives (%s)' % (shown_name(os.path.relpath(a, root)), _TOO_NESTED)
                        for a in sorted(_archives_in(root))[:1])
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

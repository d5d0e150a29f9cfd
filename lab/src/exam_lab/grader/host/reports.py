"""A student's report read in a box, and the copies the teacher grades from: root's side.

:func:`read_report` stages the submission (the student's Moodle folder, or its one file: a zip, a
PDF) byte for byte, runs :mod:`exam_lab.grader.boxed.report_reader` on it in a box of its own (as the
box's uid, without network, within :data:`REPORT_BOUNDS`), reads back one capped, checked
:class:`~exam_lab.grader.score.records.ReportRecord` and keeps, in the student's folder of OUT:

- ``report.json``, the record (make rescore and the proposals read it again, never the box);
- ``report/``, the files handed in as the report, as handed in, and the PNG of each page read (what
  the review page shows beside the proposals), every file read-only.

:func:`keep_code` copies the package's source as handed in (the inspection's copy) to ``code/``,
read-only. Whatever happens to one report (a bomb, a crash of the box, its bounds), it is that
student's report "not read" with why: never the grade's stop, never the class's.
"""
import dataclasses
import os
import shutil
import stat
import time

from exam_lab.grader import contract
from exam_lab.grader.host import cgroups, limits, sandbox, staging
from exam_lab.grader.host.boxed_run import Boxed, InspectionFailed
from exam_lab.grader.score.records import ReportRecord

#: Bounds of the reader's box (wall clock s, CPU s, address space bytes): room for the OCR of a scan's
#: pages, the reader's own clock stopping first (report_reader.SECONDS; what a reading takes, wall and
#: CPU: lab/bench/reports.md, make bench); LibreOffice wants a large address space. Each of its tools is bounded inside the box too (the reader's own timeouts).
REPORT_BOUNDS = (150.0, 150, 4 << 30)
#: What root copies back of the box's report/ folder: bytes of one file, and of all.
COPY_FILE_BYTES = 64 << 20
COPY_BYTES = 256 << 20
#: What of the package's source is copied to code/ (the package as handed in: a few files of kB).
CODE_FILES = 500
CODE_BYTES = 32 << 20
#: /etc files the reader's tools read beyond a ROS process's: fontconfig's (LibreOffice, poppler) and
#: LibreOffice's configuration (its registry: without it, it aborts).
READER_ETC = ('/etc/fonts', '/etc/libreoffice')
_PNG = b'\x89PNG\r\n\x1a\n'


def read_report(submission, out_dir, *, timeout=None, jobs=1, watch=None):
    """Read the report(s) of ``submission`` (a student's folder or file) in a box; write
    ``out_dir/report.json`` and ``out_dir/report/``; return the checked
    :class:`~exam_lab.grader.score.records.ReportRecord`. Never raises for the student's bytes: a
    report that cannot be read, or a box that fails, is a record "not read" with why.

    :param timeout: the wall clock left for it (REPORT_BOUNDS's when None or larger).
    :param jobs: gradings side by side: the box's part of the CPU.
    :param watch: a :class:`~exam_lab.grader.host.timings.Stopwatch` whose stage in progress is charged the
        box's CPU (its cgroup's count: what runs under bubblewrap is never waited for).
    """
    start = time.monotonic()
    wall = min(REPORT_BOUNDS[0], timeout) if timeout else REPORT_BOUNDS[0]
    work = staging.new_work('exam-report-')
    try:
        folder = os.path.basename(os.path.abspath(submission).rstrip('/'))
        try:
            (upload,) = staging.stage_work(work, [(folder, os.path.realpath(submission))])
            with sandbox.Box(work, bwrap=sandbox.check() is None, cpus=limits.box_cpus(jobs)) as box:
                boxed = Boxed(box, work, [(path, None, False) for path in READER_ETC if os.path.isdir(path)])
                try:
                    found = boxed.run('exam_lab.grader.boxed.report_reader',
                                      ['--upload', boxed.path(upload), '--out', boxed.path(boxed.out)],
                                      ReportRecord, (wall,) + REPORT_BOUNDS[1:])
                finally:
                    if watch is not None:
                        watch.add_cpu(cgroups.cpu_use(box.cgroups))
                record = keep_copies(found, boxed.out, out_dir)
        except staging.UploadRefused as err:
            record = ReportRecord.not_read('the submission was not staged for the reader: %s' % err)
        except InspectionFailed as err:
            record = ReportRecord.not_read('the reader\'s box failed: %s' % err)
        except Exception as err:  # the grader's own bug: this student's report, never the grade or the class
            record = ReportRecord.not_read('the grader failed reading the report: %r' % err)
        record = record.replaced(seconds=round(time.monotonic() - start, 2))
        write(out_dir, record)
        return record
    finally:
        shutil.rmtree(work, ignore_errors=True)


def write(out_dir, record):
    """``out_dir/report.json``, by the contract's writer."""
    contract.write_record(os.path.join(out_dir, ReportRecord.FILE), record)


def _box_bytes(path, cap):
    """The bytes of a box's regular file ``path``, or None (missing, a link, not a regular file, over
    ``cap``): a file kept for the teacher whole or not at all."""
    try:
        return contract.read_bytes(path, cap)
    except contract.ContractError:
        return None


def keep_copies(record, box_out, out_dir):
    """Copy the files ``record`` names (``files[].copy``, ``pages[].image``: ``report/<name>`` of the
    box's ``box_out``) to ``out_dir/report/``, read-only, through the contract (regular files only, never a
    link, capped; a page image must be a PNG); return the record with what could not be copied set to
    None and said in its notes. The old ``report/`` of an earlier run is replaced."""
    target = os.path.join(out_dir, 'report')
    remove_read_only(target)
    os.makedirs(target)
    budget, notes = [COPY_BYTES], []

    def take(path, png):
        if path is None:
            return None
        name = path[len('report/'):]
        data = _box_bytes(os.path.join(box_out, 'report', name), min(COPY_FILE_BYTES, budget[0]))
        if data is None or (png and not data.startswith(_PNG)):
            notes.append('%s: not kept (%s)' % (path, 'not a PNG' if data is not None else
                                                'missing, not a regular file or over its bytes'))
            return None
        budget[0] -= len(data)
        contract.write_bytes(os.path.join(target, name), data, mode=0o444)
        return path
    files = [dataclasses.replace(f, copy=take(f.copy, False)) for f in record.files]
    pages = [dataclasses.replace(p, image=take(p.image, True)) for p in record.pages]
    return record.replaced(files=files, pages=pages, notes=record.notes + tuple(notes))


def keep_code(source, out_dir):
    """Copy the package's source as handed in (``source``: the inspection's copy in its box's output)
    to ``out_dir/code/``, read-only (regular files and folders only, capped: CODE_FILES, CODE_BYTES);
    returns the notes on what was not copied. No source (nothing was found to grade): no code/."""
    target = os.path.join(out_dir, 'code')
    remove_read_only(target)
    if not os.path.isdir(source) or os.path.islink(source):
        return []
    skipped = contract.copy_tree(source, target, CODE_FILES, CODE_BYTES)
    for dirpath, dirnames, filenames in os.walk(target):
        for name in filenames:
            os.chmod(os.path.join(dirpath, name), 0o444)
    return ['code/: not copied: %s' % ', '.join(skipped[:20]) + (' and %d more' % (len(skipped) - 20)
                                                                if len(skipped) > 20 else '')] if skipped else []


def remove_read_only(folder):
    """Remove ``folder`` (a copy this module made: its files read-only), never following a link."""
    if os.path.islink(folder) or os.path.isfile(folder):
        os.unlink(folder)
    elif os.path.isdir(folder):
        for dirpath, dirnames, _ in os.walk(folder):
            os.chmod(dirpath, stat.S_IRWXU | stat.S_IRGRP | stat.S_IXGRP | stat.S_IROTH | stat.S_IXOTH)
        shutil.rmtree(folder)


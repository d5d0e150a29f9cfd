"""Grading a class: its students listed (for both engines: the local pool here and
:mod:`~exam_lab.grader.engine.slurm`), each graded by :func:`grade_student` (one submission, by the runner),
side by side in a pool of threads; the class's similarity check.
"""
import concurrent.futures
import json
import os
import re
import shutil

from exam_lab.grader import contract, runner
from exam_lab.grader.host import classfolder, reports, sandbox, similarity_setup, staging
from exam_lab.grader.host.boxed_run import INTAKE_BOUNDS, SIMILARITY_BOUNDS, Boxed, InspectionFailed
from exam_lab.grader.host.underlay import default_underlay, ensure_underlay
from exam_lab.grader.host.bwrap import can_isolate
from exam_lab.grader.publish import desk, grades, report
from exam_lab.grader.score import identity, records, schema
from exam_lab.grader.score.names import CLASS_BYTES
from exam_lab.grader.score.records import UnpackError
from exam_lab.grader.score import kept as kept_records

#: What one grading costs, as it timed itself (``logs/timings.json``, :mod:`~exam_lab.grader.host.timings`):
#: CPU s (its boxes' cgroups, its judge, the grader's own thread) and wall s, ``good_student`` graded
#: alone with its two runs side by side, measured 2026-12-01 on two cores under a load average of 4
#: to 8 (other work): 13.2 s of CPU in 50.2 s. A grading mostly waits: its flights are timed.
GRADING_CPU_S = 13.2
GRADING_WALL_S = 50.2
#: The part of the cores the default JOBS fills on average: what is left absorbs the bursts (two
#: roslaunch starts at once, a build) so that no flight's node is starved; each box is held to
#: cores/JOBS besides, and the judge outweighs it. Measured 2026-12-01, classes of 12 on two cores
#: shared with other work: JOBS=4 (60 %) kept every point at a load average of 7 to 22; JOBS=5 (75 %)
#: lost 8 of 12 nodes' starts (not registered within START_TIMEOUT) at a load of 40.
CPU_SHARE = 0.6
#: Memory one grading is counted for when JOBS is not given: its processes use a few hundred MB (the
#: bounds are higher: each box 2 GB, each master 384 MB, each probe 512 MB).
JOB_MEMORY_BYTES = 1 << 30


def default_jobs(cores=None, memory=None, cpu=GRADING_CPU_S, wall=GRADING_WALL_S):
    """JOBS when the teacher gives none, from what the machine has: as many gradings as fill CPU_SHARE
    of the cores this process may run on, each using ``cpu`` s of CPU in ``wall`` s, no more than the
    memory holds at JOB_MEMORY_BYTES each, at least 1."""
    if cores is None:
        cores = len(os.sched_getaffinity(0)) if hasattr(os, 'sched_getaffinity') else (os.cpu_count() or 1)
    by_cpu = int(cores * CPU_SHARE * wall / cpu)
    if memory is None:
        try:
            memory = os.sysconf('SC_PAGE_SIZE') * os.sysconf('SC_PHYS_PAGES')
        except (ValueError, OSError):
            memory = JOB_MEMORY_BYTES * by_cpu
    return max(1, min(by_cpu, memory // JOB_MEMORY_BYTES))


def worst_case(students, jobs):
    """Seconds a class of ``students`` takes at most, ``jobs`` side by side, when every grading uses
    its whole budget: ceil(students / jobs) gradings one after the other, each
    :data:`~exam_lab.grader.runner.STUDENT_BUDGET` + :data:`~exam_lab.grader.runner.AFTER_BUDGET_S` (the
    class's own steps, its intake and similarity check, aside: INTAKE_BOUNDS, SIMILARITY_BOUNDS)."""
    return -(-students // max(1, jobs)) * (runner.STUDENT_BUDGET + runner.AFTER_BUDGET_S)


def class_students(class_path, work_dirs, scratch=None, refused=None, out=None):
    """``[(student, folder or archive)]`` of a class, each name unique (``Jane Doe``, ``Jane Doe_2``):
    the students both engines grade (:func:`grade_class`, :mod:`exam_lab.grader.engine.slurm`); with
    ``out``, the folder of an earlier run of the class, each student keeps the name (the folder in OUT)
    that run gave its participant number (:func:`kept_folders`). A
    folder is listed by root, by its entries' names only (:func:`~exam_lab.grader.host.classfolder.list_students`
    opens no file of a folder); an archive is unpacked by :mod:`exam_lab.grader.boxed.intake` in a box of
    its own (INTAKE_BOUNDS), in a work folder made in ``scratch`` (default: the system's temp folder) and
    appended to ``work_dirs`` (the caller removes it once the students are graded). ``refused`` (a
    dict) receives ``{folder: why}`` of the students whose files the intake refused by their own
    bounds, or whose entry of a class folder is a link (:func:`grade_student`'s ``refused``).

    :raises UnpackError: the archive could not be unpacked (why, and the end of the box's log).
    """
    # The teacher's path, followed (as a submission's is): a link to the class's zip is that zip. Its
    # entries are not: a link in a class folder is passed over (classfolder.list_students).
    class_path = os.path.realpath(class_path)
    if not os.path.isfile(class_path):
        return _unique(classfolder.list_students(class_path, refused), kept_folders(out))
    if scratch:
        os.makedirs(scratch, mode=0o711, exist_ok=True)
    # One file, bounded as a class (a class of 60 with its PDFs is more than one upload may be).
    work = staging.new_work('exam-intake-', scratch)
    work_dirs.append(work)
    (staged,) = staging.stage_work(work, [(os.path.basename(class_path), class_path)], (CLASS_BYTES, 1))
    with sandbox.Box(work, bwrap=sandbox.check() is None) as box:
        boxed = Boxed(box, work)
        try:
            found = boxed.run('exam_lab.grader.boxed.intake', ['--class', boxed.path(staged), '--out',
                                                                 boxed.path(boxed.out)], records.IntakeRecord,
                              INTAKE_BOUNDS)
        except InspectionFailed as err:
            raise UnpackError('unpacking it in its box failed: %s' % err)
    students = []
    for student in found.students:
        path = os.path.join(boxed.out, student.path)
        if os.path.realpath(path) != os.path.normpath(path) or not os.path.lexists(path):
            raise UnpackError('the intake named %s, which is a link or missing' % student.path)
        if student.refused is not None and refused is not None:
            refused[path] = student.refused
        students.append((student.name, path))
    return _unique(students, kept_folders(out))


def kept_folders(out):
    """``{participant number: folder name}`` of the students an earlier run graded into ``out`` (from
    each folder's measurements.json, else its grade.json; written by the grader, never by a box).

    Lenient on purpose, unlike every other reader of these files: a file that is not a record of
    today's grader (an older shape no upgrade knows, one edited by hand, one cut short by a full disk)
    still says whose folder it is when it holds a participant number. Read strictly, it would free
    that folder for a classmate of the same name, whose grading would then overwrite the kept
    measurements and grade of another student. Only the number and Moodle's folder name are taken
    from it (never shown, never a path: the folder's own name is), read up to the record's cap; a
    file of any other shape holds none."""
    kept = {}
    if not out or not os.path.isdir(out):
        return kept
    for name in contract.folders(out):
        for record_type in (kept_records.MeasurementsRecord, kept_records.GradeRecord):
            try:  # through the contract: no link, a regular file, capped; its shape unchecked on purpose
                facts = schema.load(contract.read_bytes(os.path.join(out, name, record_type.FILE),
                                                        record_type.MAX_BYTES, under=out),
                                    record_type.FILE, constants=True)
            except (OSError, records.RecordError):
                continue
            if record_type is kept_records.MeasurementsRecord and isinstance(facts, dict):
                facts = facts.get('extra')
            if not isinstance(facts, dict):
                continue
            number = facts.get('participant')
            if number is None and isinstance(facts.get('folder'), str):
                number = identity.participant_number(facts['folder'])
            if isinstance(number, int) and not isinstance(number, bool):
                kept.setdefault(number, name)
            break
    return kept


def _unique(students, kept=None):
    """Each student's name made unique (``Jane Doe``, ``Jane Doe_2``): it is the student's folder in
    OUT, which never ends like one of the class's files (:func:`~exam_lab.grader.score.identity.student_name`).
    A participant that ``kept`` (:func:`kept_folders`) gives a folder keeps it, and no other
    student takes a folder of OUT that is a participant's: a classmate whose name cleans to the same
    (``Jane Doe.``) submitting late never takes the first one's folder, its kept measurements or its
    row (the rows of hand.csv and the worksheet are keyed by the number anyway)."""
    kept = kept or {}
    held = set(kept.values())
    named, seen = [None] * len(students), set()
    for index, (name, folder) in enumerate(students):
        previous = kept.get(identity.participant_number(os.path.basename(folder.rstrip('/'))))
        if previous is not None and previous not in seen and \
                (previous == name or re.match(r'^%s_\d+$' % re.escape(name), previous)):
            named[index] = previous
            seen.add(previous)
    for index, (name, _) in enumerate(students):
        if named[index] is None:
            unique, n = name, 2
            while unique in seen or unique in held:
                unique, n = '%s_%d' % (name, n), n + 1
            named[index] = unique
            seen.add(unique)
    return [(named[index], folder) for index, (_, folder) in enumerate(students)]


def grade_student(name, folder, out_dir, *, sheet=None, underlay=None, isolate=None, on_step=None,
                  unsandboxed=False, jobs=1, refused=None):
    """Grade one student of a class into ``out_dir/name``; return the record. Anything the grader
    raises is this student's record ("could not grade"), never the class's. Both engines grade a
    student with it: a local pool's thread and a Slurm task.

    :param refused: why the class's intake did not unpack this student's files (its own bounds): the
        student is not graded, with that sentence, and its measurements are kept for a rescore.
    """
    try:
        if refused is not None:
            return _refused_at_intake(name, folder, os.path.join(out_dir, name), sheet, refused)
        return runner.grade_submission(folder, os.path.join(out_dir, name), sheet=sheet, student=name, underlay=underlay,
                                       isolate=isolate,
                                       on_step=on_step, unsandboxed=unsandboxed, jobs=jobs)
    except Exception as err:  # anything: this student's row says so, the class goes on
        record = grades.could_not_grade(name, sheet, '%r' % err,
                                        [grades.bug_note()])
        moodle_name = os.path.basename(os.path.abspath(folder).rstrip('/'))
        record = dict(record, participant=identity.participant_number(moodle_name), folder=moodle_name)  # who, even so
        try:
            report.write_grade(os.path.join(out_dir, name), record)
        except (OSError, records.RecordError):  # its folder of OUT a link: nothing written through it
            pass
        return record


def _refused_at_intake(name, folder, out_dir, sheet, why):
    """The record of a student whose files the class's intake refused: nothing of it ran."""
    folder_name = os.path.basename(folder)
    measured = {'student': name, 'sheet': sheet or 'altitude', 'static': {}, 'notes': [], 'fixes': [],
                'comments': None, 'isolate': None, 'how_run': None,
                'session': grades.no_session(records.Outcome.REFUSED, 'submission refused: %s' % why, refused=True).value,
                'extra': {'participant': identity.participant_number(folder_name), 'folder': folder_name,
                          'documents': [], 'seconds': 0.0}}
    contract.make_folder(out_dir)
    reports.write(out_dir, records.ReportRecord.not_read(schema.cut('the class\'s intake refused this student\'s '
                                                                     'files: %s' % why)))
    return grades.keep_and_score(out_dir, measured)


def class_similarity(klass, out, records_):
    """The similarity check over a class's submissions, each named as its grade record names it, run in
    a box (:mod:`exam_lab.grader.boxed.similarity` ``--class``: unpacking and comparing, SIMILARITY_BOUNDS)
    and read back as a :class:`~exam_lab.grader.score.records.SimilarityRecord`, with a note for each
    student the intake refused; written to ``out/similarity.json`` and returned as that record (what
    the desk and ``make rescore`` read: :func:`~exam_lab.grader.publish.desk.finish`). A record of
    ``error`` when it could not run (the grades stand): every file written here is one
    SimilarityRecord reads back."""
    work_dirs, refused = [], {}
    try:
        by_folder = {r.get('folder'): r['student'] for r in records_}
        listed = [(by_folder.get(os.path.basename(folder), name), folder)
                  for name, folder in class_students(klass, work_dirs, refused=refused)]
        intake = [(name, folder) for name, folder in listed if folder not in refused]
        python = similarity_setup.ensure_venv()  # as root: an installation, from PyPI, of no student's bytes
        # Each student staged by its own bounds: one over them is not compared, the others are.
        work = staging.new_work('exam-similarity-')
        work_dirs.append(work)
        staged = staging.stage_work(work, [(os.path.basename(f), f) for _, f in intake], refused=refused)
        kept = [(student, path) for student, path in zip(intake, staged) if path is not None]
        submissions, staged = [student for student, _ in kept], [path for _, path in kept]
        similarity_setup.boilerplate(os.path.join(work, 'upload', 'boilerplate'))
        venv = os.path.dirname(os.path.dirname(python))
        with sandbox.Box(work, [venv], bwrap=sandbox.check() is None) as box:
            # copydetect imports matplotlib, which wants Debian's /etc/matplotlibrc
            boxed = Boxed(box, work, [(path, None, False) for path in ('/etc/matplotlibrc',) if os.path.isfile(path)])
            job = {'submissions': [[name, boxed.path(path)] for (name, _), path in zip(submissions, staged)],
                   'boilerplate': boxed.path(os.path.join(work, 'upload', 'boilerplate')), 'python': python,
                   'out': boxed.path(boxed.out)}
            with open(os.path.join(work, 'upload', 'job.json'), 'w') as f:
                json.dump(job, f)
            result = boxed.run('exam_lab.grader.boxed.similarity', ['--class', boxed.path(f.name)],
                               records.SimilarityRecord, SIMILARITY_BOUNDS, python=python).value
        # The intake's words of why (a student's file names among them) are made safe with the record.
        refusals = ['%s: not compared (its files were refused: %s)' % (name, refused[folder])
                    for name, folder in listed if folder in refused]
        result = records.SimilarityRecord.make(dict(result, notes=schema.closed(refusals + result['notes'])))
    except Exception as err:  # a bug of the check, or its box failing, must not cost the class its page
        why = str(err) if isinstance(err, (InspectionFailed, UnpackError)) else repr(err)
        result = desk.similarity_failed(why)
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)
    contract.write_record(os.path.join(out, records.SimilarityRecord.FILE), result)
    return result


def grade_class(class_path, out_dir, *, sheet=None, jobs=None, isolate=None, progress=None, unsandboxed=False):
    """Grade every student of a class, ``jobs`` side by side (default :func:`default_jobs`); write each
    one's grade and grades.csv. One student the grader cannot grade is that student's row ("could not
    grade"), never the class's.

    :param progress: told of the run as it goes (:class:`exam_lab.grader.publish.progress.ClassProgress`).
    """
    refusal = sandbox.sandbox_refusal(unsandboxed)
    if refusal:
        raise sandbox.SandboxUnavailable(refusal)
    os.makedirs(out_dir, exist_ok=True)
    jobs = jobs or default_jobs()
    work_dirs, refused = [], {}
    try:
        students = class_students(class_path, work_dirs, refused=refused, out=out_dir)
        underlay = ensure_underlay(default_underlay())
        isolate = can_isolate() if isolate is None else isolate
        if progress:
            progress.begin([name for name, _ in students])

        def one(index):
            name, folder = students[index]
            if progress:
                progress.started(name)
            record = grade_student(name, folder, out_dir, sheet=sheet, underlay=underlay, isolate=isolate,
                                   on_step=(lambda step: progress.step(name, step)) if progress else None,
                                   unsandboxed=unsandboxed, jobs=jobs, refused=refused.get(folder))
            if progress:
                progress.finished(record)
            return record

        pool = concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs))
        futures = [pool.submit(one, index) for index in range(len(students))]
        try:
            records = [future.result() for future in futures]
        finally:
            # Interrupted (grade.py's Ctrl-C, SIGTERM), no student is started any more and the gradings
            # going on are not waited for: they end with this process (harness.supervisor's "Lifetime").
            for future in futures:
                future.cancel()
            pool.shutdown(wait=False)
        report.write_csv(os.path.join(out_dir, 'grades.csv'), records)
        return records
    finally:
        for work in work_dirs:
            shutil.rmtree(work, ignore_errors=True)

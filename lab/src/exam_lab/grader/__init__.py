"""The grader: scores a student's ``exam`` package by running it, against the sheets' rubric.

``make grade SUBMISSION=<dir or zip>`` or ``make grade CLASS=<dir or zip>`` (docs/grading.md).

The folder a module lives in says who runs it, on whose bytes (docs/grading.md, "Isolation"):

- ``boxed/`` -- as a box's uid, never root, on the student's bytes: :mod:`~.boxed.inspect` (reads one
  upload and writes its record), :mod:`~.boxed.intake` (a class archive), :mod:`~.boxed.archives` (one
  archive unpacked after checking every entry), :mod:`~.boxed.package` (the package found in an upload,
  copied), :mod:`~.boxed.uploads` (which of several uploads is the last), :mod:`~.boxed.classlist` (a
  class's students, from a folder or an archive), :mod:`~.boxed.source` (what the sources say;
  the teacher's fixes before running), :mod:`~.boxed.code_quality` (the code's comments per function
  and block, its signs of bad practice), :mod:`~.boxed.launch` (the launch file read without running it),
  :mod:`~.boxed.repair` (a launch file roslaunch refuses for its form, read and run repaired),
  :mod:`~.boxed.derive` (which launch file and threshold are run; the derived launch files the grader
  runs), :mod:`~.boxed.documents` (participant number, PDF
  reports), :mod:`~.boxed.report_reader` (the student's report read: text layer, OCR; converted by
  LibreOffice), :mod:`~.boxed.report_files` (which files are the report, of what kind),
  :mod:`~.boxed.report_text` (its text: lines, OCR words, underscores, pictures' places),
  :mod:`~.boxed.report_images` (its pictures prepared for OCR, PIL),
  :mod:`~.boxed.similarity` (similar submissions, copydetect in a venv of its own),
  :mod:`~.boxed.bounds` (what a box puts into its record, cut to the record's caps with a sentence).
- ``judge/`` -- a judge uid, never root, never reading the student's files: :mod:`~.judge.probe`
  (rospy: plays the drone with the harness's fake drone, measures; its entry point), :mod:`~.judge.graph`
  (the master's view, rospy's refusals, the clock, the node's pid watched), :mod:`~.judge.node` (the
  student's node, its inputs and output found), :mod:`~.judge.pilot` (the inputs set, the calibration,
  the legs flown) and :mod:`~.judge.legs` (the legs' holds and checks, pure).
- ``host/`` -- root: :mod:`~.host.session` (builds and runs one submission: the student's steps in its
  box, the master and the probe as the slot's judge uid), :mod:`~.host.run` (one run: its master, the
  launch, the probe; what they said), :mod:`~.host.side_by_side` (the two runs at once, each in a box and
  a network namespace of its own), :mod:`~.host.timings` (each stage's wall and CPU time), :mod:`~.host.sandbox` (the box: opened, its command lines, run, closed),
  :mod:`~.host.uids` (a slot's box and judge uids, under a lock; what runs as them ended),
  :mod:`~.host.cgroups` (the box's and the judge's cgroups), :mod:`~.host.limits` (their bounds;
  prlimit), :mod:`~.host.bwrap` (bubblewrap's command line; the session's network namespace),
  :mod:`~.host.staging` (the upload copied byte for byte; the box's work folder), :mod:`~.host.classfolder`
  (a class folder's students, by its entries' names), :mod:`~.host.similarity_setup` (the similarity
  check's venv and boilerplate, made by root before its box), :mod:`~.host.boxed_run` (one of the grader's
  modules run in a box on student bytes, its record read back), :mod:`~.host.reports` (the report read in a box
  of its own; the report's and the code's copies kept for the teacher), :mod:`~.host.underlay` (the simulators'
  workspace, built once, under every student's package) and :mod:`~.host.reference` (the sheet's drone
  run alone in a network namespace, the report's commands' outputs captured: the reference of questions 4-9).
- ``score/`` -- pure: :mod:`~.score.sheets` (each sheet's names, the delay, the items and maxima),
  :mod:`~.score.rubric` (points, evidence and status from the measurements: :func:`~.score.rubric.score`)
  and its parts: :mod:`~.score.tolerances` (each tolerance, one constant), :mod:`~.score.measured` (the
  session's runs and probes as the items read them), :mod:`~.score.node_items` (runs, Q10-Q12),
  :mod:`~.score.flight` (the flight's calls, legs and lags; the WARNING's window),
  :mod:`~.score.timing_items` (Q13, Q14a, Q14b), :mod:`~.score.verdict` (the status, the doubts),
  :mod:`~.score.runs` (whether a run counts: its result's times, the clock, the master, the judge's deaths);
  :mod:`~.score.fields` (a record read by attributes, following its schema), :mod:`~.score.safe_text`
  (student-derived text without control characters, for every record and output), :mod:`~.score.records`
  (the typed records that cross the boundary, with their schemas), :mod:`~.score.inspection`
  (what the inspection's box read of a submission), :mod:`~.score.job` (the session's job and each
  run's plan, root's orders), :mod:`~.score.kept` (what a grading
  keeps, as records: its measurements and its grade, versioned), :mod:`~.score.schema` (a schema, its
  check, the base of every record), :mod:`~.score.answers` (the report's questions 4-9 found by their
  headings and judged by named checks), :mod:`~.score.report_tables` (a report's table read from its
  layout: the questions' rows, their cells), :mod:`~.score.report_text` (what of a passage is the
  student's own: commands, output, sentences), :mod:`~.score.code_items` (the comments and the code
  quality proposed from the inspection's measures), :mod:`~.score.reference` (the drone's reference
  outputs as a record, and what of them every run shares), :mod:`~.score.identity` (who a submission is:
  Moodle's participant number and folder, the student's name; a class listed from its entries' names),
  :mod:`~.score.names` (archive endings, folders never taken, both sides' alike) and :mod:`~.score.boxenv`
  (the paths and the environment a box's processes see).
- ``publish/`` -- what the teacher reads, from records only: :mod:`~.publish.report` (grade.json,
  grade.md, grades.csv, the terminal table), :mod:`~.publish.desk` (writes the rest into OUT),
  :mod:`~.publish.page` (index.html), :mod:`~.publish.flightplot`, :mod:`~.publish.moodle` (the
  offline grading worksheet), :mod:`~.publish.gradescope` (results.json), :mod:`~.publish.progress`
  (k of n, the time left; a run's steps), :mod:`~.publish.hand` (the teacher's hand points, hand.csv),
  :mod:`~.publish.feedback` (each student's page for Moodle, moodle-feedback.zip), :mod:`~.publish.cells`
  (a CSV cell a spreadsheet cannot run, read back exactly), :mod:`~.publish.proposals` (the hand points
  proposed: proposals.csv, each student's proposals.json),
  :mod:`~.publish.provenance` (what made a grade), :mod:`~.publish.student_view` (what ``make check``
  shows a student), :mod:`~.publish.grades` (the grade record from the measurements: the rubric applied,
  by a run and by a rescore alike; the rescore), :mod:`~.publish.teacher` (the teacher's notes of a
  grade: what the machine saw but does not score, how the code was read and run), :mod:`~.publish.review`
  (``make review``: the hand points confirmed on a page served to 127.0.0.1, into hand.csv).
- :mod:`~exam_lab.grader.contract` -- root's one reader of a file it did not write in this process (a
  box's or the judge's record and logs, every file kept in OUT: no link followed, regular files only,
  never blocking, capped, checked against its type) and its one writer in OUT (a temporary file, then
  ``os.replace``: never through an existing entry).
- :mod:`~exam_lab.grader.runner` -- one submission, top to bottom: stage, inspect (boxed), plan, build
  and run (box and judge), score (:func:`~exam_lab.grader.publish.grades.score`, also for a rescore),
  publish.
- :mod:`~exam_lab.grader.class_run` -- a class: its students listed (for every engine), each graded by
  the runner in a local pool; the class's similarity check.
- ``engine/`` -- the host, as the teacher: where else a class is graded, each student by
  :func:`~exam_lab.grader.class_run.grade_student` (:mod:`~.engine.slurm`: an array job on a Slurm cluster).
"""
import os


def workspace():
    """The project's build workspace ($EXAM_WS, set by tools/env.sh; .ws/ by default): the grader's
    caches (the simulators' underlay, the similarity venv) and default output live there."""
    return os.environ.get('EXAM_WS', os.path.join(os.getcwd(), '.ws'))

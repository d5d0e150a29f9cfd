"""The grader: scores a student's ``exam`` package by running it, against the sheets' rubric.

``make grade SUBMISSION=<dir or zip>`` or ``make grade CLASS=<dir or zip>`` (docs/grading.md).

Modules (the pure ones import no rospy and are unit-tested in lab/test/unit):

- :mod:`~exam_lab.grader.sheets` -- each sheet's names, the delay, the rubric's items and maxima.
- :mod:`~exam_lab.grader.unpack` -- safe unzipping, finding the package, a class's students.
- :mod:`~exam_lab.grader.source` -- what the sources say (node scripts, params read, comments) and
  the teacher's fixes before running (chmod +x, a python3 shebang).
- :mod:`~exam_lab.grader.launch` -- the launch file read without running it (drone, exam node,
  the threshold however it is set) and the derived launch files the grader runs.
- :mod:`~exam_lab.grader.rubric` -- points and evidence from the measurements.
- :mod:`~exam_lab.grader.report` -- grade.json, grade.md, grades.csv, the terminal table.
- :mod:`~exam_lab.grader.probe` -- (rospy) plays the drone with the harness's fake drone, measures.
- :mod:`~exam_lab.grader.sandbox` -- the box a submission's code runs in (bubblewrap, a uid of its
  own, limits) and the capped, regular-file-only copy of what a session leaves.
- :mod:`~exam_lab.grader.session` -- builds and runs one submission: the student's steps in its box,
  the master and probe outside.
- :mod:`~exam_lab.grader.runner` -- one submission or a class: prepare, isolate, score, write.

The teacher's desk, after grading (docs/grading.md, "The teacher's desk"):

- :mod:`~exam_lab.grader.desk` -- writes what follows into OUT after a run.
- :mod:`~exam_lab.grader.page` -- index.html: the class's table, histogram, who needs the teacher.
- :mod:`~exam_lab.grader.flightplot` -- each student's flight plot (matplotlib, Agg).
- :mod:`~exam_lab.grader.moodle` -- Moodle's offline grading worksheet, filled.
- :mod:`~exam_lab.grader.gradescope` -- Gradescope's results.json.
- :mod:`~exam_lab.grader.similarity` -- similar submissions (copydetect, in a venv of its own).
- :mod:`~exam_lab.grader.documents` -- the participant number and the PDF reports of a submission.
- :mod:`~exam_lab.grader.progress` -- k of n, who is graded now, the time left; a run's steps.
"""

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
- :mod:`~exam_lab.grader.session` -- builds and runs one submission under the harness's Supervisor.
- :mod:`~exam_lab.grader.runner` -- one submission or a class: prepare, isolate, score, write.
"""

"""Where a class's students are graded besides this machine's own pool: :mod:`~.slurm` (an array job on
a Slurm cluster). An engine runs on the host as the teacher and grades each student with the local
run's own code path (:func:`exam_lab.grader.class_run.grade_student`)."""

"""The grader's class runs that its test modules read, each graded once a session in a child process
of its own and started together when the session knows its tests (conftest.py; issue 37 point 6).

A grading mostly waits for its flight (about 60 s of wall clock, a few seconds of CPU), so classes
graded one after the other leave the machine idle: started together, as many gradings side by side
as conftest.py's budget allows, they take the time of the longest instead of the sum. A child process,
not a thread: a test that monkeypatches the grader (a budget, a rubric constant, ``os.geteuid``) must
not reach a class graded meanwhile.

``python3 class_runs.py <run> <folder>`` grades the run in the folder and writes its result (JSON) to
``<folder>/result.json``; RUNS names each run, its function and its weight (how many gradings it
runs side by side, the part of the budget it holds).
"""
import concurrent.futures
import json
import os
import pathlib
import sys

HERE = os.path.dirname(os.path.realpath(__file__))
RESULT = 'result.json'


def main_class(root):
    """test_grade's main class (:func:`test_grade.grade_main_class`), its desk written as ``make grade``
    writes it (the page, the feedback zip, the similarity check): ``{'out', 'klass', 'records' (graded
    order), 'lines' (what the desk printed)}``."""
    import test_grade
    from exam_lab.grader import class_run
    from exam_lab.grader.publish import desk
    out, records, klass = test_grade.grade_main_class(pathlib.Path(root))
    lines = desk.finish(str(out), records, similar=class_run.class_similarity(str(klass), str(out), records))
    return {'out': str(out), 'klass': str(klass), 'records': records, 'lines': lines}


def fair_class(root):
    """test_grade's third kind of class (:func:`test_grade.grade_fair_class`): ``{'out', 'records'}``."""
    import test_grade
    out, records = test_grade.grade_fair_class(pathlib.Path(root))
    return {'out': str(out), 'records': records}


def fairness_sample(root):
    """test_fairness's sample of generated answers graded as one class: ``{'records'}``."""
    import test_fairness
    from exam_lab.grader import class_run
    klass = test_fairness.generator.write_class(test_fairness.SAMPLE, os.path.join(root, 'class'))
    return {'records': class_run.grade_class(klass, os.path.join(root, 'out'), jobs=class_run.default_jobs())}


#: The single submissions graded on a sheet named, not detected: ``name: (package, sheet)``.
SINGLES = {
    'simple_altitude': ('simple_answer', 'altitude'),   # test_simple_answer: full marks on both sheets
    'simple_depth': ('simple_answer', 'depth'),
    'ours_depth': ('ours', 'depth'),                    # test_grade: our node on the depth sheet
    'simple_many_files': ('many_files', 'altitude'),    # test_simple_answer: 501 Python files, one over a cap
}


#: How many of SINGLES are graded side by side.
SINGLES_JOBS = 2


def singles(root):
    """Each of SINGLES graded alone (``grade_submission``, as ``make grade SUBMISSION=...`` does),
    SINGLES_JOBS side by side: ``{name: record}``."""
    import test_grade
    import test_simple_answer
    from exam_lab.grader import runner
    from exam_lab.grader.host import underlay
    packages = {'simple_answer': test_simple_answer.SIMPLE, 'ours': test_grade.OUR_EXAM,
                'many_files': test_simple_answer.many_files(os.path.join(root, 'many_files'))}

    def one(name):
        package, sheet = SINGLES[name]
        return name, runner.grade_submission(packages[package], os.path.join(root, name), sheet=sheet,
                                             jobs=SINGLES_JOBS)
    underlay.ensure_underlay(underlay.default_underlay())  # once, before three gradings wait on its lock
    with concurrent.futures.ThreadPoolExecutor(max_workers=SINGLES_JOBS) as pool:
        return dict(pool.map(one, sorted(SINGLES)))


def _class_jobs():
    from exam_lab.grader import class_run
    return class_run.default_jobs()


#: ``run: (function, its weight)``; the weight is a callable (the default JOBS is this machine's).
RUNS = {
    'main_class': (main_class, _class_jobs),
    'singles': (singles, lambda: SINGLES_JOBS),
    'fair_class': (fair_class, _class_jobs),
    'fairness_sample': (fairness_sample, _class_jobs),
}


def main(argv):
    name, root = argv
    result = RUNS[name][0](root)
    path = os.path.join(root, RESULT)
    with open(path + '.part', 'w') as f:
        json.dump(result, f)
    os.replace(path + '.part', path)


if __name__ == '__main__':
    sys.path.insert(0, HERE)
    main(sys.argv[1:])

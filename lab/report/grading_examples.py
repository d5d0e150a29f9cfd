#!/usr/bin/env python3
"""Writes the example grades of docs/grading.md ("Two real grades") from a real grader run.

Usage: lab/report/grading_examples.py   (as root, where the grader's sandbox works; about 2 minutes:
two submissions graded one after the other)

It grades this repository's own exam/ package and the student package
lab/test/grader/submissions/no_kelvin, each as `make grade SUBMISSION=<dir>` does (the sheet chosen
by the grader), and
puts each grade.md, verbatim, between its markers in docs/grading.md
(``<!-- example NAME: ... -->`` and ``<!-- end of example NAME -->``): nobody types an example grade.
"""
import os
import re
import sys
import tempfile

from exam_lab.grader import runner

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
GRADING = os.path.join(REPO, 'docs', 'grading.md')
#: (name in docs/grading.md's markers, submission folder); the sheet is the grader's own choice.
EXAMPLES = [('ours', 'exam'), ('no_kelvin', 'lab/test/grader/submissions/no_kelvin')]
BEGIN = '<!-- example %s: written by lab/report/grading_examples.py from a grader run; do not edit -->'
END = '<!-- end of example %s -->'


def splice(text, name, grade_md):
    """``text`` with the block between example ``name``'s markers replaced by ``grade_md``, fenced."""
    pattern = re.compile(r'(%s\n).*?(\n%s)' % (re.escape(BEGIN % name), re.escape(END % name)), re.S)
    if not pattern.search(text):
        raise ValueError('docs/grading.md has no markers for the example %r' % name)
    block = '```markdown\n%s\n```' % grade_md.strip()
    return pattern.sub(lambda m: m.group(1) + block + m.group(2), text, count=1)


def main():
    with open(GRADING) as f:
        text = f.read()
    with tempfile.TemporaryDirectory(prefix='grading-examples-') as out:
        for name, submission in EXAMPLES:
            folder = os.path.join(out, name)
            record = runner.grade_submission(os.path.join(REPO, submission), folder)
            print('grading_examples: %s: %s / %s' % (submission, record['total'], record['max']), flush=True)
            with open(os.path.join(folder, 'grade.md')) as f:
                text = splice(text, name, f.read())
    with open(GRADING, 'w') as f:
        f.write(text)
    print('grading_examples: docs/grading.md written')
    return 0


if __name__ == '__main__':
    sys.exit(main())

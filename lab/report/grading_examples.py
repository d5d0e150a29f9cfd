#!/usr/bin/env python3
"""Writes the example grades of docs/grading.md ("Two real grades") from a real grader run.

Usage: lab/report/grading_examples.py [NAME...]   (as root, where the grader's sandbox works; about 2
minutes: two submissions graded one after the other; NAME, ours or no_kelvin, grades only those)

It grades this repository's own exam/ package and the student package
lab/test/grader/submissions/no_kelvin, each as `make grade SUBMISSION=<dir>` does (the sheet chosen
by the grader), and
puts each grade.md, verbatim, between its markers in docs/grading.md
(``<!-- example NAME: ... -->`` and ``<!-- end of example NAME -->``): nobody types an example grade.

no_kelvin is graded from a folder named as Moodle's "download all submissions" names one
(FEEDBACK_FOLDER), and its student's feedback page, as ``moodle-feedback.zip`` holds it with the
evidence shown, is written to docs/feedback_example.html; the markers ``<!-- example feedback ... -->``
get the zip's folder name, and its screenshot is docs/figures/feedback_page.png (headless Chromium, the
PNG tagged with the page's digest: lab/report/screenshots.py). lab/test/grader/test_page_browser.py
opens that page in Chromium.
"""
import os
import re
import shutil
import sys
import tempfile
import zipfile

from exam_lab.grader import runner
from exam_lab.grader.publish import feedback

import screenshots

# realpath: a test imports this from the workspace's src/ link, and docs/ is the repository's.
REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
GRADING = os.path.join(REPO, 'docs', 'grading.md')
#: (name in docs/grading.md's markers, submission folder); the sheet is the grader's own choice.
EXAMPLES = [('ours', 'exam'), ('no_kelvin', 'lab/test/grader/submissions/no_kelvin')]
BEGIN = '<!-- example %s: written by lab/report/grading_examples.py from a grader run; do not edit -->'
END = '<!-- end of example %s -->'
#: The example whose feedback page docs/grading.md shows, and the Moodle download folder it is graded from.
FEEDBACK_OF, FEEDBACK_FOLDER = 'no_kelvin', 'Paul Martin_102_assignsubmission_file_'
FEEDBACK_PAGE = os.path.join(REPO, 'docs', 'feedback_example.html')


def splice(text, name, grade_md, fence='markdown'):
    """``text`` with the block between example ``name``'s markers replaced by ``grade_md``, fenced."""
    pattern = re.compile(r'(%s\n).*?(\n%s)' % (re.escape(BEGIN % name), re.escape(END % name)), re.S)
    if not pattern.search(text):
        raise ValueError('docs/grading.md has no markers for the example %r' % name)
    block = '```%s\n%s\n```' % (fence, grade_md.strip())
    return pattern.sub(lambda m: m.group(1) + block + m.group(2), text, count=1)


def feedback_page(folder, record):
    """``(its folder in the zip, the page)``: the one student's page of ``folder``'s moodle-feedback.zip,
    the evidence shown."""
    lines = feedback.write(folder, [record], single=True, show='evidence')
    with zipfile.ZipFile(os.path.join(folder, feedback.FILE)) as archive:
        names = archive.namelist()
        if len(names) != 1:
            raise RuntimeError('no feedback page for %s: %s' % (record['student'], ' '.join(lines)))
        return names[0].split('/')[0], archive.read(names[0]).decode('utf-8')


def main(argv=None):
    names = (sys.argv[1:] if argv is None else argv) or [name for name, _ in EXAMPLES]
    unknown = set(names) - {name for name, _ in EXAMPLES}
    if unknown:
        print('grading_examples: no example %s (of %s)' % (', '.join(sorted(unknown)),
                                                         ', '.join(name for name, _ in EXAMPLES)), file=sys.stderr)
        return 2
    with open(GRADING) as f:
        text = f.read()
    with tempfile.TemporaryDirectory(prefix='grading-examples-') as out:
        for name, submission in EXAMPLES:
            if name not in names:
                continue
            folder = os.path.join(out, name)
            source = os.path.join(REPO, submission)
            if name == FEEDBACK_OF:  # a copy named as Moodle names it: the participant number is in the name
                source = os.path.join(out, 'moodle', FEEDBACK_FOLDER, 'exam')
                shutil.copytree(os.path.join(REPO, submission, 'exam'), source, symlinks=True)
                source = os.path.dirname(source)
            record = runner.grade_submission(source, folder, student=name)
            print('grading_examples: %s: %s / %s' % (submission, record['total'], record['max']), flush=True)
            with open(os.path.join(folder, 'grade.md')) as f:
                text = splice(text, name, f.read())
            if name == FEEDBACK_OF:
                zipped, page = feedback_page(folder, record)
                with open(FEEDBACK_PAGE, 'w') as f:
                    f.write(page)
                text = splice(text, 'feedback', '%s/%s' % (zipped, feedback.PAGE), fence='text')
                screenshots.take(FEEDBACK_PAGE, screenshots.FEEDBACK_PNG, (1000, 1750), screenshots.digest(FEEDBACK_PAGE))
                print('grading_examples: %s and %s written' % (os.path.relpath(FEEDBACK_PAGE, REPO),
                                                             os.path.relpath(screenshots.FEEDBACK_PNG, REPO)))
    with open(GRADING, 'w') as f:
        f.write(text)
    print('grading_examples: docs/grading.md written')
    return 0


if __name__ == '__main__':
    sys.exit(main())

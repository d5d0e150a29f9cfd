"""docs/operations.md's master-restart console, taken from a real run of its test, never typed.

Runs ``lab/test/ops/test_master_restart.py -k killed`` (the master killed and restarted mid-flight),
reads the launch's console it keeps (``launch.log`` under pytest's ``--basetemp``), and writes, between
the markers of docs/operations.md, every line from the warning service's connection to the last
re-registration, unedited, with the line numbers, the date and the commit of the run. The docs test
(lab/test/docs/test_docs_quote_code.py) holds the block to that form.

Usage (in the workspace environment: ``source tools/env.sh``)::

    python3 lab/report/console_excerpt.py [--log LAUNCH_LOG]   # --log: splice a kept console, no run

No rospy here; the test it runs starts its own masters.
"""
import argparse
import datetime
import glob
import os
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
DOC = os.path.join(REPO, 'docs', 'operations.md')
TEST = os.path.join(REPO, 'lab', 'test', 'ops', 'test_master_restart.py')
BEGIN = '<!-- console: written by lab/report/console_excerpt.py from a run of test_master_restart.py; do not edit -->'
END = '<!-- end of console -->'
#: The excerpt: from the first line holding FIRST to the last line holding LAST, both included.
FIRST = ': connected to rosrpc://'
LAST = ' restarted after '


def excerpt(lines):
    """(first line number, last line number, the lines between them) of a console, 1-based."""
    starts = [i for i, line in enumerate(lines) if FIRST in line]
    ends = [i for i, line in enumerate(lines) if LAST in line]
    if not starts or not ends or ends[-1] < starts[0]:
        raise ValueError('the console has no line with %r followed by one with %r' % (FIRST, LAST))
    return starts[0] + 1, ends[-1] + 1, lines[starts[0]:ends[-1] + 1]


def block(first, last, lines, date, commit):
    """The Markdown between (and with) the markers."""
    return '\n'.join([BEGIN,
                      'Lines %d to %d of the launch\'s console, unedited, in the run of %s at commit %s:'
                      % (first, last, date, commit),
                      '', '```'] + lines + ['```', END])


def splice(text, new_block, begin=BEGIN, end=END):
    """``text`` with the block between ``begin`` and ``end`` (markers included) replaced by ``new_block``."""
    start, end = text.index(begin), text.index(end) + len(end)
    return text[:start] + new_block + text[end:]


def commit():
    out = subprocess.run(['git', '-C', REPO, 'rev-parse', '--short=12', 'HEAD'], stdout=subprocess.PIPE,
                         universal_newlines=True, check=True).stdout.strip()
    dirty = subprocess.run(['git', '-C', REPO, 'status', '--porcelain', '--untracked-files=no'],
                           stdout=subprocess.PIPE, universal_newlines=True, check=True).stdout.strip()
    return out + ('+changes' if dirty else '')


def run_test(basetemp):
    """Run the test once; the path of the console it kept."""
    done = subprocess.run([sys.executable, '-m', 'pytest', '-q', '-p', 'no:cacheprovider', '--basetemp', basetemp,
                           TEST, '-k', 'killed'], cwd=REPO)
    if done.returncode != 0:
        sys.exit('console_excerpt: the test failed; docs/operations.md is left as it was')
    # pytest also links the newest test folder as ...current: one file, whatever its names.
    found = sorted({os.path.realpath(p) for p in glob.glob(os.path.join(basetemp, '*', 'launch.log'))})
    if len(found) != 1:
        sys.exit('console_excerpt: expected one launch.log under %s, found %s' % (basetemp, found))
    return found[0]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--log', help='a launch.log kept from a run of the test (default: run it now)')
    args = parser.parse_args(argv)
    date = datetime.datetime.utcnow().strftime('%Y-%m-%d %H:%M UTC')
    with tempfile.TemporaryDirectory(prefix='console-excerpt-') as scratch:
        log = args.log or run_test(os.path.join(scratch, 'pytest'))
        if args.log:
            date = datetime.datetime.utcfromtimestamp(os.path.getmtime(log)).strftime('%Y-%m-%d %H:%M UTC')
        with open(log, encoding='utf-8', errors='replace') as f:
            first, last, lines = excerpt(f.read().splitlines())
    with open(DOC, encoding='utf-8') as f:
        text = f.read()
    with open(DOC, 'w', encoding='utf-8') as f:
        f.write(splice(text, block(first, last, lines, date, commit())))
    print('console_excerpt: lines %d to %d written into %s' % (first, last, os.path.relpath(DOC, REPO)))


if __name__ == '__main__':
    main()

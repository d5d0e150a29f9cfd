"""Summarise catkin test results as the line `N passed, N failed, N skipped`.

Usage: test_summary.py RESULTS_DIR. Exit status 0 only when something ran and nothing failed.

Counting rule: pytest-*.xml and rosunit-*.xml hold the test cases themselves. A rostest-*.xml only
wraps one .test file: it counts once when its launch or test node broke (failure/error with no test
case report of its own), never for the cases it wraps, so nothing is counted twice.
"""
import pathlib
import sys
import xml.etree.ElementTree as ET


def count_file(path):
    """Return (passed, failed, skipped, names): ``names`` holds "FAILED <test>" for each failure and
    "SKIPPED <test>: <reason>" for each skip, so a test skipped for a missing tool is seen, not only counted."""
    root = ET.parse(path).getroot()
    suites = [root] if root.tag == 'testsuite' else root.iter('testsuite')
    passed = failed = skipped = 0
    names = []
    wrapper = path.name.startswith('rostest-')
    for suite in suites:
        for case in suite.iter('testcase'):
            label = '%s: %s.%s' % (path.parent.name, case.get('classname'), case.get('name'))
            if case.find('failure') is not None or case.find('error') is not None:
                failed += 1
                names.append('FAILED ' + label)
            elif case.find('skipped') is not None:
                skipped += 1
                reason = case.find('skipped').get('message') or (case.find('skipped').text or '').strip()
                names.append('SKIPPED %s: %s' % (label, ' '.join(reason.split())[:200]))
            elif not wrapper:
                passed += 1
    return passed, failed, skipped, names


def main(argv):
    results = pathlib.Path(argv[1])
    totals = [0, 0, 0]
    failed_names = []
    files = sorted(results.rglob('*.xml')) if results.is_dir() else []
    for path in files:
        try:
            p, f, s, names = count_file(path)
        except ET.ParseError as err:
            p, f, s, names = 0, 1, 0, ['FAILED %s: unreadable result file (%s)' % (path, err)]
        totals[0] += p
        totals[1] += f
        totals[2] += s
        failed_names += names
    for name in sorted(failed_names, key=lambda n: not n.startswith('SKIPPED')):
        print(name)
    if not files:
        print('no test result files under %s' % results)
    print('%d passed, %d failed, %d skipped' % tuple(totals))
    return 0 if totals[0] > 0 and totals[1] == 0 else 1


if __name__ == '__main__':
    sys.exit(main(sys.argv))

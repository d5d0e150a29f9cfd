"""The parts of the simple answer (docs/simple_answer/exam) that answer each of questions 10 to 14.

docs/report.md shows them in the question's box as ``{{excerpt NAME}}``. An excerpt is a list of line
ranges of one file, each given by a regular expression for its first line and one for its last (the
first match at or after the first line), so an edit of the simple answer moves the excerpt with it; a
range whose first or last line is no longer there is an error, never a hole or a wrong part. Ranges
that do not touch are joined by a line ``# ...`` (``<!-- ... -->`` in XML), indented like the next
range, so the reader sees where code was left out. A Python range that starts inside a block brings the
lines that open its blocks (``def main():``, ``while ...:``), so every line shows at the indent it has
in the file and an excerpt pasted lands where the file has it (a subscriber under ``def main():``, never
under the callback printed above it). The first line of an excerpt names its file. No rospy here.
"""
import os
import re

ALTITUDE = 'docs/simple_answer/exam/scripts/exam_node.py'
DEPTH = 'docs/simple_answer/exam/scripts/exam_submarine_node.py'
ALTITUDE_LAUNCH = 'docs/simple_answer/exam/launch/exam.launch'
PACKAGE_XML = 'docs/simple_answer/exam/package.xml'
CMAKELISTS = 'docs/simple_answer/exam/CMakeLists.txt'


def _sheet(path, sensor, output, ticks):
    """The ranges of one sheet's node for questions 11, 13, 14a and 14b (both nodes have one layout)."""
    return {
        'q10': (path, [(r'^from std_msgs', r'^from std_msgs'),
                       (r'^def \w+_callback\(msg\)', r'^    %s = msg\.data' % sensor),
                       (r'# Question 10: one subscriber', r"rospy\.Subscriber\('/%s'" % sensor)]),
        'q11': (path, [(r'^# The latest value received', r'^    %s = msg\.data' % sensor),
                       (r'^def compute_', r'^    return '),
                       (r'# Question 11: the publisher', r'%s_pub = rospy\.Publisher' % output),
                       (r'rate = rospy\.Rate\(10\)', r'rate = rospy\.Rate\(10\)'),
                       (r'while not rospy\.is_shutdown\(\):', r'%s_pub\.publish' % output),
                       (r'rate\.sleep\(\)', r'rate\.sleep\(\)')]),
        'q13': (path, [(r'^from \w+\.srv import', r'^from \w+\.srv import'),
                       (r'# Question 13: wait until', r'set_led = rospy\.ServiceProxy'),
                       (r'warning = False', r'warning = False'),
                       (r'# Question 13: call the service only', r"rospy\.loginfo\(.*NORMAL'")]),
        'q14a': (path, [(r'# Question 14a:', r"rospy\.loginfo\('threshold")]),
        'q14b': (path, [(r'%s = 0 ' % ticks, r'%s = 0 ' % ticks),
                        (r'# Question 14b: count', r'^                %s = 0' % ticks),
                        (r'# 5 s = 50 periods', r"set_led\('WARNING'\)")]),
    }


def _all():
    excerpts = {}
    for sheet, (path, sensor, output, ticks) in (
            ('altitude', (ALTITUDE, 'pressure', 'altitude', 'ticks_above')),
            ('depth', (DEPTH, 'pressure_remote', 'depth', 'ticks_deeper'))):
        for question, spec in _sheet(path, sensor, output, ticks).items():
            excerpts['%s.%s' % (question, sheet)] = spec
    # Question 9: what catkin_create_pkg wrote and the simple answer kept: the dependencies.
    excerpts['q9.package'] = (PACKAGE_XML, [(r'<name>exam</name>', r'<name>exam</name>'),
                                            (r'<buildtool_depend>', r'</package>')])
    excerpts['q9.cmake'] = (CMAKELISTS, [(r'^project\(exam\)', r'^project\(exam\)'),
                                         (r'^## The drones', r'^catkin_package\(\)'),
                                         (r'^## Python nodes', r'^\)$')])
    excerpts['q14a.altitude.launch'] = (ALTITUDE_LAUNCH, [(r'<!-- Question 14a', r'<arg name="threshold"'),
                                                          (r'<node pkg="exam"', r'</node>')])
    return excerpts


#: name -> (path in the repository, [(first-line regex, last-line regex), ...])
EXCERPTS = _all()


def line_ranges(lines, ranges, where):
    """[(first, last)] line indices (0-based, inclusive) of each range of ``ranges`` in ``lines``."""
    found = []
    for first_pattern, last_pattern in ranges:
        starts = [i for i, line in enumerate(lines) if re.search(first_pattern, line)]
        if not starts:
            raise ValueError('%s: no line matches %r' % (where, first_pattern))
        ends = [i for i in range(starts[0], len(lines)) if re.search(last_pattern, lines[i])]
        if not ends:
            raise ValueError('%s: no line matches %r after line %d' % (where, last_pattern, starts[0] + 1))
        found.append((starts[0], ends[0]))
    return found


def _indent(line):
    return len(line) - len(line.lstrip())


def openers(lines, first):
    """The indices of the lines that open the blocks line ``first`` is in (``def main():``, then
    ``while ...:``), outermost first: for each, the nearest line above with less indent that is not
    blank nor a comment."""
    found, level = [], _indent(lines[first])
    for i in range(first - 1, -1, -1):
        text = lines[i].strip()
        if level == 0:
            break
        if text and not text.startswith('#') and _indent(lines[i]) < level:
            found.append(i)
            level = _indent(lines[i])
    return found[::-1]


def excerpt(repo, name):
    """The text of excerpt ``name``: a comment line naming the file and its lines, then the ranges."""
    if name not in EXCERPTS:
        raise KeyError('unknown excerpt %r (lab/report/excerpts.py)' % name)
    path, ranges = EXCERPTS[name]
    with open(os.path.join(repo, path)) as f:
        lines = f.read().splitlines()
    xml = path.endswith(('.launch', '.xml'))
    found = line_ranges(lines, ranges, '%s (%s)' % (path, name))
    if not xml:
        found = sorted(set(found) | {(i, i) for first, _ in found for i in openers(lines, first)})
    merged = []
    for first, last in found:
        if merged and first <= merged[-1][1] + 1:
            merged[-1] = (merged[-1][0], max(last, merged[-1][1]))
        else:
            merged.append((first, last))
    out = []
    for first, last in merged:
        if out:
            indent = re.match(r'\s*', lines[first]).group(0)
            out.append(indent + ('<!-- ... -->' if xml else '# ...'))
        out.extend(lines[first:last + 1])
    where = ['%d' % (first + 1) if first == last else '%d-%d' % (first + 1, last + 1) for first, last in merged]
    while out and not out[-1].strip():
        out.pop()
    title = '%s, lines %s' % (os.path.relpath(path, 'docs/simple_answer'), ', '.join(where))
    return '\n'.join([('<!-- %s -->' if xml else '# %s') % title] + out)

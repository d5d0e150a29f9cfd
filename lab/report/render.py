#!/usr/bin/env python3
"""Fills docs/report.md from report_template.md with the outputs of a run, and draws the figures.

Usage: render.py --work DIR --repo DIR   (DIR of collect.py: outputs.json and the three bags)

The template is Markdown with placeholders, each replaced by something this run produced:

- ``{{run KEY}}``: a console block with the command line of command_list.py and its real output (cut
  where command_list.py says so, with the number of lines left out);
- ``{{line KEY}}``: the command line alone (a background command: a launch, a recording);
- ``{{value NAME}}``: a number or short text computed from the run (see :func:`facts`);
- ``{{block NAME}}``: a preformatted block computed from the run (log excerpts, comparisons);
- ``{{file PATH}}``: a file of the repository, verbatim;
- ``{{source MODULE:NAME}}``: the source of one function or class of the code, verbatim;
- ``{{excerpt NAME}}``: the lines of the simple answer that answer one question (excerpts.py).

Placeholders of one kind (run, source, block) separated by blank lines only share one block. A
placeholder alone on a line of a block quote (``> {{file PATH}}``) becomes a block inside the quote:
the answer boxes of questions 9 to 14 hold the simple answer's code that way. A line ``LEFT || RIGHT``,
each side one or more placeholders, puts sheet 000's command outputs beside sheet 001's (a two-column
table of raw HTML, which pandoc and GitHub both keep): the questions part stays within its 10 pages.
Code (``file``, ``source``, ``excerpt``) is never put side by side: sheet 001's comes below sheet 000's,
at full width, so no line of it wraps in the PDF (report.css; the docs test measures the lines).

An unknown placeholder or key is an error: the report never shows a hole.
"""
import argparse
import importlib
import inspect
import json
import math
import os
import re
import shlex
import socket
import subprocess
import textwrap
import time
import xml.etree.ElementTree as ET

from exam import formulas
from mydrone import atmosphere

import analysis
import command_list
import excerpts
import figures

PLACEHOLDER = re.compile(r'\{\{(run|line|value|block|file|source|excerpt) ([^ }]+)\}\}')
#: A placeholder alone on a line of a block quote.
QUOTED = re.compile(r'^> (\{\{(?:run|block|file|source|excerpt) [^ }]+\}\})$', re.M)
#: Two sets of placeholders side by side: ``{{run a}} {{run b}} || {{run c}}``, maybe in a block quote.
PAIR = re.compile(r'^(> )?((?:\{\{[a-z]+ [^ }]+\}\} ?)+)\|\| ((?:\{\{[a-z]+ [^ }]+\}\} ?)+)$', re.M)
#: The placeholders that stand for code (a file, a function, an excerpt of the simple answer).
CODE = re.compile(r'\{\{(?:file|source|excerpt) ')
#: The fence language of a file, by its name: what pandoc highlights, and what report.css never wraps.
LANGUAGES = {'.launch': 'xml', '.xml': 'xml', '.py': 'python', '.srv': 'text', 'CMakeLists.txt': 'cmake'}


def language_of(path):
    name = os.path.basename(path)
    return LANGUAGES.get(name, LANGUAGES.get(os.path.splitext(name)[1], ''))


ANSI = re.compile(r'\x1b\][^\x07\x1b]*(\x07|\x1b\\)?|\x1b\[[0-9;]*[A-Za-z]|\][0-9];[^\n]*?(?=\n|$)')


def clean(text):
    """Console text without colour codes and terminal-title sequences."""
    return ANSI.sub('', text).replace('\r', '')


def last_rate(hz_output):
    """The last 'average rate' that ``rostopic hz`` printed, as a float."""
    rates = re.findall(r'average rate: ([0-9.]+)', hz_output)
    if not rates:
        raise RuntimeError('rostopic hz printed no rate (a loaded machine?); run make report again:\n'
                           + hz_output)
    return float(rates[-1])


def console_lines(text, pattern):
    """Lines of a console that match ``pattern`` (colour codes removed)."""
    return [line for line in clean(text).splitlines() if re.search(pattern, line)]


def log_excerpt(text, pattern):
    """The lines of a console that match ``pattern``, each run of lines left out marked in its place
    with their number, so that a reader never takes a filtered log for the whole one."""
    kept, skipped = [], 0
    for line in clean(text).splitlines():
        if re.search(pattern, line):
            if skipped:
                kept.append('[... %d line%s left out ...]' % (skipped, '' if skipped == 1 else 's'))
            kept.append(line)
            skipped = 0
        else:
            skipped += 1
    if not kept:
        raise RuntimeError('no line matches %r:\n%s' % (pattern, text[-2000:]))
    if skipped:
        kept.append('[... %d line%s left out ...]' % (skipped, '' if skipped == 1 else 's'))
    return '\n'.join(kept)


def uncommented(text, comment):
    """``text`` without its comments (``comment``: a regular expression) and blank lines."""
    return '\n'.join(line.rstrip() for line in re.sub(comment, '', text).splitlines() if line.strip())


def logged_threshold(console):
    """The threshold the simple answer logs at start (``threshold 150.0 m``)."""
    found = re.search(r'\]: threshold (-?[0-9.]+) m$', clean(console), re.M)
    if not found:
        raise RuntimeError('the simple answer logged no threshold:\n' + console[-2000:])
    return float(found.group(1))


def param_value(outputs, key):
    """The number ``rosparam get`` printed."""
    return float(outputs[key]['output'].strip())


def depends(package_xml_text):
    """{tag: [names]} of the dependency tags of a package.xml."""
    root = ET.fromstring(package_xml_text)
    found = {}
    for element in root:
        if element.tag.endswith('depend'):
            found.setdefault(element.tag, []).append(element.text.strip())
    return found


def fmt(value, digits=1):
    """``value`` with ``digits`` decimals; a value that rounds to zero prints as 0, never as -0.0."""
    text = '%.*f' % (digits, value)
    return text[1:] if text.startswith('-') and float(text) == 0.0 else text


def shown(command, output):
    """The part of ``output`` the report shows (see command_list.Command), with what was left out."""
    lines = output.splitlines()
    if command.show_from:
        starts = [i for i, line in enumerate(lines) if re.search(command.show_from, line)]
        if not starts:
            raise RuntimeError('%s: no line matches %r' % (command.key, command.show_from))
        if starts[0] > 0:
            lines = ['[... %d lines above left out ...]' % starts[0]] + lines[starts[0]:]
    if command.show_until:
        ends = [i for i, line in enumerate(lines) if re.search(command.show_until, line)]
        if not ends:
            raise RuntimeError('%s: no line matches %r' % (command.key, command.show_until))
        if ends[0] + 1 < len(lines):
            lines = lines[:ends[0] + 1] + ['[... %d more lines until Ctrl-C ...]' % (len(lines) - ends[0] - 1)]
    return '\n'.join(lines)


def run_facts(work, outputs, name, bag, inputs, compute, output, truth, led, threshold, delay):
    """analysis.summarise of one recorded run, with its origin at the roslaunch start.

    :param threshold: the run's threshold, or the key of the ``rosparam get`` that read it.
    """
    series = analysis.read_bag(os.path.join(work, bag))
    if isinstance(threshold, str):
        threshold = param_value(outputs, threshold)
    origin = outputs[name]['started']
    summary = analysis.summarise(series, inputs, compute, output, truth, led, threshold, delay, origin)
    summary['threshold'] = threshold
    summary['series'] = series
    return summary


def facts(work, repo, outputs):
    """Every {{value}} and {{block}} of the template, and the figures (written to docs/figures/)."""
    delay = param_value(outputs, 'flight.param_delay')
    flight = run_facts(work, outputs, 'flight.launch', 'flight.bag', ['/temperature', '/pressure'],
                       formulas.altitude, '/altitude', '/mydrone/true_altitude', '/alt_warn_led',
                       'flight.param_threshold', delay)
    custom = run_facts(work, outputs, 'custom.launch', 'flight_1200.bag', ['/temperature', '/pressure'],
                       formulas.altitude, '/altitude', '/mydrone/true_altitude', '/alt_warn_led',
                       'custom.param_threshold', param_value(outputs, 'custom.param_delay'))
    dive = run_facts(work, outputs, 'dive.launch', 'dive.bag', ['/pressure_robot', '/pressure_remote'],
                     formulas.depth, '/depth', '/submarine_drone/true_depth', '/depth_warn_led',
                     'dive.param_threshold', delay)
    simple = run_facts(work, outputs, 'simple.launch', 'simple.bag', ['/temperature', '/pressure'],
                       formulas.altitude, '/altitude', '/mydrone/true_altitude', '/alt_warn_led',
                       'simple.param_threshold', delay)
    simple_dive = run_facts(work, outputs, 'simple_dive.launch', 'simple_dive.bag',
                            ['/pressure_robot', '/pressure_remote'], formulas.depth, '/depth',
                            '/submarine_drone/true_depth', '/depth_warn_led',
                            logged_threshold(outputs['simple_dive.launch']['output']), delay)
    out = os.path.join(repo, 'docs', 'figures')
    os.makedirs(out, exist_ok=True)
    figures.run_figure(os.path.join(out, 'flight.png'), flight, 'mydrone, default flight, exam.launch',
                       'altitude', 'm', flight['threshold'], delay, '/altitude_warning')
    figures.run_figure(os.path.join(out, 'dive.png'), dive, 'submarine_drone, default dive, '
                       'exam_submarine.launch', 'depth', 'm', dive['threshold'], delay, '/depth_warning',
                       invert=True)
    curve = [(float(h), analysis.isothermal_error(h)) for h in range(0, 3001, 50)]
    fixed = [(float(h), analysis.lapse_rate_error(h)) for h in range(0, 3001, 50)]
    measured = analysis.hold_errors(flight['series'], ['/temperature', '/pressure'], formulas.altitude,
                                    '/mydrone/true_altitude')
    figures.model_error_figure(os.path.join(out, 'model_error.png'), curve, fixed, measured,
                               flight['threshold'])
    dive_errors = analysis.hold_errors(dive['series'], ['/pressure_robot', '/pressure_remote'],
                                       formulas.depth, '/submarine_drone/true_depth')

    v = {}
    for prefix, run in (('simple', simple), ('simple_dive', simple_dive)):
        # The simple answer's LED changes, against the same excesses (it is the same seeded flight).
        if len(run['changes']) < 2 or not run['warning_lag'] or not run['normal_lag']:
            raise RuntimeError('%s: expected a WARNING and a NORMAL call; got changes %s'
                               % (prefix, run['changes']))
        v[prefix + '.calls'] = str(len(run['changes']))
        v[prefix + '.changes'] = ', '.join('%s at %.1f s' % (c, t) for t, c in run['changes'])
        v[prefix + '.warning_lag_ms'] = '%.0f' % (1000 * run['warning_lag'][0])
        v[prefix + '.normal_lag_ms'] = '%.0f' % (1000 * run['normal_lag'][0])
        v[prefix + '.rate'] = fmt(run['rate'], 2)
    v['simple.hz'] = fmt(last_rate(outputs['simple.hz_altitude']['output']), 3)
    for prefix, run in (('flight', flight), ('dive', dive)):
        episodes = [e for e in run['episodes'] if e[2] is not None]
        short = [e for e in episodes if e[2] < delay]
        long_ = [e for e in episodes if e[2] >= delay]
        if not short or not long_ or len(run['changes']) < 2:
            raise RuntimeError('%s: expected a short and a long excess and two LED changes; got '
                               'episodes %s, changes %s' % (prefix, episodes, run['changes']))
        v[prefix + '.threshold'] = '%g' % run['threshold']
        v[prefix + '.short_start'] = fmt(short[0][0])
        v[prefix + '.short_duration'] = fmt(short[0][2])
        # The same excursions of the ground truth (sampled with each reading of the truth's sensor).
        true = [(end - start) for start, end in analysis.excess_episodes(run['truth'], run['threshold'])
                if end is not None]
        v[prefix + '.true_short_duration'] = fmt(min(true))
        v[prefix + '.true_long_duration'] = fmt(max(true))
        v[prefix + '.long_start'] = fmt(long_[0][0])
        v[prefix + '.long_end'] = fmt(long_[0][1])
        v[prefix + '.long_duration'] = fmt(long_[0][2])
        v[prefix + '.calls'] = str(len(run['changes']))
        v[prefix + '.red_at'] = fmt([t for t, c in run['changes'] if c == 'RED'][0])
        v[prefix + '.green_at'] = fmt([t for t, c in run['changes'] if c == 'GREEN'][0])
        v[prefix + '.warning_lag_ms'] = '%.0f' % (1000 * run['warning_lag'][0])
        v[prefix + '.normal_lag_ms'] = '%.0f' % (1000 * run['normal_lag'][0])
        v[prefix + '.rate'] = fmt(run['rate'], 2)
        v[prefix + '.seconds'] = '%.0f' % run['published'][-1][0]
        v[prefix + '.changes'] = ', '.join('%s at %.1f s' % (c, t) for t, c in run['changes'])
    order = re.findall(r'^-- ~~  - (\S+)', outputs['build.catkin_make']['output'], re.M)
    if not order:
        raise RuntimeError('catkin_make printed no package order')
    v['build.count'] = str(len(order))
    v['build.order'] = ', '.join('`%s`' % name for name in order)
    started = outputs['flight.launch']['started']
    v['run.date'] = time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime(started))
    v['run.host'] = socket.gethostname()
    versions = re.findall(r'/rosversion: (\S+)', outputs['flight.launch']['output'])
    v['run.rosversion'] = versions[0] if versions else 'unknown'
    v['flight.delay'] = '%g' % delay
    v['flight.bad_launch_seconds'] = '%.0f' % outputs['flight.bad_launch']['seconds']
    v['custom.threshold'] = '%g' % custom['threshold']
    v['custom.delay'] = '%g' % param_value(outputs, 'custom.param_delay')
    v['custom.calls'] = str(len(custom['changes']))
    # The 1200 m example on the drone's clock: from its first log line (the flight's time 0), which
    # comes after roslaunch's own start-up (about 1.5 s, varying); README and architecture.md use it.
    first = console_lines(outputs['custom.launch']['output'], r'\]: /mydrone: profile')
    if not first:
        raise RuntimeError('custom.launch: no start line of the drone')
    drone_start = float(re.search(r'\[(\d+\.\d+)\]', first[0]).group(1)) - outputs['custom.launch']['started']
    v['custom.drone_start'] = fmt(drone_start)
    v['custom.changes'] = ', '.join('%s at %.1f s' % (c, t - drone_start) for t, c in custom['changes'])
    v['custom.seconds'] = '%.0f' % custom['published'][-1][0]
    custom_episodes = [e for e in custom['episodes'] if e[2] is not None]
    v['custom.short_duration'] = fmt(custom_episodes[0][2])
    v['flight.max'] = fmt(max(value for _, value in flight['published']))
    v['flight.true_max'] = fmt(max(value for _, value in flight['truth']))

    v['model.err_1300'] = fmt(analysis.isothermal_error(1300.0))
    v['model.err_1500'] = fmt(analysis.isothermal_error(1500.0))
    v['model.err_3000'] = fmt(analysis.isothermal_error(3000.0))
    v['model.true_at_threshold'] = fmt(analysis.true_altitude_read_as(flight['threshold']))
    # Two significant digits each: 0.097 and 1.3, not 0.10 beside 1.3 (one precision for both).
    v['model.mean_t_1300'] = '%.2g' % analysis.mean_temperature_error(1300.0)
    v['model.mean_t_3000'] = '%.2g' % analysis.mean_temperature_error(3000.0)
    v['model.t_1300'] = '%.2f' % atmosphere.temperature_c(1300.0)
    v['model.p_1300'] = '%.0f' % atmosphere.pressure_pa(1300.0)
    # Rounding only: the bound, a power of ten, rather than digits that change with the sampling.
    v['model.fix_max'] = 'less than 1e%d' % math.ceil(math.log10(max(abs(e) for _, e in fixed)))
    v['model.standard_1300'] = '%.3f' % analysis.standard_altitude(atmosphere.pressure_pa(1300.0))
    for level in (1200.0, 1500.0):
        errs = [e for h, e in measured if abs(h - level) < 0.5]
        v['model.measured_%d' % level] = fmt(analysis.mean(errs))
        v['model.measured_%d_n' % level] = str(len(errs))
    v['dive.err_mean_mm'] = fmt(1000 * analysis.mean(e for _, e in dive_errors))
    v['dive.err_max_mm'] = '%.0f' % (1000 * max(abs(e) for _, e in dive_errors))
    v['dive.err_n'] = str(len(dive_errors))
    v['mydrone.temperature_rate'] = fmt(last_rate(outputs['mydrone.hz_temperature']['output']), 3)
    v['mydrone.pressure_rate'] = fmt(last_rate(outputs['mydrone.hz_pressure']['output']), 3)
    v['submarine.robot_rate'] = fmt(last_rate(outputs['submarine.hz_pressure_robot']['output']), 3)
    v['submarine.remote_rate'] = fmt(last_rate(outputs['submarine.hz_pressure_remote']['output']), 3)
    v['flight.hz'] = fmt(last_rate(outputs['flight.hz_altitude']['output']), 3)
    v['dive.hz'] = fmt(last_rate(outputs['dive.hz_depth']['output']), 3)

    b = {}
    # The exam node's lines only: its start-up summary, its decisions, and its service calls.
    exam_lines = r'\]: (/exam: |\w+ -?[0-9.]+ m .*: (WARNING|NORMAL)$|/\w+_warning: LED set to|could not set)'
    b['flight.exam_log'] = log_excerpt(outputs['flight.launch']['output'], exam_lines)
    b['dive.exam_log'] = log_excerpt(outputs['dive.launch']['output'], exam_lines)
    b['flight.drone_log'] = log_excerpt(outputs['flight.launch']['output'], r'altitude_warning: ALT WARN')
    b['dive.drone_log'] = log_excerpt(outputs['dive.launch']['output'], r'depth_warning: DEPTH WARN')
    # The simple answer's own log: its threshold, then each call it made.
    simple_lines = r'\]: (threshold -?[0-9.]+ m$|(altitude|depth) -?[0-9.]+ m .*: (WARNING|NORMAL)$)'
    b['simple.log'] = log_excerpt(outputs['simple.launch']['output'], simple_lines)
    b['simple_dive.log'] = log_excerpt(outputs['simple_dive.launch']['output'], simple_lines)
    line = 'git ls-files -s -- mydrone/scripts submarinedrone/scripts docs/simple_answer/exam/scripts'
    listed = subprocess.run(shlex.split(line), cwd=repo, stdout=subprocess.PIPE, check=True)
    b['scripts.modes'] = '$ %s\n%s' % (line, listed.stdout.decode().rstrip())
    created_files = outputs['exam.create_pkg']
    b['exam.created_files'] = '%s\n\n%s' % (
        '<!-- exam/package.xml -->\n' + uncommented(created_files['package_xml'], r'(?s)<!--.*?-->'),
        '# exam/CMakeLists.txt\n' + uncommented(created_files['cmakelists'], r'(?m)#.*$'))
    created = depends(created_files['package_xml'])
    with open(os.path.join(repo, 'exam', 'package.xml')) as f:
        ours = depends(f.read())
    rows = ['%-20s %-44s %s' % ('tag', 'catkin_create_pkg wrote', 'exam/package.xml has')]
    for tag in sorted(set(created) | set(ours)):
        rows.append('%-20s %-44s %s' % (tag, ' '.join(created.get(tag, [])) or '-',
                                        ' '.join(ours.get(tag, [])) or '-'))
    b['exam.depends'] = '\n'.join(rows)
    return v, b


def source_of(spec):
    """Source text of ``module:Name`` or ``module:Class.method``, dedented."""
    module_name, qualname = spec.split(':')
    obj = importlib.import_module(module_name)
    for part in qualname.split('.'):
        obj = getattr(obj, part)
    return textwrap.dedent(inspect.getsource(obj)).rstrip()


def fence(text, language=''):
    return '```%s\n%s\n```' % (language, text)


#: Placeholders of one kind separated by blank lines only (``{{run}}``, ``{{source}}``, ``{{block}}``):
#: one block for them all, as in one terminal or one file.
GROUP = re.compile(r'\{\{(run|source|block) [^ }]+\}\}(?:\n\n\{\{\1 [^ }]+\}\})+')


def render(template, outputs, values, blocks, repo):
    """The template with every placeholder replaced; raises KeyError on an unknown one."""
    def console(key):
        result = outputs[key]
        if command_list.BY_KEY[key].line != result['line']:
            raise KeyError('%s: outputs.json is older than command_list.py, run make report' % key)
        return '$ %s\n%s' % (result['line'], shown(command_list.BY_KEY[key], clean(result['output'])))

    def replace_group(match):
        kind = match.group(1)
        keys = re.findall(r'\{\{%s ([^ }]+)\}\}' % kind, match.group(0))
        if kind == 'run':
            return fence('\n\n'.join(console(key) for key in keys), 'console')
        if kind == 'source':
            return fence('\n\n\n'.join(source_of(key) for key in keys), 'python')
        return fence('\n\n'.join(blocks[key] for key in keys), 'text')

    def replace(match):
        kind, key = match.groups()
        if kind == 'run':
            return fence(console(key), 'console')
        if kind == 'line':
            return '`%s`' % command_list.BY_KEY[key].line
        if kind == 'value':
            return values[key]
        if kind == 'block':
            return fence(blocks[key], 'text')
        if kind == 'excerpt':
            path = excerpts.EXCERPTS[key][0]
            return fence(excerpts.excerpt(repo, key), language_of(path))
        if kind == 'file':
            with open(os.path.join(repo, key)) as f:
                return fence(f.read().rstrip(), language_of(key))
        return fence(source_of(key), 'python')
    def quoted(text):
        return '\n'.join(('> ' + line).rstrip() for line in text.splitlines())

    def replace_quoted(match):
        return quoted(PLACEHOLDER.sub(replace, match.group(1)))

    def side(placeholders):
        # Consecutive placeholders of one kind on a side: one block, as GROUP makes them.
        return GROUP.sub(replace_group, '\n\n'.join(placeholders))

    def replace_pair(match):
        left, right = (re.findall(r'\{\{[^}]+\}\}', match.group(i)) for i in (2, 3))
        cells = [PLACEHOLDER.sub(replace, side(placeholders)) for placeholders in (left, right)]
        if any(CODE.match(p) for p in left + right):
            # Code a student copies: one sheet's below the other's, at the page's full width, never
            # wrapped (a wrapped comment loses its #, a wrapped statement no longer runs).
            text = '%s\n\n%s' % tuple(cells)
        else:
            text = ('<table class="pair"><tr><td>\n\n%s\n\n</td><td>\n\n%s\n\n</td></tr></table>' % tuple(cells))
        return quoted(text) if match.group(1) else text
    template = PAIR.sub(replace_pair, template)
    return PLACEHOLDER.sub(replace, GROUP.sub(replace_group, QUOTED.sub(replace_quoted, template)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--work', required=True, help='folder of outputs.json and the bags')
    parser.add_argument('--repo', required=True, help='the repository (docs/ is written there)')
    args = parser.parse_args()
    with open(os.path.join(args.work, 'outputs.json')) as f:
        outputs = json.load(f)
    values, blocks = facts(args.work, args.repo, outputs)
    here = os.path.dirname(os.path.realpath(__file__))
    with open(os.path.join(here, 'report_template.md')) as f:
        template = f.read()
    text = render(template, outputs, values, blocks, args.repo)
    # The template's own comment lines (<!-- ... -->) stay: they say how the file is made.
    with open(os.path.join(args.repo, 'docs', 'report.md'), 'w') as f:
        f.write(text)
    print('report: docs/report.md and docs/figures/{flight,dive,model_error}.png written')


if __name__ == '__main__':
    main()

"""Every command README.md and docs/*.md give runs as pasted (issue 49 point 2).

Each shell block (```sh, ```bash, ```shell; in a console block each ``$ `` line) is read by
``bash -n`` (its syntax), searched for a comment after a line continuation (``\\ # ...``: bash then
ends the command there and runs the next line on its own: README's Noetic install once never
installed chromium nor poppler that way), and each ``make`` it runs is checked against the Makefile:
its targets are the Makefile's, and each ``VAR=value`` one the Makefile reads. Each check is shown
failing on a planted error first.
"""
import glob
import json
import os
import re
import shlex
import subprocess

import pytest

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.realpath(__file__)), '..', '..', '..'))
DOCS = [os.path.join(REPO, 'README.md')] + sorted(glob.glob(os.path.join(REPO, 'docs', '*.md')))
SHELL = ('sh', 'bash', 'shell')
_FENCE = re.compile(r'^(?P<indent>[ >]*)```(?P<lang>[\w-]*)\s*$')
#: Variables make itself gives meaning to on its command line (GNU make's manual, "Overriding").
MAKE_OWN = {'SHELL', 'MAKEFLAGS'}


def _read(path):
    with open(path, encoding='utf-8') as f:
        return f.read()


def blocks(text):
    """``[(first line number, language, text)]`` of the fenced blocks of a Markdown ``text``, each
    line without the block's indent or quote marks."""
    found, lines, i = [], text.splitlines(), 0
    while i < len(lines):
        opened = _FENCE.match(lines[i])
        if not opened:
            i += 1
            continue
        indent, body, start = len(opened.group('indent')), [], i + 1
        i += 1
        while i < len(lines) and not _FENCE.match(lines[i]):
            body.append(lines[i][indent:] if len(lines[i]) >= indent else '')
            i += 1
        found.append((start + 1, opened.group('lang'), '\n'.join(body) + '\n'))
        i += 1
    return found


def shell_of(language, text):
    """The shell a block holds: a shell block whole, a console block's ``$ `` lines; else None."""
    if language in SHELL:
        return text
    if language == 'console':
        commands = [line[2:] for line in text.splitlines() if line.startswith('$ ')]
        return '\n'.join(commands) + '\n' if commands else None
    return None


def makefile_rules(path=os.path.join(REPO, 'Makefile')):
    """``(targets, variables)`` of the Makefile: every rule's target, every ``$(VAR)`` it reads."""
    text = _read(path)
    targets = set(re.findall(r'^([A-Za-z][\w.-]*)\s*:(?!=)', text, re.M))
    variables = set(re.findall(r'\$\((\w+)\)', text)) | set(re.findall(r'^(\w+)\s*[?:]?=', text, re.M))
    return targets, variables


def make_calls(script):
    """Each ``make`` a script runs: ``[[word, ...]]``, its words after ``make`` up to the command's end
    (line continuations joined)."""
    calls = []
    joined = re.sub(r'\\\n', ' ', script)
    for line in joined.splitlines():
        line = re.sub(r'(^|\s)#.*$', '', line)
        try:
            lexer = shlex.shlex(line, posix=True, punctuation_chars=True)
            lexer.whitespace_split = True
            words = list(lexer)
        except ValueError:
            continue  # bash -n says what is wrong with it
        command = []
        for word in words + [';']:
            if word and set(word) <= set(';&|()'):
                if command:
                    calls.append(command)
                command = []
            elif command or word == 'make':
                command.append(word)
    return [call[1:] for call in calls if call and call[0] == 'make']


def problems(script, rules=None):
    """What is wrong with a shell ``script`` as pasted, one line each ([] when nothing is)."""
    targets, variables = rules or makefile_rules()
    found = []
    checked = subprocess.run(['bash', '-n'], input=script.encode('utf-8'), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE)
    if checked.returncode != 0:
        found.append('bash -n: %s' % checked.stderr.decode('utf-8', 'replace').strip().replace('\n', '; '))
    for number, line in enumerate(script.splitlines(), 1):
        if re.search(r'\\[ \t]+#', line):
            found.append('line %d: a comment after a line continuation ends the command there: %s'
                         % (number, line.strip()))
    for call in make_calls(script):
        for word in call:
            if word.startswith('-'):
                continue
            name = word.split('=', 1)[0] if '=' in word else None
            if name is None and word not in targets:
                found.append('make %s: no such target in the Makefile' % word)
            elif name is not None and name not in variables | MAKE_OWN:
                found.append('make ... %s=: the Makefile reads no variable %s' % (name, name))
    return found


def all_scripts():
    for path in DOCS:
        for line, language, text in blocks(_read(path)):
            script = shell_of(language, text)
            if script is not None:
                yield '%s:%d' % (os.path.relpath(path, REPO), line), script


SCRIPTS = list(all_scripts())


def test_the_docs_have_shell_blocks_to_check():
    where = {name.split(':')[0] for name, _ in SCRIPTS}
    assert {'README.md', 'docs/grading.md', 'docs/report.md', 'docs/operations.md'} <= where, where
    assert sum(len(make_calls(s)) for _, s in SCRIPTS) >= 10


@pytest.mark.parametrize('where,script', SCRIPTS, ids=[name for name, _ in SCRIPTS])
def test_every_shell_block_runs_as_pasted(where, script):
    assert problems(script) == [], where


def test_the_check_catches_each_kind_of_error():
    rules = ({'grade', 'rescore'}, {'OUT', 'CLASS'})
    assert problems('make grade CLASS=a.zip\nmake rescore OUT="a b"\n', rules) == []
    assert len(problems('if true; then echo\n', rules)) == 1  # never closed: bash -n
    noetic = 'sudo apt install a \\\n  b \\  # a comment\n  c\n'
    assert problems(noetic, rules) == [
        'line 2: a comment after a line continuation ends the command there: b \\  # a comment']
    assert problems('cd x && make grades OUT=y\n', rules) == ['make grades: no such target in the Makefile']
    assert problems('make grade \\\n  WORKSHEET_SCALE=1\n', rules) == [
        'make ... WORKSHEET_SCALE=: the Makefile reads no variable WORKSHEET_SCALE']


def test_the_makefile_is_read_as_it_is():
    targets, variables = makefile_rules()
    assert {'grade', 'rescore', 'worksheet', 'check', 'report', 'build'} <= targets
    assert {'OUT', 'CLASS', 'WORKSHEET', 'PACKAGE', 'SHEET', 'JOBS'} <= variables
    assert 'WORKSHEET_SCALE' not in variables


def test_blocks_are_found_indented_and_quoted():
    text = 'a\n\n   ```sh\n   make grade OUT=x\n   ```\n> ```console\n> $ ls\n> out\n> ```\n'
    assert [(lang, body) for _, lang, body in blocks(text)] == [('sh', 'make grade OUT=x\n'), ('console', '$ ls\nout\n')]
    assert shell_of('console', '$ ls\nout\n') == 'ls\n'


def grade_json_problems(text):
    """The keys docs/grading.md lists for grade.json against GradeRecord's schema (the record's type
    itself): every key, nothing more, the items' keys too."""
    from exam_lab.grader.score.kept import GradeRecord
    found = re.search(r'^- `grade\.json`[^`]*(?:`[^`]*`[^`]*)*?`(\{"version".*?\})`', text, re.M | re.S)
    if found is None:
        return ['docs/grading.md lists no keys of grade.json']
    listed = re.sub(r'\s+', ' ', found.group(1))
    items = re.search(r'"items": \[\{([^}]*)\}\]', listed)
    top = set(re.findall(r'"(\w+)"', listed.replace(items.group(0), '"items"') if items else listed))
    problems = ['%s: %s' % (what, sorted(keys)) for what, keys in (
        ('not listed', set(GradeRecord.SCHEMA) - top), ('not a key of the record', top - set(GradeRecord.SCHEMA))) if keys]
    item_keys = set(re.findall(r'"(\w+)"', items.group(1))) if items else set()
    if item_keys != set(GradeRecord.SCHEMA['items'].schema):
        problems.append('the items\' keys: %s' % sorted(item_keys))
    return problems


def test_grade_jsons_keys_are_its_records():
    assert grade_json_problems(_read(os.path.join(REPO, 'docs', 'grading.md'))) == []


def test_the_grade_json_check_catches_a_key_left_out():
    text = _read(os.path.join(REPO, 'docs', 'grading.md'))
    assert grade_json_problems(text.replace('"graded_on"}', '"x"}')) == [
        "not listed: ['graded_on']", "not a key of the record: ['x']"]


def noise_free_peak_problems(text):
    """architecture.md's noise-free peak of the default flight: equation (1) (exam/src/exam/formulas.py)
    on the drone's own noise-free values at the flight's highest point (mydrone's FLIGHTS, atmosphere)."""
    import sys
    for package in ('exam', 'mydrone'):
        path = os.path.join(REPO, package, 'src')
        if path not in sys.path:
            sys.path.insert(0, path)
    from exam import formulas
    from mydrone import atmosphere, flights
    top = max(h for _, h in flights.FLIGHTS['default'])
    peak = '%.1f' % formulas.altitude(atmosphere.temperature_c(top), atmosphere.pressure_pa(top))
    quoted = re.findall(r'noise-free estimate peaks at ([\d.]+) m', text)
    return [] if quoted == [peak] else ['quoted %s, equation (1) gives %s m at %s m' % (quoted, peak, top)]


def test_the_noise_free_peak_is_equation_ones():
    assert noise_free_peak_problems(_read(os.path.join(REPO, 'docs', 'architecture.md'))) == []
    assert len(noise_free_peak_problems('its noise-free estimate peaks at 1476.6 m')) == 1


def report_peak_problems(architecture, report):
    """architecture.md's highest value of the report's run against the one report.md was generated with
    (lab/report/render.py's ``flight.max``)."""
    flat = re.sub(r'\s+', ' ', architecture)
    generated = re.findall(r'its estimate peaks at ([\d.]+) m \(appendix B\)', re.sub(r'\s+', ' ', report))
    quoted = re.findall(r"the report's run saw up to ([\d.]+) m", flat)
    return [] if len(generated) == 1 and quoted == generated else [
        'architecture.md quotes %s m, the report\'s run peaked at %s m' % (quoted, generated)]


def test_the_report_runs_peak_is_the_reports():
    architecture = _read(os.path.join(REPO, 'docs', 'architecture.md'))
    report = _read(os.path.join(REPO, 'docs', 'report.md'))
    assert report_peak_problems(architecture, report) == []
    assert len(report_peak_problems(architecture, re.sub(r'peaks at [\d.]+ m \(appendix B', 'peaks at 1480.2 m (appendix B',
                                                         report))) == 1


def window_problems(text):
    """grading.md's widths of question 14b's WARNING window and the short excursion's longest time
    above, per sheet (altitude, depth): from the rubric's tolerances and the drones' rates."""
    from exam_lab.fairness.generator import DRONE_RATES
    from exam_lab.grader.score import tolerances
    slowest = [1.0 / min(DRONE_RATES[s].values()) for s in ('altitude', 'depth')]
    width = ['%g' % round(tolerances.WARNING_EARLY_S + max(tolerances.WARNING_LATE_S, p + 1.0 / tolerances.RATE_HZ), 2)
             for p in slowest]
    from exam_lab.grader.judge import legs
    above = ['%g' % round(legs.SHORT_S + p + tolerances.LAG_SLACK_S, 2) for p in slowest]  # the lag tolerance
    start = '%g' % (5.0 - tolerances.WARNING_EARLY_S)
    problems = []
    if 'the window is %s s wide on the altitude sheet, %s s on the depth sheet' % tuple(width) not in text:
        problems.append('the window is %s s / %s s wide' % tuple(width))
    if 'at most %g s + the lag tolerance below (%s s / %s s < %s s, the window\'s start)' % (
            legs.SHORT_S, above[0], above[1], start) not in text:
        problems.append('the short excursion: %s s / %s s < %s s' % (above[0], above[1], start))
    return problems


def ours_excursion_problems(grading):
    """The legs table's "3.0 s excursion above" for ours is what the example grade of ours says."""
    ours = grading[grading.index('<!-- example ours:'):grading.index('<!-- end of example ours -->')]
    said = re.findall(r'(\d+\.\d) s excursion above: no WARNING', ours)
    quoted = re.findall(r'grade\.md\'s "(\d+\.\d) s excursion above" for ours', grading)
    return [] if said and quoted == said[:1] else ['the legs table says %s s for ours, its grade %s s' % (quoted, said)]


def test_the_short_excursion_of_ours_is_its_example_grades():
    grading = _read(os.path.join(REPO, 'docs', 'grading.md'))
    assert ours_excursion_problems(grading) == []
    assert len(ours_excursion_problems(re.sub(r'"\d+\.\d s excursion above" for ours', '"9.9 s excursion above" for ours',
                                              grading))) == 1


def test_the_windows_quoted_are_the_rubrics():
    text = re.sub(r'\s+', ' ', _read(os.path.join(REPO, 'docs', 'grading.md')))
    assert window_problems(text) == []
    assert len(window_problems(text.replace('1.69 s wide', '0.8 s wide'))) == 1


def drone_start_problems(readme, architecture, report):
    """The drone's first line after the command, quoted for "the report's run" and for README's run of
    the profile example: the number each of those runs printed (report.md is made by make report from its
    run; README's measured sentence gives its own)."""
    flat = [re.sub(r'\s+', ' ', t) for t in (readme, architecture, report)]
    reports = re.findall(r"the flight's time 0, ([\d.]+) s after the command", flat[2])
    readmes = re.findall(r"the drone's first line came ([\d.]+) s after the command", flat[0])
    if len(reports) != 1 or len(readmes) != 1:
        return ['the runs no longer say when the drone started: %s, %s' % (reports, readmes)]
    problems = []
    for name, text, other in (('README.md', flat[0], r'in the run below'), ('architecture.md', flat[1], r"in the README's")):
        quoted = re.findall(r"([\d.]+) s in the report's run, ([\d.]+) s %s" % other, text)
        if quoted != [(reports[0], readmes[0])]:
            problems.append('%s quotes %s, the runs say %s' % (name, quoted, (reports[0], readmes[0])))
    return problems


def test_the_drones_start_is_each_runs_own():
    texts = [_read(os.path.join(REPO, p)) for p in ('README.md', 'docs/architecture.md', 'docs/report.md')]
    assert drone_start_problems(*texts) == []
    planted = re.sub(r"[\d.]+ s in the report's run", "0.01 s in the report's run", texts[0])
    assert len(drone_start_problems(planted, *texts[1:])) == 1


def threshold_run_problems(text):
    """The threshold run's range docs/grading.md quotes, from score/sheets.py (LOWERED_BY, margin_of)."""
    from exam_lab.grader.score import sheets
    low, high = sheets.LOWERED_BY
    top = '%g' % sheets.threshold_run_value(1300.0, 0.0)
    bottom = '%g' % (1300.0 - high * sheets.margin_of(1300.0))
    said = 'the threshold lowered by %g to %g margins (from %s m to %s m for 1300 m' % (low, high, top, bottom)
    return [] if said in text else ['not said: %s' % said]


def test_the_threshold_runs_range_is_the_sheets():
    text = re.sub(r'\s+', ' ', _read(os.path.join(REPO, 'docs', 'grading.md')))
    assert threshold_run_problems(text) == []
    assert len(threshold_run_problems(text.replace('from 975 m to 780 m', 'from 1040 m to 780 m'))) == 1


def fairness_count_problems(makefile, grading):
    """How many answers make fairness grades, as its help line and docs/grading.md say: the generator's
    matrix (lab/src/exam_lab/fairness/generator.py, the script's default count)."""
    from exam_lab.fairness import generator
    matrix = generator.answers()
    correct = sum(1 for a in matrix if a.mistake is None)
    mistakes = len(matrix) - correct
    rules = len(generator.MISTAKES)
    said = {'Makefile': re.findall(r'generated student answers \((\d+) correct, (\d+) one-mistake', makefile),
            'docs/grading.md': re.findall(r'grades them as one class: (\d+) correct answers.*?for each of (\d+) '
                                          r'rules of the rubric two one-mistake', re.sub(r'\s+', ' ', grading))}
    want = {'Makefile': [(str(correct), str(mistakes))], 'docs/grading.md': [(str(correct), str(rules))]}
    return ['%s says %s, the generator makes %s' % (k, said[k], want[k]) for k in said if said[k] != want[k]]


def test_the_fairness_counts_are_the_generators():
    makefile, grading = _read(os.path.join(REPO, 'Makefile')), _read(os.path.join(REPO, 'docs', 'grading.md'))
    assert fairness_count_problems(makefile, grading) == []
    assert len(fairness_count_problems(makefile.replace('(46 correct', '(40 correct'), grading)) == 1


def bench_figure_problems(grading, bench):
    """The figures docs/grading.md derives from the grader's benchmark record (lab/bench/grader.md, made
    by grader_bench.py --record): the run's load average, the class of 60 at the default JOBS against the
    worst case, and the Slurm course's waves of a correct student's time alone (and the file system's
    load over them). When the benchmark runs
    again, this test names each figure to write anew."""
    from exam_lab.grader import class_run
    flat = re.sub(r'\s+', ' ', grading)
    load = re.search(r'Load average \(1, 5, 15 min\) at start ([\d.]+), [\d.]+, [\d.]+, at end ([\d.]+),', bench)
    default = str(class_run.default_jobs(cores=2, memory=24 << 30))
    wall = re.search(r'^\| class of 60, JOBS=%s \| (\d+) s \|' % default, bench, re.M)
    alone = re.search(r'^\| good_student \| [\d.]+ \| (\d+) s \|$', bench, re.M)
    if not (load and wall and alone):
        return ['lab/bench/grader.md no longer holds the load average, the class of 60 or good_student']
    seconds = int(alone.group(1))
    expected = [
        'load average %s at the start of the run, %s at its end' % load.groups(),
        'against %.1f minutes for the class above' % (int(wall.group(1)) / 60.0),
        'A correct student takes %d s graded alone' % seconds,
        'about 10 x %d s = %.1f minutes once the tasks start' % (seconds, 10 * seconds / 60.0),
        'twenty waves of %d s, %.1f minutes' % (seconds, 20 * seconds / 60.0),
        # 1,000 students' 0.8 GB read, 150 MB written and 12 million metadata operations over the waves
        'over the %.1f minutes (%.1f MB/s and %.1f MB/s' % (10 * seconds / 60.0, 800.0 / (10 * seconds),
                                                            150.0 / (10 * seconds)),
        'about 12 million metadata operations (about {:,} a second)'.format(
            int(round(12e6 / (10 * seconds), -3))),
    ]
    return ['not said (from lab/bench/grader.md): %s' % e for e in expected if e not in flat]


def test_the_figures_from_the_grader_benchmark_are_its_records():
    grading = _read(os.path.join(REPO, 'docs', 'grading.md'))
    bench = _read(os.path.join(REPO, 'lab', 'bench', 'grader.md'))
    assert bench_figure_problems(grading, bench) == []
    start, end = re.search(r'at start ([\d.]+), [\d.]+, [\d.]+, at end ([\d.]+),', bench).groups()
    assert bench_figure_problems(grading, bench.replace('at start %s' % start, 'at start 9.99')) == [
        'not said (from lab/bench/grader.md): load average 9.99 at the start of the run, %s at its end' % end]


#: The class-only runs of 2026-12-03 that grading.md's Speed quotes, and the full run they compare with.
CLASS_RUNS = ('grader-class-1203-jobs4.json', 'grader-class-1203-jobs6.json')


def class_run_problems(grading, runs, alone):
    """grading.md's figures of the class-only runs (``runs``: [results.json of grader_bench.py
    --no-alone]): each class's wall time and CPU a grading, and that every copy got the points of its
    package in ``alone`` (the recorded full run's results)."""
    flat, problems = re.sub(r'\s+', ' ', grading), []
    for run in runs:
        for c in run['classes']:
            said = '`JOBS=%d` **%.0f s' % (c['jobs'], c['wall'])
            cpu = '%.1f s of CPU a grading' % (c['cpu'] / c['students'])
            for phrase in (said, cpu):
                if phrase not in flat:
                    problems.append('not said: %s (JOBS=%d)' % (phrase, c['jobs']))
            moved = [r['student'] for r in c['rows'] if r['points'] != alone['alone'][r['kind']]['points']]
            if moved:
                problems.append('JOBS=%d: %s did not get the points of their package alone' % (c['jobs'], moved))
    return problems


def test_the_class_runs_quoted_are_their_records():
    grading = _read(os.path.join(REPO, 'docs', 'grading.md'))
    history = os.path.join(REPO, 'lab', 'bench', 'history')
    runs = [json.loads(_read(os.path.join(history, name))) for name in CLASS_RUNS]
    alone = json.loads(_read(os.path.join(REPO, 'lab', 'bench', 'grader_results.json')))
    assert all(name in grading for name in ('grader-class-1203-jobs4.json', 'grader-class-1203-jobs6.json'))
    assert class_run_problems(grading, runs, alone) == []
    assert class_run_problems(grading.replace('**773 s', '**770 s'), runs, alone) == ['not said: `JOBS=4` **773 s (JOBS=4)']
    row = dict(runs[0]['classes'][0]['rows'][0])
    changed = dict(runs[0], classes=[dict(runs[0]['classes'][0], rows=[dict(row, points=dict(row['points'], Q11=0))])])
    assert class_run_problems(grading, [changed], alone) == [
        'JOBS=4: [%r] did not get the points of their package alone' % row['student']]


def report_class_problems(grading, results):
    """grading.md's figures of the class graded without and with reports (lab/bench/reports_results.json's
    ``class``: report_bench.py's record)."""
    graded, flat = results['class'], re.sub(r'\s+', ' ', grading)
    said = '%.0f s without, %.0f s with: %+.0f s at JOBS=%d' % (
        graded['seconds_without'], graded['seconds'], graded['seconds'] - graded['seconds_without'], graded['jobs'])
    stages = 'the report stages\' sum over the slots, %.0f s' % (sum(graded['report']) / graded['jobs'])
    return ['not said (from lab/bench/reports_results.json): %s' % p for p in (said, stages) if p not in flat] + \
        ['a class of %d, not 60' % graded['students']] * (graded['students'] != 60)


def test_the_class_with_reports_quoted_is_its_record():
    grading = _read(os.path.join(REPO, 'docs', 'grading.md'))
    results = json.loads(_read(os.path.join(REPO, 'lab', 'bench', 'reports_results.json')))
    assert report_class_problems(grading, results) == []
    other = dict(results, **{'class': dict(results['class'], seconds=results['class']['seconds'] + 10)})
    assert len(report_class_problems(grading, other)) == 1


def leg_name_problems(grading, words=None):
    """The plot's leg names (publish/flightplot.py LEG_NAMES) and grade.md's (score/flight.py LEG_WORDS:
    the name and its side) against the first column of the manual's table of the legs, in the flight's order."""
    from exam_lab.grader.publish import flightplot
    from exam_lab.grader.score import flight
    words = flight.LEG_WORDS if words is None else words
    section = grading[grading.index('### The legs of the flight'):]
    table = re.findall(r'^\| ([a-z][a-z ]+) \| ', section, re.M)
    legs = ('rest', 'short_up', 'short_down', 'long_up', 'long_down', 'deep_down')
    names = [flightplot.LEG_NAMES[leg] for leg in legs]
    manual = [name for name in table if name != 'leg'][:len(names)]
    problems = [] if manual == names else ['the manual names the legs %s, the plot %s' % (manual, names)]
    said = [re.sub(r' (above|below)$', '', words[leg]) if words[leg] not in manual else words[leg] for leg in legs]
    return problems + ([] if said == manual else ['the manual names the legs %s, grade.md %s' % (manual, said)])


def test_the_plots_leg_names_are_the_manuals():
    grading = _read(os.path.join(REPO, 'docs', 'grading.md'))
    assert leg_name_problems(grading) == []
    assert len(leg_name_problems(grading.replace('| just below | just below |', '| gap below | just below |'))) == 2
    from exam_lab.grader.score import flight
    assert leg_name_problems(grading, dict(flight.LEG_WORDS, short_down='gap below')) == [
        "the manual names the legs ['rest', 'short excursion', 'just below', 'long excursion', 'return just below', "
        "'further below'], grade.md ['rest', 'short excursion', 'gap', 'long excursion', 'return just below', "
        "'further below']"]


def test_the_plot_counts_the_calls_grade_md_counts(tmp_path, monkeypatch):
    """The legend's count of calls is question 13's (rest to end); a call of the calibration before the
    rest is counted apart, never in it."""
    import matplotlib
    matplotlib.use('Agg')
    from matplotlib.axes import Axes
    from exam_lab.grader.publish import flightplot
    labels = []
    original = Axes.plot
    monkeypatch.setattr(Axes, 'plot', lambda self, *a, **k: labels.append(k.get('label')) or original(self, *a, **k))
    schedule = {'rest': 5.0, 'short_up': 8.0, 'short_down': 11.0, 'long_up': 13.5, 'long_down': 21.0,
                'deep_down': 23.0, 'end': 25.0}
    probe = {'t0': 0.0, 'threshold': 1300.0, 'sheet': 'altitude', 'schedule': schedule,
             'calls': [[2.0, 'WARNING'], [3.0, 'NORMAL'], [18.5, 'WARNING'], [21.2, 'NORMAL']],
             'answers': [[t, r, True] for t, r in [[2.0, 'WARNING'], [3.0, 'NORMAL'], [18.5, 'WARNING'], [21.2, 'NORMAL']]],
             'trace': {'published': [[0.5, 1170.0], [20.0, 1430.0]], 'oracle': []}}
    assert flightplot.draw([('main', probe)], str(tmp_path / 'flight.png'))
    assert 'WARNING calls (1 in the flight, 1 before)' in labels and 'NORMAL calls (1 in the flight, 1 before)' in labels


def opener_problems(repo, path, text):
    """Lines of a Python excerpt printed without the statement whose block holds them (read with ast
    from the file itself): pasted, such a line lands in whatever block is printed above it."""
    import ast
    with open(os.path.join(repo, path)) as f:
        tree = ast.parse(f.read())
    shown = set()
    for part in re.match(r'# \S+, lines (.*)$', text.splitlines()[0]).group(1).split(', '):
        first, _, last = part.partition('-')
        shown.update(range(int(first), int(last or first) + 1))
    problems = []
    for parent in ast.walk(tree):
        for field in ('body', 'orelse', 'finalbody', 'handlers'):
            for child in getattr(parent, field, None) or []:
                if isinstance(parent, ast.Module) or not hasattr(child, 'lineno'):
                    continue
                if child.lineno in shown and parent.lineno not in shown:
                    problems.append('line %d without line %d, which opens its block' % (child.lineno, parent.lineno))
    return sorted(set(problems))


def test_every_excerpt_of_the_report_is_printed_whole_at_its_indent():
    """Issue 49: question 10's subscribers were printed under a callback (their block, def main():, left
    out): pasted, they landed inside it. Every Python excerpt shows the lines opening its blocks, and the
    report prints each excerpt as excerpts.py makes it."""
    import sys
    sys.path.insert(0, os.path.join(REPO, 'lab', 'report'))
    import excerpts
    report = _read(os.path.join(REPO, 'docs', 'report.md'))
    quoted = re.sub(r'^> ?', '', report, flags=re.M)
    for name in sorted(excerpts.EXCERPTS):
        text = excerpts.excerpt(REPO, name)
        assert text in quoted, '%s: not in docs/report.md as excerpts.py makes it (make report)' % name
        path = excerpts.EXCERPTS[name][0]
        if path.endswith('.py'):
            assert opener_problems(REPO, path, text) == [], name
    real = excerpts.openers
    try:
        excerpts.openers = lambda lines, first: []  # the excerpts as they were printed before
        old = excerpts.excerpt(REPO, 'q10.altitude')
    finally:
        excerpts.openers = real
    assert opener_problems(REPO, excerpts.ALTITUDE, old) == [
        'line 52 without line 43, which opens its block', 'line 53 without line 43, which opens its block']


def pdf_pages(path):
    """The text of each page of a PDF (pdftotext -layout), or None when pdftotext is missing."""
    import shutil
    if shutil.which('pdftotext') is None:
        return None
    text = subprocess.run(['pdftotext', '-layout', path, '-'], stdout=subprocess.PIPE, check=True).stdout
    return text.decode('utf-8', 'replace').split('\f')


def report_pdf_problems(markdown, pages, limit=10):
    """The report's PDF: the questions part within ``limit`` pages (the appendices start on page
    limit + 1 at the latest), and no command of a console block wrapped (each on one line of a page)."""
    problems = []
    starts = [n for n, page in enumerate(pages, 1) if re.search(r'^\s*Appendices\s*$', page, re.M)]
    if not starts or starts[0] > limit + 1:
        problems.append('the questions take %s pages (the appendices start on page %s)' % (
            starts[0] - 1 if starts else '?', starts[0] if starts else '?'))
    lines = {re.sub(r'\s+', ' ', l).strip() for page in pages for l in page.splitlines()}
    for name, language, body in blocks(markdown):
        if language != 'console':
            continue
        for command in (l for l in body.splitlines() if l.startswith('$ ')):
            wanted = re.sub(r'\s+', ' ', command).strip()
            if not any(wanted in line for line in lines):
                problems.append('wrapped or missing in the PDF: %s' % wanted)
    return problems


def test_the_report_pdf_teaches_the_questions_first_and_wraps_no_command():
    pages = pdf_pages(os.path.join(REPO, 'docs', 'report.pdf'))
    if pages is None:
        pytest.skip('pdftotext (poppler-utils) is not installed: the PDF is not checked')
    markdown = re.sub(r'^> ?', '', _read(os.path.join(REPO, 'docs', 'report.md')), flags=re.M)
    assert report_pdf_problems(markdown, pages) == []


def test_the_report_pdf_check_catches_a_long_questions_part_and_a_wrapped_command():
    pages = ['title\n1. Build', 'q\n$ rosrun exam_lab\n    exam_node_step10.py', '\nAppendices\n']
    markdown = '```console\n$ rosrun exam_lab exam_node_step10.py\n```\n'
    assert report_pdf_problems(markdown, pages, limit=1) == [
        'the questions take 2 pages (the appendices start on page 3)',
        'wrapped or missing in the PDF: $ rosrun exam_lab exam_node_step10.py']

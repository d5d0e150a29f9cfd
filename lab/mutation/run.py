"""Mutation testing of the answer's code with cosmic-ray, one session per group of mutation.toml.

Run by lab/mutation/run.sh with the interpreter of the virtual environment that holds cosmic-ray,
from the root of a scratch copy of the repository whose catkin workspace is sourced: cosmic-ray
writes each mutant into the file on disk, so it must never run in a working tree.

For each group: list its modules, create the cosmic-ray session, mark as skipped the mutants the
configuration rules out (operators not kept, string formatting, skipped lines, functions the group
does not target), check
that the test command passes on the unmutated code, run every remaining mutant against it, and write
report.md: the score and every surviving mutant with its diff. Surviving mutants judged in
known_mutants.toml are reported apart with their reason; the equivalent ones are left out of the score.

Usage: run.py CONFIG KNOWN_MUTANTS OUTDIR [group name ...]
"""
import ast
import datetime
import os
import re
import shlex
import subprocess
import sys
import time
from importlib.metadata import version

import toml
from cosmic_ray.work_db import WorkDB, use_db
from cosmic_ray.work_item import TestOutcome, WorkerOutcome, WorkResult

from scope import group_modules, unmatched


def session_config(modules, command, timeout):
    """The cosmic-ray configuration of one session, as a dict for toml."""
    return {'cosmic-ray': {
        'module-path': modules,
        'timeout': float(timeout),
        'excluded-modules': [],
        # cosmic-ray splits the command without a shell; the group's command may chain with &&.
        'test-command': 'bash -c %s' % shlex.quote(command),
        'distributor': {'name': 'local'},
    }}


def sessions(group):
    """(modules, test command) of each session of a group.

    A command naming ``{module-tests}`` gets one session per module, with that placeholder replaced by
    the group's ``module-tests`` path for the module (``{module}`` is its file name without .py) when
    that file exists: the module's own tests run first, so most mutants die in a fraction of the suite.
    """
    modules = group_modules(group)
    command = group['test']
    if '{module-tests}' not in command:
        return [(modules, command)]
    result = []
    for module in modules:
        first = group['module-tests'].format(module=os.path.splitext(os.path.basename(module))[0])
        result.append(([module], command.replace('{module-tests}', first if os.path.exists(first) else '')))
    return result


def string_formatting_spans(path):
    """Where the % of each ``'literal' % args`` can stand: ((line, col) after the string, (line, col)
    of the arguments). Such a % formats a string; it is no arithmetic."""
    with open(path) as source:
        tree = ast.parse(source.read(), path)
    return [((node.left.end_lineno, node.left.end_col_offset), (node.right.lineno, node.right.col_offset))
            for node in ast.walk(tree)
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod)
            and isinstance(node.left, ast.Constant) and isinstance(node.left.value, str)]


def skip_reason(mutation, rules, lines, formatting):
    """Why the configuration rules this mutation out, or None when it runs."""
    operator = mutation.operator_name
    if not any(re.match(keep, operator) for keep in rules['keep']):
        return 'operator not kept'
    line_no = mutation.start_pos[0]
    text = lines[line_no - 1].strip()
    position = tuple(mutation.start_pos)
    if (rules['skip-string-formatting'] and operator.startswith('core/ReplaceBinaryOperator_Mod_')
            and any(after <= position < before for after, before in formatting)):
        return 'string formatting'
    if any(re.search(pattern, text) for pattern in rules['skip-lines']):
        return 'skipped line'
    name = mutation.definition_name or ''
    if rules['definitions'] and not any(re.search(pattern, name) for pattern in rules['definitions']):
        return 'function not mutated by this group'
    if any(re.search(pattern, name) for pattern in rules['skip-definitions']):
        return 'function not mutated by this group'
    return None


def apply_filters(session, modules, rules):
    """Mark the ruled-out mutants of a session as skipped.

    Return {reason: count}.
    """
    sources = {m: open(m).read().splitlines() for m in modules}
    formatting = {m: string_formatting_spans(m) for m in modules}
    skipped = {}
    with use_db(session, WorkDB.Mode.open) as db:
        for item in list(db.pending_work_items):
            mutation = item.mutations[0]
            path = str(mutation.module_path)
            reason = skip_reason(mutation, rules, sources[path], formatting[path])
            if reason is not None:
                skipped[reason] = skipped.get(reason, 0) + 1
                db.set_result(item.job_id, WorkResult(output='filtered: ' + reason,
                                                      worker_outcome=WorkerOutcome.SKIPPED))
    return skipped


def cosmic_ray(*args, log=None):
    """Run one cosmic-ray command of the virtual environment; raise when it fails."""
    command = [os.path.join(os.path.dirname(sys.executable), 'cosmic-ray')] + list(args)
    subprocess.run(command, check=True, stdout=log, stderr=subprocess.STDOUT)


def load_known(path):
    """The surviving mutants already judged, (file, line, mutated line) -> (kind, reason).

    kind is 'equivalent' (no test can tell the mutant from the code) or 'not worth a test'.
    """
    known = {}
    for entry in toml.load(path).get('mutant', []):
        if entry['kind'] not in KINDS:
            sys.exit('mutation: %s: kind %r is none of %s' % (path, entry['kind'], KINDS))
        reason = ' '.join(entry['reason'].split())
        known[(entry['file'], entry['line'].strip(), entry['mutant'].strip())] = (entry['kind'], reason)
    return known


KINDS = ('equivalent', 'not worth a test')


def run_session(name, slug, modules, command, timeout, rules, outdir):
    """Run one cosmic-ray session; return ({skip reason: count},
    [(mutation, result)] of the mutants run)."""
    config_path = os.path.join(outdir, slug + '.toml')
    session = os.path.join(outdir, slug + '.sqlite')
    log_path = os.path.join(outdir, slug + '.log')
    with open(config_path, 'w') as out:
        toml.dump(session_config(modules, command, timeout), out)
    if os.path.exists(session):
        os.remove(session)
    with open(log_path, 'w') as log:
        cosmic_ray('init', config_path, session, log=log)
        skipped = apply_filters(session, modules, rules)
        print('mutation: %s: %d mutants skipped by the configuration %s; baseline...'
              % (name, sum(skipped.values()), skipped), flush=True)
        # The unmutated code must pass, or every mutant would count as killed.
        cosmic_ray('baseline', config_path, log=log)
        print('mutation: %s: running the mutants (log: %s)' % (name, log_path), flush=True)
        cosmic_ray('exec', config_path, session, log=log)
    results = []
    with use_db(session, WorkDB.Mode.open) as db:
        for item, result in db.completed_work_items:
            if result.worker_outcome != WorkerOutcome.SKIPPED:
                results.append((item.mutations[0], result))
    return skipped, results


def run_group(group, defaults, outdir):
    """Run the sessions of one group; return its results as a dict for the report."""
    rules = {
        'keep': defaults['keep'],
        'skip-string-formatting': defaults.get('skip-string-formatting', False),
        'skip-lines': group.get('skip-lines', []),
        'definitions': group.get('definitions', []),
        'skip-definitions': group.get('skip-definitions', []),
    }
    slug = re.sub(r'[^a-z0-9]+', '-', group['name'].lower()).strip('-')
    start = time.monotonic()
    skipped, results, modules = {}, [], []
    for modules_of_session, command in sessions(group):
        modules.extend(modules_of_session)
        name = group['name']
        session_slug = slug
        if len(modules_of_session) == 1 and '{module-tests}' in group['test']:
            stem = os.path.splitext(os.path.basename(modules_of_session[0]))[0]
            name, session_slug = '%s: %s' % (name, stem), '%s-%s' % (slug, stem)
        session_skipped, session_results = run_session(
            name, session_slug, modules_of_session, command, group['timeout'], rules, outdir)
        for reason, count in session_skipped.items():
            skipped[reason] = skipped.get(reason, 0) + count
        results.extend(session_results)
    return {'name': group['name'], 'test': group['test'], 'modules': modules, 'skipped': skipped,
            'results': results, 'seconds': time.monotonic() - start}


def describe(mutation):
    return '%s:%d %s (in %s)' % (mutation.module_path, mutation.start_pos[0],
                                 mutation.operator_name.replace('core/', ''),
                                 mutation.definition_name or 'module')


def mutated_lines(diff):
    """(original lines, mutated lines) of a cosmic-ray diff, each stripped and joined by newlines."""
    lines = (diff or '').splitlines()
    old = [l[1:].strip() for l in lines if l.startswith('-') and not l.startswith('---')]
    new = [l[1:].strip() for l in lines if l.startswith('+') and not l.startswith('+++')]
    return '\n'.join(old), '\n'.join(new)


def classify(results, known):
    """Split results: killed, equivalent, not worth a test (with their reasons), surviving, incompetent."""
    classes = {name: [] for name in ('killed', 'surviving', 'incompetent') + KINDS}
    for mutation, result in results:
        if result.worker_outcome != WorkerOutcome.NORMAL or result.test_outcome == TestOutcome.INCOMPETENT:
            classes['incompetent'].append((mutation, result, None))
        elif result.test_outcome == TestOutcome.KILLED:
            classes['killed'].append((mutation, result, None))
        else:
            kind, reason = known.get((str(mutation.module_path),) + mutated_lines(result.diff), (None, None))
            classes[kind or 'surviving'].append((mutation, result, reason))
    return classes


def score(classes):
    """(killed, non-equivalent mutants that ran); an equivalent mutant cannot be killed: it does not count."""
    killed = len(classes['killed'])
    return killed, killed + len(classes['surviving']) + len(classes['not worth a test'])


def write_report(path, runs, known, tool_version, total_seconds):
    """report.md: score per group and overall, every surviving mutant with its diff, the judged ones."""
    rows = []
    every = {}
    for run in runs:
        classes = classify(run['results'], known)
        for name, members in classes.items():
            every.setdefault(name, []).extend(members)
        killed, scored = score(classes)
        rows.append('| %s | %d | %d | %d | %d | %d | %d | %s | %s |' % (
            run['name'], sum(run['skipped'].values()), len(run['results']), killed,
            len(classes['equivalent']), len(classes['not worth a test']), len(classes['surviving']),
            percent(killed, scored), minutes(run['seconds'])))
    killed, scored = score(every)
    with open(path, 'w') as out:
        out.write('# Mutation testing report\n\n')
        out.write('%s, cosmic-ray %s, %s in all. Score: **%d killed of %d non-equivalent mutants (%s)**; '
                  '%d equivalent and %d not worth a test (lab/mutation/known_mutants.toml); %d surviving '
                  'not yet judged; %d incompetent.\n\n'
                  % (datetime.datetime.now().strftime('%Y-%m-%d %H:%M'), tool_version, minutes(total_seconds),
                     killed, scored, percent(killed, scored), len(every['equivalent']),
                     len(every['not worth a test']), len(every['surviving']), len(every['incompetent'])))
        out.write('| group | skipped by the configuration | ran | killed | equivalent | not worth a test '
                  '| surviving | score | time |\n')
        out.write('|---|---|---|---|---|---|---|---|---|\n')
        out.write('\n'.join(rows) + '\n\n')
        for run in runs:
            out.write('- %s: `%s` against %s; skipped: %s\n'
                      % (run['name'], run['test'], ', '.join(run['modules']), run['skipped'] or 'none'))
        out.write('\n## Surviving mutants not yet judged (%d)\n\n' % len(every['surviving']))
        out.write('Kill each with a sharper test, or judge it in lab/mutation/known_mutants.toml.\n\n'
                  if every['surviving'] else 'None.\n')
        for mutation, result, _ in every['surviving']:
            out.write('### %s\n\n```diff\n%s\n```\n\n' % (describe(mutation), (result.diff or '').strip()))
        for kind in KINDS:
            out.write('\n## Surviving, %s (%d)\n\n' % (kind, len(every[kind])))
            for mutation, result, reason in every[kind]:
                out.write('- %s: `%s`: %s\n' % (describe(mutation), mutated_lines(result.diff)[1], reason))
        if every['incompetent']:
            out.write('\n## Incompetent: the mutant could not be tested (%d)\n\n' % len(every['incompetent']))
            for mutation, result, _ in every['incompetent']:
                out.write('- %s: %s\n' % (describe(mutation), (result.output or '').strip()[-300:]))
    return killed, scored, len(every['surviving'])


def percent(part, whole):
    return '%.1f %%' % (100.0 * part / whole) if whole else 'n/a'


def minutes(seconds):
    return '%d min %02d s' % divmod(int(round(seconds)), 60)


def main(argv):
    config_path, known_path, outdir = argv[:3]
    wanted = argv[3:]
    config = toml.load(config_path)
    problems = unmatched(config)
    if problems:
        # A renamed or moved function: its mutants would silently leave the run (or join it).
        sys.exit('mutation: %s matches no function of its group; fix the scope in %s:\n%s'
                 % ('a pattern' if len(problems) == 1 else '%d patterns' % len(problems), config_path,
                    '\n'.join('  %s: %s %r' % problem for problem in problems)))
    groups = [g for g in config['group'] if not wanted or g['name'] in wanted]
    if wanted and len(groups) != len(wanted):
        sys.exit('mutation: unknown group in %s; the groups are: %s'
                 % (wanted, ', '.join(g['name'] for g in config['group'])))
    start = time.monotonic()
    runs = [run_group(group, config['operators'], outdir) for group in groups]
    report = os.path.join(outdir, 'report.md')
    killed, scored, surviving = write_report(report, runs, load_known(known_path), version('cosmic-ray'),
                                             time.monotonic() - start)
    print('mutation: %d killed of %d non-equivalent mutants (%s), %d surviving not yet judged; report: %s'
          % (killed, scored, percent(killed, scored), surviving, report))


if __name__ == '__main__':
    main(sys.argv[1:])

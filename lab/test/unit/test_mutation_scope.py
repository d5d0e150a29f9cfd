"""make mutation's scope (lab/mutation/mutation.toml) names functions that exist: a renamed function
would silently leave the run. The check itself is held to a configuration that names a missing one."""
import os
import sys

import toml

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
sys.path.insert(0, os.path.join(REPO, 'lab', 'mutation'))

import scope  # noqa: E402  (lab/mutation is no package: run.py runs as a script beside it)

CONFIG = os.path.join(REPO, 'lab', 'mutation', 'mutation.toml')


def test_every_pattern_of_the_project_names_a_function():
    assert scope.unmatched(toml.load(CONFIG), REPO) == []


def test_a_renamed_function_is_reported():
    config = toml.load(CONFIG)
    wiring = next(g for g in config['group'] if g.get('definitions'))
    wiring['definitions'] = wiring['definitions'] + ['^_stale_inputs$']
    wiring['skip-definitions'] = ['^no_such_function$']
    assert scope.unmatched(config, REPO) == [(wiring['name'], 'definitions', '^_stale_inputs$'),
                                             (wiring['name'], 'skip-definitions', '^no_such_function$')]


def test_a_dead_alternative_beside_live_ones_is_reported():
    config = toml.load(CONFIG)
    wiring = next(g for g in config['group'] if g.get('definitions'))
    wiring['definitions'] = ['^_(arm|stale_inputs|announce)$']
    assert scope.unmatched(config, REPO) == [(wiring['name'], 'definitions', '^_stale_inputs$')]


def test_alternatives():
    assert scope.alternatives('^_on_(reading|deadline)$') == ['^_on_reading$', '^_on_deadline$']
    assert scope.alternatives('^start$') == ['^start$']


def test_a_group_without_modules_is_reported():
    config = {'group': [{'name': 'gone', 'paths': ['exam/src/no_such_folder']}]}
    assert scope.unmatched(config, REPO) == [('gone', 'paths', 'exam/src/no_such_folder')]


def test_excludes_and_empty_files_are_left_out():
    group = {'name': 'exam', 'paths': ['exam/src/exam'], 'exclude': ['exam/src/exam/node.py']}
    modules = scope.group_modules(group, REPO)
    assert 'exam/src/exam/node.py' not in modules and 'exam/src/exam/formulas.py' in modules
    assert all(os.path.getsize(os.path.join(REPO, m)) > 0 for m in modules)

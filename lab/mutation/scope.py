"""What a group of mutation.toml targets, checked against the code before anything runs.

A group's ``definitions`` and ``skip-definitions`` are regular expressions on function names. A
function renamed or moved leaves its pattern matching nothing, and its mutants silently drop out of the
run (or into it): ``make mutation`` refuses such a configuration at once, and a unit test holds the
project's own configuration to the code on every ``make test``. Pure: ast and the file system only.
"""
import ast
import fnmatch
import os
import re


def group_modules(group, root='.'):
    """The .py files of a group: its paths (files or directories, relative to ``root``), less its
    excludes, sorted; empty files left out (cosmic-ray finds nothing to mutate in them)."""
    found = []
    for path in group['paths']:
        if path.endswith('.py'):
            found.append(path)
            continue
        for folder, _, files in os.walk(os.path.join(root, path)):
            rel = os.path.relpath(folder, root)
            found.extend(os.path.join(rel, name) for name in files if name.endswith('.py'))
    excludes = group.get('exclude', [])
    return sorted(p for p in found
                  if not any(fnmatch.fnmatch(p, pattern) for pattern in excludes)
                  and os.path.getsize(os.path.join(root, p)) > 0)


def function_names(path):
    """The names of every function and method defined in a Python file."""
    with open(path) as source:
        tree = ast.parse(source.read(), path)
    return {node.name for node in ast.walk(tree) if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))}


_ALTERNATION = re.compile(r'^([^()|]*)\(([^()]*\|[^()]*)\)([^()|]*)$')


def alternatives(pattern):
    """The patterns a one-group alternation stands for, each of which must name a function:
    ``^_(arm|stale)$`` -> ``^_arm$``, ``^_stale$`` (one live alternative would hide a dead one)."""
    match = _ALTERNATION.match(pattern)
    if match is None:
        return [pattern]
    head, choices, tail = match.groups()
    return [head + choice + tail for choice in choices.split('|')]


def unmatched(config, root='.'):
    """[(group name, key, pattern)] of every ``definitions``/``skip-definitions`` pattern (each
    alternative of it) of the configuration that names no function of its group's modules; a group with no module at all is
    reported as (name, 'paths', its paths)."""
    problems = []
    for group in config['group']:
        modules = group_modules(group, root)
        if not modules:
            problems.append((group['name'], 'paths', ', '.join(group['paths'])))
            continue
        names = set()
        for module in modules:
            names |= function_names(os.path.join(root, module))
        for key in ('definitions', 'skip-definitions'):
            for pattern in group.get(key, []):
                for each in alternatives(pattern):
                    if not any(re.search(each, name) for name in names):
                        problems.append((group['name'], key, each))
    return problems

"""Which launch file and which threshold the grader runs, and the copies of the student's launch
files it runs (:func:`derive`), from an :class:`~exam_lab.grader.boxed.launch.Analysis`.

The grader runs a *derived* launch file: the student's, without the drone (the grader's fake drone
plays it) nor any other package's node or include, every node's output to the screen (the log the
teacher reads), and optionally one parameter's value changed. Derived files are written next to the
originals (``.grader-<tag>-<name>``), which are all inside the package (so the derived files are in
the grader's copy of it, the work folder), and ``$(dirname)`` still means what the student meant.
The paths they name are ``$(find <package>)/...``: the run box sees the package at another path
than the grader does.
"""
import errno
import os
import re
import shlex

import yaml

from exam_lab.grader.boxed import launch
from exam_lab.grader.score.sheets import SHEETS

#: Parameter names that say "threshold", and those that say something else (a rate, a delay...).
_THRESHOLD_WORDS = ('thresh', 'seuil', 'limit', 'lim', 'max', 'alert', 'warn', 'alarm', 'ceiling')
_OTHER_WORDS = ('rate', 'delay', 'hz', 'freq', 'period', 'duration', 'time', 'seed', 'profile', 'mode',
                'count', 'tick', 'iter', 'queue', 'timeout', 'wait')


# --- choosing --------------------------------------------------------------------------------------

def launch_files(package_dir):
    """Every ``*.launch`` / ``*.launch.xml`` file of the package (derived copies excluded)."""
    found = []
    for dirpath, dirnames, filenames in os.walk(package_dir):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith('.'))
        for filename in sorted(filenames):
            if filename.endswith(('.launch', '.launch.xml')) and not filename.startswith('.grader-'):
                found.append(os.path.join(dirpath, filename))
    return found


def choose(analyses, sheet):
    """The analysis of the launch file to grade for ``sheet`` (None when none starts an exam node):
    the one that starts the sheet's drone, then one named exam.launch, then the first."""
    def score(a):
        other = [s for s in a.drone_sheets() if s != sheet]
        return (bool(a.exam_nodes), sheet in a.drone_sheets(), not other,
                os.path.basename(a.path) == 'exam.launch')
    ranked = sorted(analyses, key=score, reverse=True)
    if not ranked or not ranked[0].exam_nodes:
        return None
    return ranked[0]


def threshold_param(analysis, sheet):
    """The value the exam node gets as its threshold, however named and handed over (a parameter, a
    word of its ``args``), and why it was chosen.

    :returns: ``(Param or NodeArg or None, reason)``. A name that says threshold (``threshold``,
        ``seuil``, ``alt_max``, ``--threshold``, ``args="$(arg threshold)"``...) wins over the sheet's
        default value (1300 / 150) under another name; a name that says something else (rate,
        delay...) is never taken; a parameter wins over an argument of the same standing.
    """
    default = SHEETS[sheet].threshold
    best, best_score = None, 0
    for param in list(analysis.exam_params()) + list(analysis.exam_args()):
        number = launch.as_number(param.value)
        if number is None:
            continue
        if isinstance(param, launch.NodeArg):
            base = param.label.lstrip('-').lower()
        else:
            base = param.name.rsplit('/', 1)[-1].lower()
        score = 0
        if 'thresh' in base or 'seuil' in base:
            score = 4
        elif any(word in base for word in _THRESHOLD_WORDS) and not any(w in base for w in _OTHER_WORDS):
            score = 3
        elif any(w in base for w in _OTHER_WORDS):
            continue
        if number == default:
            score += 1
        if score > best_score:
            best, best_score = param, score
    if best is None:
        names = ', '.join([p.name for p in analysis.exam_params()] +
                          ['args %s' % a.name for a in analysis.exam_args()]) or 'none'
        return None, 'no parameter or argument of the launch file looks like a threshold (given: %s)' % names
    how = 'named like a threshold' if best_score >= 3 else 'the sheet\'s value %g' % default
    kind = 'argument %s of node %s' % (best.name, best.node.name) if isinstance(best, launch.NodeArg) else best.name
    return best, '%s = %s (%s)' % (kind, best.value, how)


# --- deriving --------------------------------------------------------------------------------------

def derive(analysis, tag, changes=None):
    """Write the runnable copy of the analysed launch file; return its path.

    The copy starts only the exam package's nodes (the drone and other packages' nodes and includes
    are dropped), sends every node's output to the screen, and drops ``launch-prefix`` (a terminal or
    debugger the grader does not have). ``changes`` maps an :class:`Origin` to the new literal value.
    Included files of the exam package get derived copies too, and the includes point to them.

    Every file is written beside its original, all of which are inside the package (:func:`analyse`
    reads no other), and names the others as ``$(find <package>)/...``, which the run box resolves.
    """
    changes = changes or {}
    originals = {}
    # Remember every element's state, so that several derivations start from the student's files.
    for tree in analysis.trees.values():
        for element in tree.iter():
            originals[element] = (dict(element.attrib), element.text, list(element))
    try:
        yaml_files = {}
        for origin, value in changes.items():
            _apply(origin, value, analysis, tag, yaml_files)
        derived = {path: _derived_path(path, tag) for path in analysis.trees}
        for path, tree in analysis.trees.items():
            _strip(tree.getroot(), path, analysis, derived)
            with _create(analysis, derived[path]) as f:
                tree.write(f, encoding='unicode')
        return _derived_path(analysis.path, tag)
    finally:
        for element, (attrib, text, children) in originals.items():
            element.attrib.clear()
            element.attrib.update(attrib)
            element.text = text
            element[:] = children


def _derived_path(path, tag):
    return os.path.join(os.path.dirname(path), '.grader-%s-%s' % (tag, os.path.basename(path)))


def _found(analysis, path):
    """``path`` (inside the package) as the run box finds it: ``$(find <package>)/relative/path``."""
    folder = os.path.relpath(os.path.realpath(os.path.dirname(path)), os.path.realpath(analysis.package_dir))
    return '$(find %s)/%s' % (analysis.package, os.path.normpath(os.path.join(folder, os.path.basename(path))))


def _create(analysis, path):
    """``path`` opened for writing, only inside the package and never through a link a student left."""
    folder = os.path.dirname(path)
    if os.path.realpath(folder) != os.path.realpath(analysis.package_dir) \
            and launch.inside(analysis.package_dir, folder) is None:
        raise ValueError('derived file %s would be outside the package %s' % (path, analysis.package_dir))
    try:
        os.unlink(path)
    except OSError as err:
        if err.errno != errno.ENOENT:
            raise
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW, 0o644)
    return os.fdopen(fd, 'w', encoding='utf-8')


def _apply(origin, value, analysis, tag, yaml_files):
    if origin.kind == 'attr':
        origin.element.set(origin.key, str(value))
        return
    if origin.kind == 'args':
        index, prefix = origin.key
        words = launch.split_args(origin.element.get('args'))
        words[index] = prefix + str(value)
        origin.element.set('args', ' '.join(w if not re.search(r'[\s\'"]', w) else shlex.quote(w) for w in words))
        return
    if origin.kind == 'yaml':
        data = launch.load_yaml(origin.element.text or '')
        origin.element.text = yaml.safe_dump(_set_key(data, origin.key, value), default_flow_style=False)
        return
    source = yaml_files.get(origin.yaml_file, origin.yaml_file)
    with open(source, encoding='utf-8', errors='replace') as f:
        data = launch.load_yaml(f.read())
    target = _derived_path(origin.yaml_file, tag)
    with _create(analysis, target) as f:
        f.write(yaml.safe_dump(_set_key(data, origin.key, value), default_flow_style=False))
    yaml_files[origin.yaml_file] = target
    origin.element.set('file', _found(analysis, target))


def _set_key(data, key, value):
    if not key:
        return value
    data = dict(data or {})
    data[key[0]] = _set_key(data.get(key[0]), key[1:], value)
    return data


def _strip(parent, path, analysis, derived):
    scope = launch.Scope(path, analysis.package_dir, package=analysis.package, env=analysis.env)
    for element in list(parent):
        if not isinstance(element.tag, str):
            continue
        if element.tag in ('node', 'test'):
            pkg = element.get('pkg', '')
            if pkg != analysis.package and '$(arg' not in pkg:
                parent.remove(element)
                continue
            element.set('output', 'screen')
            element.attrib.pop('launch-prefix', None)
            element.attrib.pop('machine', None)
        elif element.tag == 'machine':
            parent.remove(element)
            continue
        elif element.tag == 'include':
            try:
                target = launch.inside(analysis.package_dir, scope.substitute(element.get('file'))[0])
            except launch.Unsupported:
                target = None
            if target in derived:
                element.set('file', _found(analysis, derived[target]))
            else:
                parent.remove(element)
            continue
        _strip(element, path, analysis, derived)

"""Reading a student's launch files without running them (:mod:`~.derive` writes the copies run).

No rospy here: this is a small evaluator of roslaunch XML, enough for exam answers. It understands
``<arg>`` (default / value, passed to ``<include>``), ``<group ns>``, ``if`` / ``unless``,
``<node>`` (its private ``<param>`` and ``<rosparam>``), ``<param>`` and ``<rosparam>`` (inline YAML or
``command="load" file=...``) at any level, ``<include>`` of the exam package's own files, and the
substitutions ``$(arg)``, ``$(find)``, ``$(dirname)``, ``$(env)``, ``$(optenv)``. What it cannot
evaluate (``$(eval)``, unknown args) is reported, never guessed.

What it reads is the student's, and only that (issue 26): ``$(env)`` / ``$(optenv)`` take their values
from the ``env`` mapping given (the box's environment), never from the grader's own; every file a
launch file names is opened only when its real path (links and ``..`` resolved) is inside the package
folder, else the analysis says "file outside the package: ... not read"; YAML with anchors or aliases
is refused (a 0.8 KB file of nested aliases expands to millions of parameters); at most ``MAX_FILES``
launch files are read, ``MAX_INCLUDE_DEPTH`` deep. ``<param textfile= binfile= command=>`` are never read.

Every parameter keeps the place its literal value comes from (an attribute of an element, a key of
inline YAML or of a YAML file), followed through ``$(arg ...)``, so the grader can change a threshold
"however it is named or set" and run the student's own launch file with the new value.
"""
import collections
import os
import re
import shlex

import yaml

from exam_lab.grader.boxed import repair
from exam_lab.grader.score.sheets import PACKAGE, SHEETS, sheet_of_drone

#: Substitution pattern of roslaunch: ``$(command args)``.
_SUBST = re.compile(r'\$\((\w+)((?:\s+[^)]*)?)\)')

ALIASES_REFUSED = 'YAML anchors and aliases (&name, *name) are refused: a few can expand to millions of values'
#: Launch files read for one analysis (the top one and its includes, each time), how deep includes go.
MAX_FILES, MAX_INCLUDE_DEPTH = 50, 6
#: A node; ``type_origin`` is where its ``type`` literal lives (an :class:`Origin`), for a fix.
Node = collections.namedtuple('Node', 'pkg type name ns file type_origin')
#: A parameter: full name, value, where its literal lives (:class:`Origin` or None), owning node.
Param = collections.namedtuple('Param', 'name value origin node')
#: A value a node gets on its command line (``args=``), read with ``rospy.myargv`` / argparse: ``name``
#: is the option (``--threshold``) or the place (``argv[1]``), ``label`` the words that name it (the
#: option, or the ``$(arg)`` its value comes from).
NodeArg = collections.namedtuple('NodeArg', 'name value origin node label')


class Unsupported(Exception):
    """A construct this evaluator does not understand (the message says which)."""


class Origin(object):
    """Where a literal value lives, so that it can be changed in a derived file.

    ``kind`` is ``'attr'`` (``element.get(key)``), ``'yaml'`` (key path ``key`` in the inline YAML text
    of ``element``), ``'yaml_file'`` (key path ``key`` in the file named by ``element``'s ``file``) or
    ``'args'`` (``key`` = (index, prefix): the index-th word of ``element``'s ``args``, after ``prefix``).
    """

    def __init__(self, path, element, kind, key, yaml_file=None):
        self.path = path
        self.element = element
        self.kind = kind
        self.key = key
        self.yaml_file = yaml_file

    def describe(self, package_dir):
        where = os.path.relpath(self.yaml_file or self.path, package_dir)
        if self.kind == 'attr':
            return '%s: <%s name="%s"> %s' % (where, self.element.tag, self.element.get('name'), self.key)
        if self.kind == 'args':
            return '%s: <%s name="%s"> args, word %d' % (where, self.element.tag, self.element.get('name'),
                                                        self.key[0] + 1)
        return '%s: YAML key %s' % (where, '/'.join(self.key))


class Analysis(object):
    """What one top-level launch file (and the files it includes) would start and set."""

    def __init__(self, path, package_dir, package=PACKAGE, env=None):
        self.path = path
        self.package_dir = package_dir
        #: The student's package name (``exam`` as asked, or whatever the student named it).
        self.package = package
        #: The environment ``$(env)`` and ``$(optenv)`` see: the box's, never the grader's.
        self.env = dict(env or {})
        self.files_read = 0
        self.nodes = []
        self.params = []
        #: What the nodes get on their command line (:class:`NodeArg`).
        self.node_args = []
        #: Drone packages started through an ``<include>`` of their own launch files.
        self.included_drones = []
        self.problems = []
        #: What roslaunch refuses in these files and the grader repaired to read and run them, one
        #: sentence each (:mod:`~exam_lab.grader.boxed.repair`): question 12's loss, nothing else.
        self.repairs = []
        #: real path -> parsed tree of every file read (the top one and the exam package's includes).
        self.trees = collections.OrderedDict()

    @property
    def exam_nodes(self):
        return [n for n in self.nodes if n.pkg == self.package]

    def drone_sheets(self):
        """Sheets whose drone this launch starts (by a node or by including the drone's launch file)."""
        sheets = [sheet_of_drone(n.pkg) for n in self.nodes if sheet_of_drone(n.pkg)]
        sheets += [sheet_of_drone(pkg) for pkg in self.included_drones]
        return sorted(set(sheets))

    def starts_drone(self, sheet):
        drone = SHEETS[sheet]
        return any(n.pkg == drone.drone_pkg and n.type == drone.drone_type for n in self.nodes) \
            or drone.drone_pkg in self.included_drones

    def drone_namespace(self, sheet):
        """The namespace of the drone node in this launch ('/' when none or at the top)."""
        for node in self.nodes:
            if node.pkg == SHEETS[sheet].drone_pkg:
                return node.ns
        return '/'

    def exam_params(self):
        """Parameters the exam node can see: global ones and the exam nodes' private ones."""
        return [p for p in self.params if p.node is None or p.node.pkg == self.package]

    def exam_args(self):
        """What the exam nodes get on their command line (:class:`NodeArg`)."""
        return [a for a in self.node_args if a.node.pkg == self.package]

    def comments(self):
        """XML comments in the launch file and the package's files it includes (question 12's half)."""
        count = 0
        for path in self.trees:
            try:
                with open(path, 'rb') as f:
                    count += f.read().count(b'<!--')
            except OSError:
                pass
        return count


def _truth(text):
    value = text.strip().lower()
    if value in ('true', '1'):
        return True
    if value in ('false', '0'):
        return False
    raise Unsupported('if/unless value %r' % text)


def _join(ns, name):
    if name.startswith('/'):
        return name
    return (ns.rstrip('/') + '/' + name) if ns != '/' else '/' + name


def as_number(value):
    """``value`` as a float if it is a number (or a string holding one), else None."""
    if isinstance(value, bool):
        return None
    if isinstance(value, (int, float)):
        return float(value)
    try:
        return float(str(value).strip())
    except ValueError:
        return None


class _NoAliasLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing anchors and aliases as the composer meets them: before any
    node is shared, so an alias bomb costs what its text costs."""

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent) or getattr(event, 'anchor', None) is not None:
            raise yaml.composer.ComposerError(None, None, ALIASES_REFUSED, event.start_mark)
        return super(_NoAliasLoader, self).compose_node(parent, index)


def yaml_problem(err):
    """A YAML error in one line: what, and where."""
    mark = getattr(err, 'problem_mark', None)
    what = getattr(err, 'problem', None) or str(err).split('\n')[0]
    return '%s (line %d)' % (what, mark.line + 1) if mark is not None else what


def load_yaml(text):
    """``text`` as YAML, safely: no Python tags, no anchors or aliases (:class:`_NoAliasLoader`).

    :raises yaml.YAMLError: for anything that does not parse or is refused, absurd nesting included.
    """
    try:
        return yaml.load(text, Loader=_NoAliasLoader)
    except RecursionError:
        raise yaml.YAMLError('YAML nested too deep')


def inside(package_dir, path):
    """The real path of ``path`` (links and ``..`` resolved) when it is inside ``package_dir``, else
    None: ``$(find exam)/../../..`` and a link out of the package are outside."""
    if not path:
        return None
    root = os.path.realpath(package_dir)
    real = os.path.realpath(path)
    return real if real.startswith(root.rstrip(os.sep) + os.sep) else None


def _yaml_value(text):
    """A ``<param value>`` as roslaunch types it: bool, int, float or str (no type= attribute)."""
    try:
        value = load_yaml(text)
    except yaml.YAMLError:
        return text
    return value if isinstance(value, (bool, int, float)) else text


class Scope(object):
    """Args of one launch file: name -> (value, Origin of its literal or None)."""

    def __init__(self, path, package_dir, passed=None, package=PACKAGE, env=None):
        self.path = path
        self.package_dir = package_dir
        self.package = package
        self.args = {}
        self.passed = passed or {}
        self.env = env or {}

    def substitute(self, text):
        """``text`` with every substitution evaluated, and the Origin when it is exactly one $(arg)."""
        if text is None:
            return None, None
        whole = _SUBST.fullmatch(text.strip())
        if whole and whole.group(1) == 'arg':
            name = whole.group(2).strip()
            if name not in self.args:
                raise Unsupported('$(arg %s) of an undeclared arg in %s' % (name, self.path))
            return self.args[name]
        return _SUBST.sub(self._one, text), None

    def _one(self, match):
        command, rest = match.group(1), match.group(2).split()
        if command == 'arg':
            if not rest or rest[0] not in self.args:
                raise Unsupported('$(arg %s) of an undeclared arg' % ' '.join(rest))
            return str(self.args[rest[0]][0])
        if command == 'find':
            if rest and rest[0] == self.package:
                return self.package_dir
            return '/__pkg__/%s' % (rest[0] if rest else '')
        if command == 'dirname':
            return os.path.dirname(self.path)
        if command in ('env', 'optenv'):
            return self.env.get(rest[0], ' '.join(rest[1:])) if rest else ''
        if command == 'anon':
            return '_'.join(rest)
        raise Unsupported('$(%s ...)' % command)


def analyse(path, package_dir, package=PACKAGE, env=None):
    """Analyse the launch file ``path`` of the package ``package`` in ``package_dir``; never raises for
    content.

    :param env: what ``$(env)`` / ``$(optenv)`` see: the environment of a ROS process in the box
        (:func:`exam_lab.grader.score.boxenv.box_env`); none when not given.
    """
    analysis = Analysis(path, package_dir, package, env)
    if inside(package_dir, path) is None:
        analysis.problems.append(_outside(path))
        return analysis
    try:
        _read_file(analysis, path, Scope(path, package_dir, package=package, env=analysis.env), '/', depth=0)
    except Unsupported as err:
        analysis.problems.append('cannot evaluate %s: %s' % (os.path.relpath(path, package_dir), err))
    return analysis


def _outside(written):
    return 'file outside the package: %s not read' % written


def _read_file(analysis, path, scope, ns, depth):
    analysis.files_read += 1
    if analysis.files_read > MAX_FILES:
        raise Unsupported('more than %d launch files read (includes of includes)' % MAX_FILES)
    tree = repair.read(path, os.path.relpath(path, analysis.package_dir), analysis.problems, analysis.repairs)
    if tree is None:
        return
    analysis.trees[os.path.realpath(path)] = tree
    _read_children(analysis, tree.getroot(), scope, ns, None, depth)


def _enabled(element, scope):
    for attr, wanted in (('if', True), ('unless', False)):
        if element.get(attr) is not None and _truth(scope.substitute(element.get(attr))[0]) != wanted:
            return False
    return True


def _read_children(analysis, parent, scope, ns, node, depth):
    for element in list(parent):
        if not isinstance(element.tag, str) or not _enabled(element, scope):
            continue
        tag = element.tag
        if tag == 'arg':
            _read_arg(element, scope)
        elif tag == 'group':
            group_ns = element.get('ns')
            inner = _join(ns, scope.substitute(group_ns)[0]) if group_ns else ns
            _read_children(analysis, element, scope, inner, node, depth)
        elif tag == 'node':
            if element.get('name') is None and element.get('type'):
                repair.name_node(analysis, element, scope)
            name = scope.substitute(element.get('name'))[0] or ''
            node_ns = _join(ns, scope.substitute(element.get('ns'))[0]) if element.get('ns') else ns
            node_type, type_origin = scope.substitute(element.get('type'))
            this = Node(scope.substitute(element.get('pkg'))[0], node_type, name, node_ns, scope.path,
                        type_origin or Origin(scope.path, element, 'attr', 'type'))
            analysis.nodes.append(this)
            _read_node_args(analysis, element, scope, _join(node_ns, name), this)
            _read_children(analysis, element, scope, _join(node_ns, name), this, depth)
        elif tag == 'param':
            _read_param(analysis, element, scope, ns, node)
        elif tag == 'rosparam':
            _read_rosparam(analysis, element, scope, ns, node)
        elif tag == 'include':
            _read_include(analysis, element, scope, ns, depth)


def _read_arg(element, scope):
    name = element.get('name')
    for attr in ('value', 'default'):
        if element.get(attr) is None:
            continue
        if attr == 'default' and name in scope.passed:
            scope.args[name] = scope.passed[name]
            return
        value, origin = scope.substitute(element.get(attr))
        scope.args[name] = (value, origin or Origin(scope.path, element, 'attr', attr))
        return
    if name in scope.passed:
        scope.args[name] = scope.passed[name]
    else:
        scope.args[name] = ('', None)  # declared without a value: an error only if used


#: A substitution kept whole when a launch file's ``args`` is cut into words.
_WHOLE_SUBST = re.compile(r'\$\([^)]*\)')


def split_args(text):
    """``args`` cut into words as roslaunch does (``shlex.split``), each word as written: its
    substitutions not yet evaluated (roslaunch evaluates them first; a ``$(arg)`` value is one word)."""
    kept = []

    def keep(match):
        kept.append(match.group(0))
        return '\x00%d\x00' % (len(kept) - 1)
    words = shlex.split(_WHOLE_SUBST.sub(keep, text))
    return [re.sub('\x00(\\d+)\x00', lambda m: kept[int(m.group(1))], w) for w in words]


def _word_value(scope, element, index, prefix, written):
    """The value of the part ``written`` of the index-th word and where its literal lives: the
    ``$(arg)`` it is exactly, else the word itself."""
    value, origin = scope.substitute(written)
    return value, origin or Origin(scope.path, element, 'args', (index, prefix))


def _read_node_args(analysis, element, scope, full_name, node):
    """A node's ``args``: ``_name:=value`` words are private parameters (rospy's init_node sets
    them, :func:`rospy.client.load_command_line_node_params`); the other words are what
    ``rospy.myargv()`` returns after the script's path: ``--name value``, ``--name=value``, positional
    values (``argv[1]``...)."""
    text = element.get('args')
    if not text:
        return
    try:
        words = split_args(text)
    except ValueError as err:
        analysis.problems.append('args of node %s not read: %s' % (full_name, err))
        return
    position, skip = 0, False
    for index, word in enumerate(words):
        if skip:
            skip = False
            position += 1
            continue
        remap = re.match(r'^(_[A-Za-z][\w/]*:=)(.*)$', word)
        if remap:
            value, origin = _word_value(scope, element, index, remap.group(1), remap.group(2))
            analysis.params.append(Param(_join(full_name, remap.group(1)[1:-2]), _yaml_value(str(value)),
                                         origin, node))
            continue
        if ':=' in word:
            continue  # a remapping or a special key (__ns, __name): not in myargv
        position += 1
        option = re.match(r'^(--?[A-Za-z][\w-]*)(=(.*))?$', word)
        if option and option.group(2):
            value, origin = _word_value(scope, element, index, option.group(1) + '=', option.group(3))
            analysis.node_args.append(NodeArg(option.group(1), _yaml_value(str(value)), origin, node, option.group(1)))
        elif option:
            following = words[index + 1] if index + 1 < len(words) else None
            if following is not None and ':=' not in following and \
                    (not following.startswith('-') or as_number(following) is not None):
                value, origin = _word_value(scope, element, index + 1, '', following)
                analysis.node_args.append(NodeArg(option.group(1), _yaml_value(str(value)), origin, node,
                                                  option.group(1)))
                skip = True
        else:
            value, origin = _word_value(scope, element, index, '', word)
            whole = _SUBST.fullmatch(word.strip())
            label = whole.group(2).strip() if whole and whole.group(1) == 'arg' else ''
            analysis.node_args.append(NodeArg('argv[%d]' % position, _yaml_value(str(value)), origin, node, label))


def _read_param(analysis, element, scope, ns, node):
    name = scope.substitute(element.get('name'))[0]
    if element.get('value') is None:
        return  # textfile / command / binfile: not a number a threshold would be
    raw, origin = scope.substitute(element.get('value'))
    if origin is None:
        origin = Origin(scope.path, element, 'attr', 'value')
    kind = element.get('type')
    value = raw if kind == 'str' else _yaml_value(raw)
    analysis.params.append(Param(_join(ns, name), value, origin, node))


def _read_rosparam(analysis, element, scope, ns, node):
    command = element.get('command', 'load')
    if command != 'load':
        return
    base = _join(ns, scope.substitute(element.get('ns'))[0]) if element.get('ns') else ns
    param = scope.substitute(element.get('param'))[0] if element.get('param') else None
    if element.get('file'):
        yaml_file = inside(analysis.package_dir, scope.substitute(element.get('file'))[0])
        if yaml_file is None:
            analysis.problems.append(_outside('rosparam %s' % element.get('file')))
            return
        if not os.path.isfile(yaml_file):
            analysis.problems.append('rosparam file %s not found in the package' % element.get('file'))
            return
        with open(yaml_file, encoding='utf-8', errors='replace') as f:
            text = f.read()
        kind = 'yaml_file'
    else:
        yaml_file = None
        text = element.text or ''
        if element.get('subst_value', 'false').lower() in ('true', '1'):
            text = scope.substitute(text)[0]
        kind = 'yaml'
    try:
        data = load_yaml(text)
    except yaml.YAMLError as err:
        analysis.problems.append('rosparam %s not read: %s'
                                 % (element.get('file') or 'inline YAML', yaml_problem(err)))
        return
    prefix = _join(base, param) if param else base
    for key, value in _flatten(data, ()):
        if not key and not param:
            continue
        name = prefix if not key else _join(prefix, '/'.join(key))
        analysis.params.append(Param(name, value, Origin(scope.path, element, kind, key, yaml_file), node))


def _flatten(data, key):
    if isinstance(data, dict):
        for k, v in data.items():
            for item in _flatten(v, key + (str(k),)):
                yield item
    else:
        yield key, data


def _read_include(analysis, element, scope, ns, depth):
    target = scope.substitute(element.get('file'))[0] or ''
    inner_ns = _join(ns, scope.substitute(element.get('ns'))[0]) if element.get('ns') else ns
    found = re.match(r'/__pkg__/(\w+)', target)
    if found:
        if sheet_of_drone(found.group(1)):
            analysis.included_drones.append(found.group(1))
        return  # another package's launch file: not the student's, not analysed
    real = inside(analysis.package_dir, target)
    if real is None:
        analysis.problems.append(_outside('include %s' % element.get('file')))
        return
    if depth >= MAX_INCLUDE_DEPTH or not os.path.isfile(real):
        analysis.problems.append('include %s %s' % (element.get('file'), 'not found' if depth < MAX_INCLUDE_DEPTH else
                                                    'not read: it is included %d deep (at most %d)'
                                                    % (depth + 1, MAX_INCLUDE_DEPTH)))
        return
    passed = {}
    all_args = element.get('pass_all_args')
    if all_args is not None and _truth(scope.substitute(all_args)[0]):
        passed = dict(scope.args)  # roslaunch: every arg of the including file, overridden below
    for child in element:
        if child.tag == 'arg' and child.get('value') is not None:
            value, origin = scope.substitute(child.get('value'))
            passed[child.get('name')] = (value, origin or Origin(scope.path, child, 'attr', 'value'))
    _read_file(analysis, real, Scope(real, analysis.package_dir, passed, analysis.package, analysis.env),
               inner_ns, depth + 1)

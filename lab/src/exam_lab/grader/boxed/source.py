"""What the grader reads in a student's sources (never runs): the node's scripts, comments, params,
dependencies; and the fixes a teacher would make before running it. No rospy here.

Code is read as code (issue 36): every check on what the code does (a node, the parameters and
arguments it reads, a service client and its calls, publishing, timers, the topics it names) walks
Python's syntax tree (:mod:`ast`), so a comment or a string that mentions ``get_param('threshold')`` or
``ServiceProxy`` counts for nothing. A file that does not parse as Python 3 (Python 2, a typo) is
read as text instead, and :func:`unparsed` names it with the line Python stopped at, so the teacher
knows which facts came from text.
"""
import ast
import io
import os
import re
import shutil
import stat
import tokenize
import xml.etree.ElementTree as ET

from exam_lab.grader.score.sheets import SHEETS

#: The text fallback for a file that does not parse (comments dropped first where tokenize can).
_INIT_NODE = re.compile(r'\binit_node\s*\(')
_GET_PARAM = re.compile(r'get_param\s*\(\s*[\'"]([^\'"]+)[\'"]')
_SERVICE_CLIENT = re.compile(r'\b(ServiceProxy|wait_for_service)\b')
#: rospy's calls that read a parameter by name (its first argument).
PARAM_READERS = ('get_param', 'get_param_cached', 'search_param', 'has_param')
#: Calls that make a service client.
SERVICE_CLIENTS = ('ServiceProxy', 'wait_for_service')
#: Files whose line endings and BOM a teacher fixes: sources, scripts, launch and build files.
TEXT_ENDINGS = ('.py', '.launch', '.xml', '.yaml', '.yml', '.txt', '.cfg', '.sh', '.srv', '.msg')
_BOM = b'\xef\xbb\xbf'
#: Python 2 on a line, with the words a teacher reads: what the SyntaxError under Python 3 means.
_PYTHON2 = ((re.compile(r'^\s*print\b(\s+["\'\w%(>]|\s*$)'), 'print statement'),
            (re.compile(r'^\s*except\s+[\w.]+\s*,\s*\w+\s*:'), '"except E, e:"'),
            (re.compile(r'^\s*exec\s+["\'\w]'), 'exec statement'),
            (re.compile(r'^\s*raise\s+[\w.]+\s*,'), '"raise E, message"'),
            (re.compile(r'<>'), 'the <> operator'),
            (re.compile(r'\b0[0-7]+\b'), 'an octal literal like 0777'),
            (re.compile(r'`'), 'backquotes'))


def python_files(package_dir):
    """The package's Python sources: ``*.py`` files and extension-less scripts with a python shebang."""
    found = []
    for dirpath, dirnames, filenames in os.walk(package_dir):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith('.'))
        for filename in sorted(filenames):
            full = os.path.join(dirpath, filename)
            if filename.endswith('.py') or ('.' not in filename and _shebang(full).find('python') >= 0):
                found.append(full)
    return found


def _shebang(path):
    try:
        with open(path, 'rb') as f:
            first = f.readline(200)
    except OSError:
        return ''
    return first.decode('utf-8', 'replace').strip() if first.startswith(b'#!') else ''


def _read(path):
    with open(path, 'rb') as f:
        return f.read().decode('utf-8', 'replace')


class Parsed(object):
    """One Python file of the package: its syntax ``tree``, or None with ``error`` (why it does not
    parse: ``"SyntaxError at line 19"``) and ``code`` (its text without comments, for the fallback)."""

    def __init__(self, path, package_dir):
        self.path = path
        self.rel = os.path.relpath(path, package_dir)
        self.text = _read(path)
        self.tree, self.error = None, None
        try:
            self.tree = ast.parse(self.text, self.rel)
        except SyntaxError as err:
            self.error = '%s at line %s' % (type(err).__name__, err.lineno)
        except (ValueError, RecursionError, MemoryError, OverflowError) as err:  # null bytes, absurd nesting
            self.error = type(err).__name__
        self.code = self.text if self.tree is not None else _without_comments(self.text)

    def where(self, node):
        return '%s:%d' % (self.rel, node.lineno)

    def calls(self, *names):
        """Every call whose function is named one of ``names`` (``f(...)``, ``x.f(...)``)."""
        if self.tree is None:
            return []
        return [n for n in ast.walk(self.tree) if isinstance(n, ast.Call) and call_name(n) in names]

    def strings(self):
        """Every string constant of the code but docstrings."""
        if self.tree is None:
            return []
        docstrings = set()
        for node in ast.walk(self.tree):
            body = getattr(node, 'body', None)
            if isinstance(body, list) and body and isinstance(body[0], ast.Expr) \
                    and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str):
                docstrings.add(id(body[0].value))
        return [n.value for n in ast.walk(self.tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)
                and id(n) not in docstrings]


def _without_comments(text):
    """``text`` without its comments, where tokenize can read it; as it is otherwise."""
    try:
        tokens = [t for t in tokenize.generate_tokens(io.StringIO(text).readline) if t.type != tokenize.COMMENT]
        return tokenize.untokenize(tokens)
    except (tokenize.TokenError, IndentationError, SyntaxError, ValueError):
        return text


def call_name(call):
    """The name a call's function goes by: ``f`` for ``f(...)`` and ``a.b.f(...)``; '' otherwise."""
    func = call.func
    if isinstance(func, ast.Name):
        return func.id
    if isinstance(func, ast.Attribute):
        return func.attr
    return ''


def dotted(node):
    """``a.b.c`` for a name or an attribute chain, else None."""
    if isinstance(node, ast.Name):
        return node.id
    if isinstance(node, ast.Attribute):
        inner = dotted(node.value)
        return None if inner is None else '%s.%s' % (inner, node.attr)
    return None


def _first_string(call, keyword=None):
    args = list(call.args[:1]) + [k.value for k in call.keywords if keyword and k.arg == keyword]
    for arg in args:
        if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
            return arg.value
    return None


def parsed(package_dir):
    """Every Python file of the package, parsed (:class:`Parsed`)."""
    return [Parsed(p, package_dir) for p in python_files(package_dir)]


def unparsed(package_dir):
    """One note per Python file that does not parse: its facts were read from its text."""
    return ['%s does not parse as Python 3 (%s): what it does was read from its text, comments dropped'
            % (f.rel, f.error) for f in parsed(package_dir) if f.tree is None]


def _starts_node(f):
    return bool(f.calls('init_node')) if f.tree is not None else bool(_INIT_NODE.search(f.code))


def node_scripts(package_dir):
    """Scripts that start a ROS node (call ``init_node``), the likely exam node first."""
    scripts = [f.path for f in parsed(package_dir) if _starts_node(f)]
    return sorted(scripts, key=lambda p: ('exam' not in os.path.basename(p), len(p), p))


def dependencies(package_dir):
    """Names of every package that package.xml depends on, in any way."""
    try:
        root = ET.parse(os.path.join(package_dir, 'package.xml')).getroot()
    except (ET.ParseError, OSError):
        return []
    return sorted(set((e.text or '').strip() for e in root if e.tag.endswith('depend')))


def sheets_in_code(package_dir):
    """Sheets whose input topic names are strings of the package's Python code."""
    strings = []
    for f in parsed(package_dir):
        strings.extend(f.strings() if f.tree is not None else re.findall(r'[\'"]([^\'"\n]*)[\'"]', f.code))
    return [name for name, sheet in SHEETS.items()
            if all(any(s.strip('/').split('/')[-1] == topic for s in strings) for topic in sheet.inputs)]


def param_names(package_dir):
    """Parameter names the code reads (``get_param('~x')``, ``search_param``, ``has_param``...)."""
    names = set()
    for f in parsed(package_dir):
        if f.tree is None:
            names.update(_GET_PARAM.findall(f.code))
            continue
        for call in f.calls(*PARAM_READERS):
            name = _first_string(call, 'param_name')
            if name:
                names.add(name)
    return sorted(names)


def _scope_calls(scope):
    """The calls of one scope (a module or a function), not those of the functions and classes it defines."""
    todo = list(ast.iter_child_nodes(scope))
    while todo:
        node = todo.pop()
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef, ast.Lambda)):
            continue
        if isinstance(node, ast.Call):
            yield node
        todo.extend(ast.iter_child_nodes(node))


def private_before_init(package_dir):
    """Private parameters (``~name``) the code reads before it starts its node, ``"file:line: ~name"``:
    in the function that calls ``init_node``, above that call, or in the module's own body (run on
    import, before ``main()``). Until ``init_node`` rospy's caller id is ``<ns>/unnamed``
    (``rospy/names.py``), so such a read never sees the node's parameter; relative and global names
    resolve alike before and after."""
    found = []
    for f in parsed(package_dir):
        if f.tree is None or not f.calls('init_node'):
            continue
        scopes = [f.tree] + [n for n in ast.walk(f.tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
        for scope in scopes:
            calls = list(_scope_calls(scope))
            inits = [c.lineno for c in calls if call_name(c) == 'init_node']
            if not inits and scope is not f.tree:
                continue
            first = min(inits) if inits else float('inf')  # the module's body runs before any function's init
            for call in calls:
                name = _first_string(call, 'param_name') if call_name(call) in PARAM_READERS else None
                if name and name.startswith('~') and call.lineno < first:
                    found.append('%s: %s' % (f.where(call), name))
    return sorted(set(found), key=lambda w: (w.split(':')[0], int(w.split(':')[1])))


def _argv_sources(tree):
    """Names bound to the node's arguments (``argv = rospy.myargv()``, ``args = sys.argv``)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and _is_argv(node.value, ()):
            names.update(dotted(t) for t in node.targets if dotted(t))
    return names


def _is_argv(node, names):
    if isinstance(node, ast.Call) and call_name(node) == 'myargv':
        return True
    return dotted(node) in ('sys.argv',) + tuple(names)


def args_read(package_dir):
    """What the code reads of its command line (a launch file's ``args=``): argparse's options and
    positional names (``--threshold``, ``threshold``), and ``argv[N]`` for an index into
    ``rospy.myargv()`` or ``sys.argv`` (or a name bound to either)."""
    found = set()
    for f in parsed(package_dir):
        if f.tree is None:
            continue
        for call in f.calls('add_argument'):
            for arg in call.args:
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    found.add(arg.value)
        names = _argv_sources(f.tree)
        for node in ast.walk(f.tree):
            if isinstance(node, ast.Subscript) and _is_argv(node.value, names):
                index = getattr(node.slice, 'value', None) if type(node.slice).__name__ == 'Index' else node.slice
                if isinstance(index, ast.Constant) and isinstance(index.value, int):
                    found.add('argv[%d]' % index.value)
    return sorted(found)


def calls_a_service(package_dir):
    """True when the code makes a service client (``ServiceProxy``, ``wait_for_service``)."""
    return any(f.calls(*SERVICE_CLIENTS) if f.tree is not None else _SERVICE_CLIENT.search(f.code)
               for f in parsed(package_dir))


def code_evidence(package_dir):
    """Where the code does what the rules need, as ``file:line`` (for a rule the run could not see):
    ``service_calls`` (a call of a ``ServiceProxy`` it made, or of one made on the spot),
    ``publishes`` (``.publish(...)``), ``timers`` (``rospy.Timer``, ``rospy.Rate``). Read from the
    syntax tree only: a file that does not parse gives none (:func:`unparsed` says so)."""
    out = {'service_calls': [], 'publishes': [], 'timers': []}
    for f in parsed(package_dir):
        if f.tree is None:
            continue
        proxies = set()
        for node in ast.walk(f.tree):
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) \
                    and call_name(node.value) == 'ServiceProxy':
                proxies.update(dotted(t) for t in node.targets if dotted(t))
        for node in ast.walk(f.tree):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            target = dotted(func.value) if isinstance(func, ast.Attribute) and func.attr == 'call' else dotted(func)
            if target in proxies or (isinstance(func, ast.Call) and call_name(func) == 'ServiceProxy'):
                out['service_calls'].append(f.where(node))
            elif call_name(node) == 'publish':
                out['publishes'].append(f.where(node))
            elif call_name(node) in ('Timer', 'Rate'):
                out['timers'].append(f.where(node))
    for key in out:
        out[key] = sorted(set(out[key]), key=lambda w: (w.rsplit(':', 1)[0], int(w.rsplit(':', 1)[1])))
    return out


def comment_ratio(paths):
    """``(comment lines, code lines)`` of Python files: a line holding a comment or a docstring line
    counts as commented; code lines are the non-blank lines that are not only comment."""
    comments = code = 0
    for path in paths:
        text = _read(path)
        commented, only_comment = set(), set()
        try:
            tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
        except (tokenize.TokenError, IndentationError, SyntaxError):
            continue
        previous = tokenize.NEWLINE
        for tok in tokens:
            if tok.type == tokenize.COMMENT:
                commented.add(tok.start[0])
                if tok.line.strip().startswith('#'):
                    only_comment.add(tok.start[0])
            elif tok.type == tokenize.STRING and previous in (tokenize.NEWLINE, tokenize.INDENT,
                                                              tokenize.DEDENT, tokenize.NL):
                lines = range(tok.start[0], tok.end[0] + 1)  # a docstring or a bare string
                commented.update(lines)
                only_comment.update(lines)
            if tok.type not in (tokenize.NL, tokenize.COMMENT):
                previous = tok.type
        lines = [n for n, line in enumerate(text.splitlines(), 1) if line.strip()]
        comments += len([n for n in lines if n in commented and not _is_shebang(text, n)])
        code += len([n for n in lines if n not in only_comment])
    return comments, code


def _is_shebang(text, number):
    return number == 1 and text.startswith('#!')


def fix_text(package_dir):
    """What a teacher does first with files edited on Windows: CRLF line endings to LF (a shebang
    ``python3\\r`` is no command) and no UTF-8 byte order mark (it hides ``#!``). Returns one note per
    kind of fix, naming the files."""
    crlf, bom = [], []
    for dirpath, dirnames, filenames in os.walk(package_dir):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith('.'))
        for filename in sorted(filenames):
            full = os.path.join(dirpath, filename)
            if os.path.islink(full) or not os.path.isfile(full):
                continue
            if not (filename.endswith(TEXT_ENDINGS) or filename == 'CMakeLists.txt' or '.' not in filename):
                continue
            with open(full, 'rb') as f:
                data = f.read()
            if b'\0' in data:
                continue  # not text
            fixed = data
            rel = os.path.relpath(full, package_dir)
            if fixed.startswith(_BOM):
                fixed = fixed[len(_BOM):]
                bom.append(rel)
            if b'\r' in fixed:
                fixed = fixed.replace(b'\r\n', b'\n').replace(b'\r', b'\n')
                crlf.append(rel)
            if fixed != data:
                with open(full, 'wb') as f:
                    f.write(fixed)
    notes = []
    if crlf:
        notes.append('Windows line endings (CRLF) changed to LF, as dos2unix does, in %d file(s): %s'
                     % (len(crlf), ', '.join(crlf)))
    if bom:
        notes.append('UTF-8 byte order mark removed from %d file(s): %s' % (len(bom), ', '.join(bom)))
    return notes


def python2_evidence(package_dir):
    """Where the student's code is Python 2 (``"scripts/n.py:12: print statement"``): files that
    Python 3 cannot compile, at a line that Python 2 would accept. Never runs anything."""
    found = []
    for path in student_code(package_dir):
        text = _read(path)
        rel = os.path.relpath(path, package_dir)
        try:
            compile(text, rel, 'exec', dont_inherit=True)
            continue
        except SyntaxError as err:
            error_line = err.lineno
        except (ValueError, RecursionError, MemoryError, OverflowError):  # null bytes, absurd nesting
            continue
        lines = text.splitlines()
        hits = []
        for number, line in enumerate(lines, 1):
            words = next((w for pattern, w in _PYTHON2 if pattern.search(line)), None)
            # Operators and literals only where Python 3 stopped: elsewhere they may sit in a string.
            if words and (number == error_line or words.endswith('statement') or words.startswith('"')):
                hits.append((number != error_line, number, words))
        if hits:
            _, number, words = min(hits)  # the line Python 3 stopped at, if it is one of them
            found.append('%s:%d: %s' % (rel, number, words))
    return found


def make_runnable(package_dir, launched=()):
    """What a teacher does before running a student's package: make the scripts executable (the sheet
    asks students to), point a ``python`` shebang to ``python3`` when this machine has no ``python``,
    give the launched scripts (basenames in ``launched``) a shebang if they have none.
    Returns a note for each fix."""
    notes = []
    has_python = shutil.which('python', path='/usr/local/bin:/usr/bin:/bin') is not None
    for path in python_files(package_dir):
        rel = os.path.relpath(path, package_dir)
        line = _shebang(path)
        if not line and os.path.basename(path) in launched:
            text = _read(path)
            with open(path, 'w') as f:
                f.write('#!/usr/bin/env python3\n' + text)
            line = '#!/usr/bin/env python3'
            notes.append('%s: no shebang line; "%s" added so it can run (line numbers +1)' % (rel, line))
        if re.match(r'#!\s*(/usr/bin/env\s+|/usr/bin/)python\s*$', line) and not has_python:
            text = _read(path)
            with open(path, 'w') as f:
                f.write('#!/usr/bin/env python3' + text[len(text.split('\n', 1)[0]):])
            notes.append('%s: shebang "%s" changed to python3 (no python 2 here)' % (rel, line))
        mode = os.stat(path).st_mode
        if line and not mode & stat.S_IXUSR:
            os.chmod(path, mode | stat.S_IXUSR | stat.S_IXGRP | stat.S_IXOTH)
            notes.append('%s was not executable: made executable (chmod +x), as the sheet asks' % rel)
    return notes


def node_type_fixes(package_dir, nodes):
    """What a teacher changes in the launch file before running it: a node whose ``type`` names no
    file of the package while ``<type>.py`` is one of its scripts (``type="exam_node"`` beside
    ``scripts/exam_node.py``) is run as ``<type>.py``. The student's file is left as handed in
    (question 12 is judged on it).

    :param nodes: the launched :class:`~exam_lab.grader.boxed.launch.Node` s of the package.
    :returns: ``({node.type_origin: fixed type}, [a note for each fix])``, the changes for
        :func:`~exam_lab.grader.boxed.derive.derive`.
    """
    names = set()
    for dirpath, dirnames, filenames in os.walk(package_dir):
        dirnames[:] = [d for d in dirnames if not d.startswith('.')]
        names.update(filenames)
    scripts = dict((os.path.basename(p), os.path.relpath(p, package_dir)) for p in python_files(package_dir))
    changes, notes = {}, []
    for node in nodes:
        meant = (node.type or '') + '.py'
        if node.type and node.type not in names and meant in scripts and node.type_origin not in changes:
            changes[node.type_origin] = meant
            notes.append('the launch file starts type="%s", which is no file of the package: run as "%s" (%s), '
                         'as a teacher would fix it' % (node.type, meant, scripts[meant]))
    return changes, notes


def student_code(package_dir):
    """The Python files a teacher reads for comments and quality: not setup.py, not tests."""
    return [p for p in python_files(package_dir) if os.path.basename(p) != 'setup.py'
            and not any(part in ('test', 'tests') for part in os.path.relpath(p, package_dir).split(os.sep))]


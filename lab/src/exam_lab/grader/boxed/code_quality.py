"""How well the student's code is commented, function by function and block by block, and the signs
of bad practice a teacher looks for (pyflakes, a service called on every pass, a busy wait, a blocking
call in a callback, a global read nowhere), each with its file and line: what the comments and
quality proposals (:mod:`exam_lab.grader.score.answers`) rest on. Run in the inspection's box, on the
student's bytes (:mod:`~exam_lab.grader.boxed.inspect`); read from the syntax tree, nothing of the code
runs. No rospy here.
"""
import ast
import io
import tokenize

from exam_lab.grader.boxed.source import Parsed, call_name, dotted


#: Compound statements whose comments the teacher reads block by block.
_BLOCKS = (ast.If, ast.For, ast.While, ast.With, ast.Try)
#: Calls that block the thread they run on: in a subscriber's or a timer's callback they hold up
#: every later message of that topic.
BLOCKING = ('sleep', 'wait_for_service', 'wait_for_message', 'input', 'spin', 'join')
#: Calls that let a loop wait without using a core (what a loop on rospy.is_shutdown() needs).
_WAITS = ('sleep', 'spin', 'spin_once', 'wait', 'wait_for_message', 'wait_for_service', 'join', 'get', 'select')
#: Most units and signals kept per package (the record's lists are capped; the inspection cuts them,
#: saying so: :func:`~exam_lab.grader.boxed.bounds.kept`).
MAX_UNITS = 300
MAX_SIGNALS = 100


def _comment_lines(text):
    """``(lines holding a comment, lines of a docstring or a bare string)``, by number; empty sets when
    tokenize cannot read the file."""
    comments, strings = set(), set()
    try:
        tokens = list(tokenize.generate_tokens(io.StringIO(text).readline))
    except (tokenize.TokenError, IndentationError, SyntaxError):
        return comments, strings
    previous = tokenize.NEWLINE
    for tok in tokens:
        if tok.type == tokenize.COMMENT:
            comments.add(tok.start[0])
        elif tok.type == tokenize.STRING and previous in (tokenize.NEWLINE, tokenize.INDENT, tokenize.DEDENT,
                                                          tokenize.NL):
            strings.update(range(tok.start[0], tok.end[0] + 1))
        if tok.type not in (tokenize.NL, tokenize.COMMENT):
            previous = tok.type
    return comments, strings


def _comment_above(line, comments, text_lines):
    """Whether a comment sits on ``line`` or on the lines just above it (comment lines only)."""
    if line in comments:
        return True
    above = line - 1
    return above in comments and text_lines[above - 1].strip().startswith('#')


def _main_guard(node):
    """Whether ``node`` is ``if __name__ == '__main__':``, which no note asks to comment."""
    test = getattr(node, 'test', None)
    return isinstance(node, ast.If) and isinstance(test, ast.Compare) and isinstance(test.left, ast.Name) and \
        test.left.id == '__name__'


def comment_units(paths, package_dir):
    """Each function and each block (if/for/while/with/try) of the student's code, commented or not:
    ``[{"file", "line", "kind", "name", "commented"}]``. A function is commented when it has a
    docstring, a comment just above its ``def`` or one in its body; a block when a comment is on its
    first line, just above it, or before or on the first statement of its body (``if __name__ ==
    '__main__':`` is no block to comment). What the notes call "commenté
    partout" is then every unit commented, not a share of lines: ten comments on the imports and none
    in the callbacks is not a commented node."""
    units = []
    for path in paths:
        f = Parsed(path, package_dir)
        if f.tree is None:
            continue
        comments, strings = _comment_lines(f.text)
        text_lines = f.text.splitlines()
        for node in ast.walk(f.tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                end = getattr(node, 'end_lineno', None) or node.body[-1].lineno
                inside = any(n in comments for n in range(node.lineno, end + 1))
                commented = bool(ast.get_docstring(node)) or inside or _comment_above(node.lineno, comments, text_lines)
                units.append({'file': f.rel, 'line': node.lineno, 'kind': 'function', 'name': node.name,
                              'commented': commented})
            elif isinstance(node, _BLOCKS) and not _main_guard(node):
                first_body = node.body[0].lineno if node.body else node.lineno
                # a comment on its line, just above it, or from its line to its body's first statement
                commented = _comment_above(node.lineno, comments, text_lines) or first_body in strings or \
                    any(n in comments for n in range(node.lineno, first_body + 1))
                units.append({'file': f.rel, 'line': node.lineno, 'kind': type(node).__name__.lower(),
                              'name': '', 'commented': commented})
    units.sort(key=lambda u: (u['file'], u['line']))
    return units


def _callbacks(tree):
    """Names of the functions given to a Subscriber or a Timer as their callback (``cb`` and
    ``self.cb`` alike, by the last part of the name)."""
    names = set()
    for call in (n for n in ast.walk(tree) if isinstance(n, ast.Call)):
        name = call_name(call)
        index = {'Subscriber': 2, 'Timer': 1}.get(name)
        if index is None:
            continue
        args = list(call.args[index:index + 1]) + [k.value for k in call.keywords if k.arg == 'callback']
        for arg in args:
            target = dotted(arg)
            if target:
                names.add(target.split('.')[-1])
    return names


def _proxies(tree):
    """Names (last part: ``srv`` of ``self.srv``) assigned a ``ServiceProxy``."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) and call_name(node.value) == 'ServiceProxy':
            for target in node.targets:
                name = dotted(target)
                if name:
                    names.add(name.split('.')[-1])
    return names


def _every_pass(body, proxies):
    """The calls of a service proxy (by name, ``proxies``) that ``body`` makes every time it runs:
    not under an ``if`` unless both its branches call one, never under a ``try`` or a nested function."""
    calls = []
    for statement in body:
        if isinstance(statement, ast.If):
            then, other = _every_pass(statement.body, proxies), _every_pass(statement.orelse, proxies)
            if then and other:
                calls += then + other
        elif isinstance(statement, ast.With):
            calls += _every_pass(statement.body, proxies)
        elif not isinstance(statement, (ast.Try, ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            calls += [n for n in ast.walk(statement) if isinstance(n, ast.Call)
                      and (dotted(n.func) or '').split('.')[-1] in proxies]
    return calls


def _every_time(body, proxies):
    """:func:`_every_pass`'s calls of ``body``, and those of each ``if``/``else`` within it whose both
    branches call a proxy (whatever encloses it: ``if data ready: ... if high: warn() else: normal()``
    calls at every pass where data is ready)."""
    calls = _every_pass(body, proxies)
    for statement in body:
        for node in ast.walk(statement):
            if isinstance(node, ast.If) and node.orelse:
                calls += _every_pass([node], proxies)
    unique = {id(c): c for c in calls}
    return sorted(unique.values(), key=lambda c: (c.lineno, c.col_offset))


def _calls_in(statements):
    for statement in statements:
        for node in ast.walk(statement):
            if isinstance(node, ast.Call):
                yield node


def _pyflakes(f):
    """pyflakes' messages of one parsed file: ``[(line, message)]``; None when pyflakes is missing."""
    try:
        from pyflakes import checker
    except ImportError:
        return None
    found = checker.Checker(f.tree, filename=f.rel)
    return sorted((m.lineno, m.message % m.message_args) for m in found.messages)


def quality_signals(paths, package_dir):
    """What a teacher reads as bad practice in the student's code, each with its file and line:
    ``[{"file", "line", "kind", "detail"}]``, kinds ``pyflakes`` (its message), ``service in a loop``
    (a service proxy called on every pass of a loop or in every message's callback, instead of on a
    crossing), ``busy wait`` (a ``while`` that waits without sleeping), ``blocking call in a callback``
    (a sleep or a wait in a subscriber's or timer's callback), ``global without need`` (a ``global``
    written and read nowhere). Read from the syntax tree only: nothing of the code runs."""
    signals, missing = [], False
    for path in paths:
        f = Parsed(path, package_dir)
        if f.tree is None:
            continue
        flakes = _pyflakes(f)
        missing = missing or flakes is None
        for line, message in flakes or []:
            signals.append({'file': f.rel, 'line': line, 'kind': 'pyflakes', 'detail': message})
        callbacks, proxies = _callbacks(f.tree), _proxies(f.tree)
        functions = [n for n in ast.walk(f.tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]
        for loop in (n for n in ast.walk(f.tree) if isinstance(n, (ast.While, ast.For))):
            for call in _every_time(loop.body, proxies):
                signals.append({'file': f.rel, 'line': call.lineno, 'kind': 'service in a loop',
                                'detail': '%s() is called on every pass of the loop of line %d, not only on a '
                                          'crossing' % ((dotted(call.func) or '?').split('.')[-1], loop.lineno)})
        for function in functions:
            if function.name not in callbacks:
                continue
            for call in _calls_in(function.body):
                name = (dotted(call.func) or '').split('.')[-1]
                if call_name(call) in BLOCKING:
                    signals.append({'file': f.rel, 'line': call.lineno, 'kind': 'blocking call in a callback',
                                    'detail': '%s() in the callback %s() holds up the messages that follow'
                                              % (call_name(call), function.name)})
            for call in _every_time(function.body, proxies):
                signals.append({'file': f.rel, 'line': call.lineno, 'kind': 'service in a loop',
                                'detail': '%s() is called at every call of the callback %s(), not only on a '
                                          'crossing' % ((dotted(call.func) or '?').split('.')[-1], function.name)})
        for loop in (n for n in ast.walk(f.tree) if isinstance(n, ast.While)):
            test = ast.dump(loop.test)
            waits = [c for c in _calls_in(loop.body) if call_name(c) in _WAITS]
            idle = all(isinstance(s, (ast.Pass, ast.Continue)) for s in loop.body)
            if not waits and (idle or 'is_shutdown' in test or (isinstance(loop.test, ast.Constant) and loop.test.value)):
                signals.append({'file': f.rel, 'line': loop.lineno, 'kind': 'busy wait',
                                'detail': 'this while loop waits without sleeping (no rate.sleep(), rospy.sleep() '
                                          'or spin()): it keeps a core busy'})
        # a value read somewhere (another function, the module's loop, this one's next call); ``x += 1``
        # alone only writes it: a counter nothing compares is no state anyone needs
        read = {n.id for n in ast.walk(f.tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
        for function in functions:
            for statement in (n for n in ast.walk(function) if isinstance(n, ast.Global)):
                for name in statement.names:
                    if name not in read:
                        signals.append({'file': f.rel, 'line': statement.lineno, 'kind': 'global without need',
                                        'detail': 'global %s in %s() is written, and read nowhere: nothing '
                                                  'needs it shared' % (name, function.name)})
    signals.sort(key=lambda s: (s['file'], s['line'], s['kind']))
    if missing:
        signals.insert(0, {'file': '', 'line': 0, 'kind': 'note',
                           'detail': 'pyflakes is not installed (tools/install_deps.sh installs python3-pyflakes)'})
    return signals

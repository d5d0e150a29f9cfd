"""The repairs that let the grader read and run a launch file roslaunch refuses for its form alone
(issue 45: one mistake, one loss): its elements not inside one ``<launch>`` root, a ``<node>`` without
its name. The file as handed in keeps roslaunch's verdict (question 12's loss); what it starts and
sets is read as written (:mod:`~exam_lab.grader.boxed.launch`) and run from the repaired tree
(:mod:`~exam_lab.grader.boxed.derive`). Each repair is a sentence of the analysis's ``repairs``, a fix
the status names. A file that is not XML even inside a ``<launch>`` is not repaired: its problem says why.
"""
import os
import re
import xml.etree.ElementTree as ET


#: The repairs the grader makes to read and run a launch file roslaunch refuses, each a mistake of
#: the file's form whose meaning is plain: what it starts and sets is judged as written (issue 45).
REPAIRS = {
    'root': '%s: roslaunch refuses it (no root <launch> tag: %s); the grader read and ran its elements '
            'inside a <launch>',
    'name': '%s: roslaunch refuses <node pkg="%s" type="%s"> without a name (required in ROS 1, optional in '
            'ROS 2); the grader read and ran it named "%s", after its executable',
}


#: The elements a launch file holds: a root of one of these is the file's one element, any other
#: root (``<roslaunch>``, ``<launch_file>``) a wrong name for ``<launch>``.
_LAUNCH_TAGS = ('arg', 'env', 'group', 'include', 'machine', 'node', 'param', 'remap', 'rosparam', 'test')


def rooted(element):
    """A tree whose root is a ``<launch>`` holding what ``element`` meant: itself when it is a launch
    file's element, else its children (a ``<launch>`` inside them opened too): the file as roslaunch
    would read it had it been written inside one."""
    launch_root = ET.Element('launch')
    for child in ([element] if element.tag in _LAUNCH_TAGS else list(element)):
        if isinstance(child.tag, str) and child.tag == 'launch':
            launch_root.extend(list(child))
        else:
            launch_root.append(child)
    return ET.ElementTree(launch_root)


_PROLOG = re.compile(br'^\s*(<\?xml[^>]*\?>)?\s*(<!DOCTYPE[^>]*>)?')


def read(path, where, problems, repairs):
    """The tree of the launch file ``path`` (``where`` in the package) as the grader reads it: rooted
    in ``<launch>``, the repair said in ``repairs``; None, with the problem said, when it is not XML."""
    try:
        tree = ET.parse(path)
    except ET.ParseError as err:
        tree = without_root(path)
        if tree is None:
            problems.append('%s is not valid XML: %s' % (where, err))
        else:
            repairs.append(REPAIRS['root'] % (where, 'its elements are not inside one <launch>'))
        return tree
    except OSError as err:
        problems.append('%s is not valid XML: %s' % (where, err))
        return None
    if tree.getroot().tag != 'launch':
        repairs.append(REPAIRS['root'] % (where, 'its root element is <%s>' % tree.getroot().tag))
        return rooted(tree.getroot())
    return tree


def without_root(path):
    """The tree of a file that is XML but for its root (elements side by side at the top, text
    around them), read inside a ``<launch>``; None when it is not even that."""
    try:
        with open(path, 'rb') as f:
            text = f.read()
        return rooted(ET.fromstring(b'<launch>' + _PROLOG.sub(b'', text, count=1) + b'</launch>'))
    except (ET.ParseError, OSError, ValueError):
        return None


def name_node(analysis, element, scope):
    """Name a ``<node>`` written without its name (roslaunch requires one) after its executable, in
    the tree the grader runs, and say so (:data:`REPAIRS`)."""
    node_type = scope.substitute(element.get('type'))[0] or ''
    name = re.sub(r'\W', '_', re.sub(r'\.py$', '', os.path.basename(node_type))) or 'node'
    element.set('name', name)
    analysis.repairs.append(REPAIRS['name'] % (os.path.relpath(scope.path, analysis.package_dir),
                                               element.get('pkg'), node_type, name))

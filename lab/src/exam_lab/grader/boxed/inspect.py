"""Read one submission, as its box's uid: the only place the upload's bytes are opened before the build.

The runner starts it in the submission's box (:meth:`exam_lab.grader.host.sandbox.Box.run`), without
network, with a wall-clock, CPU and memory bound::

    python3 -m exam_lab.grader.boxed.inspect --upload U --ws /box/ws --out /box/out [--sheet S] [--toplevel T]

It unpacks the upload (:mod:`~exam_lab.grader.boxed.package`, scratch under ``OUT``), copies the package
into ``WS/src/<name>``, makes the teacher's fixes (:mod:`~exam_lab.grader.boxed.source`), analyses the
launch files and writes the derived ones (:mod:`~exam_lab.grader.boxed.launch`), reads the PDF facts
(:mod:`~exam_lab.grader.boxed.documents`) and the comment statistics, and writes ``OUT/inspect.json``:
one :class:`~exam_lab.grader.score.inspection.InspectRecord`, which root checks before using anything of it.

``WS`` is the workspace at the path the build and run box sees it (``/box/ws``), so every path written
into a derived launch file is valid there. ``T`` (catkin's toplevel.cmake) is linked as
``WS/src/CMakeLists.txt``. An upload that cannot be opened safely is a record with ``refused``; any
other failure exits non-zero with its traceback on stderr (the runner keeps a capped copy).
"""
import argparse
import os
import random
import re
import sys

from exam_lab.grader.boxed import archives, bounds, code_quality, derive, documents, launch, package, source
from exam_lab.grader.score import boxenv, records
from exam_lab.grader.score.inspection import InspectRecord
from exam_lab.grader.score.sheets import PACKAGE, SHEETS, threshold_run_value


#: The package's source as handed in (before the teacher's fixes), copied below ``OUT``: root keeps it
#: for the teacher as ``code/`` of the student's folder (:func:`exam_lab.grader.host.reports.keep_code`).
#: Notes of one kind, one a file (a file that does not parse, a launch file's problem), named at most:
#: a package of hundreds of such files must leave room in the record's notes for the others.
NOTES_OF_A_KIND = 50


def detect_sheet(wanted, package_dir, analyses):
    """``(sheet, how it was chosen)``: given, else from package.xml, else the launch files, else the
    topics the code names; altitude when nothing decides."""
    if wanted:
        return wanted, 'sheet %s given' % wanted
    deps = [d for d in source.dependencies(package_dir) if d in (s.drone_pkg for s in SHEETS.values())]
    by_deps = [name for name, s in SHEETS.items() if s.drone_pkg in deps]
    if len(by_deps) == 1:
        return by_deps[0], 'sheet %s: package.xml depends on %s' % (by_deps[0], SHEETS[by_deps[0]].drone_pkg)
    by_launch = sorted(set(s for a in analyses for s in a.drone_sheets()))
    if len(by_launch) == 1:
        return by_launch[0], 'sheet %s: the launch files start %s' % (by_launch[0], SHEETS[by_launch[0]].drone_pkg)
    by_code = source.sheets_in_code(package_dir)
    if len(by_code) == 1:
        return by_code[0], 'sheet %s: the code names its topics' % by_code[0]
    return 'altitude', ('sheet altitude by default: the package could be either (depends on %s); '
                        'give SHEET=depth to grade the other' % (', '.join(deps) or 'neither drone'))


def _executable_in(pkg, name):
    for dirpath, _, filenames in os.walk(pkg):
        if name in filenames and os.access(os.path.join(dirpath, name), os.X_OK):
            return True
    return False


def inspect(upload, ws, out, wanted_sheet=None, draw=None):
    """The record (a dict, :class:`~exam_lab.grader.score.inspection.InspectRecord`'s fields) of the
    submission ``upload``; its package is written to ``ws/src/<name>``, scratch goes below ``out``.

    :param draw: in [0, 1), drawn by the grader at grading time: where the threshold run's value lies
        in its range (:func:`~exam_lab.grader.score.sheets.threshold_run_value`); drawn here if None.
    """
    notes, fixes, capped = [], [], []  # capped: the sentences of caps, never left out of the notes
    draw = random.SystemRandom().random() if draw is None else draw
    record = {'uid': os.getuid(), 'refused': None, 'sheet': wanted_sheet or 'altitude', 'notes': notes,
              'fixes': fixes, 'static': None, 'threshold_value': SHEETS[wanted_sheet or 'altitude'].threshold,
              'calls_service': False, 'namespace': '/', 'main_launch': None, 'threshold_launch': None,
              'threshold_run_value': None, 'handed_in_launch': None,
              'comments': None, 'facts': documents.submission_facts(upload, capped)}
    uploads = []
    try:
        pkg_source = package.open_submission(upload, os.path.join(out, 'unpacked'), notes, fixes, uploads=uploads)
    except archives.UnpackError as err:
        record['refused'] = str(err)
        notes.extend(capped)
        return record
    package.copy_package(pkg_source, os.path.join(out, boxenv.CODE_COPY), [])  # as handed in, for the teacher (code/)
    name = package.package_name(os.path.join(pkg_source, 'package.xml')) or PACKAGE
    pkg = os.path.join(ws, 'src', name if re.match(r'^[A-Za-z][\w-]*$', name) else PACKAGE)
    package.copy_package(pkg_source, pkg, fixes)
    fixes.extend(source.fix_text(pkg))
    box_env = boxenv.box_env({'PATH': '/usr/bin:/bin'})  # what $(env) reads in the run box, nothing of ours
    analyses = [launch.analyse(path, pkg, name, box_env) for path in bounds.kept(
        derive.launch_files(pkg), 'launch files', capped, first=lambda p: os.path.basename(p) == 'exam.launch',
        verb='read', text=None)]
    sheet, how = detect_sheet(wanted_sheet, pkg, analyses)
    notes.insert(0, how)
    chosen = derive.choose(analyses, sheet)
    scripts = source.node_scripts(pkg)
    types, type_fixes = source.node_type_fixes(pkg, chosen.exam_nodes if chosen else [])
    fixes.extend(type_fixes)
    launched = [types.get(n.type_origin, n.type) for n in chosen.exam_nodes] if chosen \
        else [os.path.basename(p) for p in scripts[:1]]
    fixes.extend(source.make_runnable(pkg, launched))
    static = {'launch_files': [os.path.relpath(a.path, pkg) for a in analyses], 'package': name,
              'python2': source.python2_evidence(pkg), 'params_in_code': source.param_names(pkg),
              'args_in_code': source.args_read(pkg),
              'code': dict(source.code_evidence(pkg), private_before_init=source.private_before_init(pkg)),
              'launch': None, 'threshold': None, 'uploads': uploads}
    record.update(sheet=sheet, static=static, threshold_value=SHEETS[sheet].threshold,
                  calls_service=source.calls_a_service(pkg))
    notes.extend(bounds.kept(source.unparsed(pkg), 'Python files that do not parse as Python 3', capped,
                             NOTES_OF_A_KIND, verb='named'))
    if static['python2']:
        notes.append('Python 2 code, which ROS Noetic cannot run: %s' % archives.listed(static['python2']))
    notes.extend(bounds.kept(['launch: %s' % problem for analysis in analyses for problem in analysis.problems],
                             "problems of the launch files", capped, NOTES_OF_A_KIND, verb='named'))
    code = bounds.kept(source.student_code(pkg), 'Python files', capped, verb='read for comments', text=None)
    if code:
        comments, lines = source.comment_ratio(code)
        record['comments'] = {'comments': comments, 'code': lines, 'files': [os.path.relpath(p, pkg) for p in code],
                              'units': bounds.kept(code_quality.comment_units(code, pkg), 'functions and blocks of '
                                                   'the code', capped, code_quality.MAX_UNITS,
                                                   verb='judged for their comments', text=None),
                              'quality': bounds.kept(code_quality.quality_signals(code, pkg), 'signs of bad '
                                                     'practice in the code', capped, code_quality.MAX_SIGNALS,
                                                     verb='listed', text=None)}
    if chosen is not None:
        exam = chosen.exam_nodes[0]
        static['launch'] = {'file': os.path.relpath(chosen.path, pkg), 'starts_drone': chosen.starts_drone(sheet),
                            'exam_type': exam.type, 'exam_name': exam.name, 'package': name,
                            'comments': chosen.comments(), 'exam_type_found': _executable_in(pkg, exam.type),
                            'repairs': chosen.repairs}
        fixes.extend(chosen.repairs)
        param, why = derive.threshold_param(chosen, sheet)
        static['threshold_reason'] = why
        if param is not None:
            value = launch.as_number(param.value)
            if value is not None:
                record['threshold_value'] = value
            static['threshold'] = {'name': param.name, 'value': param.value,
                                   'how': 'args' if isinstance(param, launch.NodeArg) else 'param',
                                   'where': param.origin.describe(pkg) if param.origin else '?'}
            notes.append('threshold parameter: %s, set in %s' % (why, static['threshold']['where']))
        record['main_launch'] = os.path.relpath(derive.derive(chosen, 'main', types), ws)
        record['handed_in_launch'] = os.path.relpath(chosen.path, os.path.join(ws, 'src'))
        record['namespace'] = chosen.drone_namespace(sheet)
        if param is not None and param.origin is not None:
            lowered = threshold_run_value(record['threshold_value'], draw)
            changes = dict(types)
            changes[param.origin] = lowered
            record['threshold_launch'] = os.path.relpath(derive.derive(chosen, 'threshold', changes), ws)
            record['threshold_run_value'] = static['threshold']['run_value'] = lowered
        elif param is not None:
            static['threshold']['not_rewritable'] = 'its value comes from no literal the grader can change'
    else:
        static['threshold_reason'] = 'no launch file starts an exam node, so no parameter'
        unread = _unread_launch(analyses, pkg)
        if unread is not None:
            static['launch_unread'] = static['threshold_reason'] = unread[1]
            record['handed_in_launch'] = os.path.relpath(unread[0], os.path.join(ws, 'src'))
        if scripts:
            notes.append('no launch file starts an exam node: ran %s alone, without parameters'
                         % os.path.relpath(scripts[0], pkg))
            minimal = os.path.join(pkg, '.grader-main-minimal.launch')
            with open(minimal, 'w') as f:
                f.write('<launch><node pkg="%s" type="%s" name="exam" output="screen"/></launch>\n'
                        % (name, os.path.basename(scripts[0])))
            record['main_launch'] = os.path.relpath(minimal, ws)
    _bound_static(static, capped)
    record['notes'] = bounds.closed(notes + capped, keep=capped)
    record['fixes'] = bounds.closed(fixes, 'fixes')
    return record


def _unread_launch(analyses, pkg):
    """``(path, sentence)`` of the first launch file the grader could not read at all (not XML even
    inside a ``<launch>``), when no other starts an exam node: what it starts and sets is then for the
    teacher to read (a hand grade, never a second loss); None when every launch file was read."""
    for analysis in analyses:
        where = os.path.relpath(analysis.path, pkg)
        unread = [p for p in analysis.problems if p.startswith('%s is not valid XML' % where)]
        if unread:
            return analysis.path, ('%s cannot be read, by roslaunch nor by the grader (%s): the nodes it starts and '
                                   'the threshold it sets are not judged by a run; read it by hand'
                                   % (where, unread[0].split(': ', 1)[-1]))
    return None


def _bound_static(static, notes):
    """The lists of ``static`` within their caps (:func:`~exam_lab.grader.boxed.bounds.kept`), the
    items the rubric reads kept first: what names the threshold's parameter or argument. (Its launch
    files were bounded before they were read.)"""
    name = ((static.get('threshold') or {}).get('name') or '').split('/')[-1]

    def reads(item):  # '~threshold', '--threshold' and 'scripts/n.py:3: ~threshold' alike: its name's last part
        return bool(name) and item.rsplit(': ', 1)[-1].strip('~/-').split('/')[-1] == name.strip('-')
    static['python2'] = bounds.kept(static['python2'], 'files of Python 2', notes)
    for key, what in (('params_in_code', 'parameter names the code reads'), ('args_in_code', 'arguments the code reads')):
        static[key] = bounds.kept(static[key], what, notes, first=reads)
    for key, what in (('service_calls', 'service calls in the code'), ('publishes', 'publish calls in the code'),
                      ('timers', 'timers in the code'), ('private_before_init', 'private parameters read before init_node')):
        static['code'][key] = bounds.kept(static['code'][key], what, notes, first=reads)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--upload', required=True)
    parser.add_argument('--ws', required=True, help='the workspace, at the path the run box sees it')
    parser.add_argument('--out', required=True)
    parser.add_argument('--sheet', choices=sorted(SHEETS))
    parser.add_argument('--toplevel', help="catkin's toplevel.cmake, linked as WS/src/CMakeLists.txt")
    parser.add_argument('--draw', type=float, help='in [0, 1): where the threshold run\'s value lies in its range')
    args = parser.parse_args(argv)
    if os.getuid() == 0:
        sys.stderr.write('inspect: refusing to read a student\'s upload as root\n')
        return 2
    os.makedirs(os.path.join(args.ws, 'src'), exist_ok=True)
    if args.toplevel:
        os.symlink(args.toplevel, os.path.join(args.ws, 'src', 'CMakeLists.txt'))
    try:
        record = inspect(args.upload, args.ws, args.out, args.sheet, args.draw)
        records.write(args.out, InspectRecord, bounds.fit(record, InspectRecord))
    except records.RecordError as err:  # a sentence for the teacher, not a traceback
        sys.stderr.write('inspect: its record exceeds a bound: %s\n' % err)
        return 4
    return 0


if __name__ == '__main__':
    sys.exit(main())

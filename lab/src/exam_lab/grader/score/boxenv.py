"""What a box's processes see of the paths and the environment: the contract between root, which makes
the box (:mod:`~exam_lab.grader.host.sandbox`), and the inspection, which reads the student's launch
files as the box's uid ahead of the run (a ``$(env HOME)`` there is the box's:
:mod:`~exam_lab.grader.boxed.inspect`). Pure: no rospy, no I/O.
"""

#: Where the box sees its workspace, and its private HOME.
BOX_WS = '/box/ws'
BOX_HOME = '/box/home'
#: The inspection's copy of the package as handed in (in its box's output), kept by root as OUT's code/.
CODE_COPY = 'code'
#: Variables of a box's environment, besides ROS_* and those a sourced workspace sets.
PASSED = ('PATH', 'LANG', 'LC_ALL', 'PYTHONUNBUFFERED', 'PYTHONDONTWRITEBYTECODE')
#: PATH entries a box keeps (the system's, ROS's, the workspace's): none of the grading user's own.
SYSTEM_PATH = ('/usr/', '/bin', '/sbin', '/opt/ros/', BOX_WS)


def box_env(env, workspace_vars=(), home=BOX_HOME):
    """Only what ROS and the build need from ``env`` (ROS_*, the ``workspace_vars`` a sourced workspace
    sets, PATH, locale), with a fresh HOME and a user name of the box: nothing else of the grading user
    reaches student code."""
    kept = {k: v for k, v in env.items() if k.startswith('ROS') or k in workspace_vars or k in PASSED}
    kept['PATH'] = ':'.join(p for p in kept.get('PATH', '').split(':') if p.startswith(SYSTEM_PATH)) or \
        '/usr/bin:/bin'
    kept.update(HOME=home, USER='student', LOGNAME='student', PYTHONNOUSERSITE='1')
    kept.setdefault('LANG', 'C.UTF-8')
    return kept

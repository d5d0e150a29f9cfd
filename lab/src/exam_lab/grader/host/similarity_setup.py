"""Root's part of the class's similarity check, outside its box: the detector's virtual environment
(copydetect from PyPI, :data:`~exam_lab.grader.score.names.VERSION`, installed on first use into
``$EXAM_WS/similarity-venv``: an installation, of no student's bytes) and the boilerplate every student
got (``catkin_create_pkg``'s files, the launch file's skeletons, the sheets' packages' code), made from
the teacher's installed packages. The comparison itself runs in a box
(:mod:`~exam_lab.grader.boxed.similarity`): root never runs its code.
"""
import os
import shutil
import subprocess
import sys

from exam_lab.grader import workspace
from exam_lab.grader.score.names import CODE_NAMES, CODE_SUFFIXES, VERSION

#: The launch file's skeletons students write from the sheets' question 12 (the drone's node or its
#: launch file, the exam node, the threshold as a parameter or an argument, in the usual orders).
LAUNCH_TEMPLATES = [
    """<launch>
  <node pkg="{drone}" name="{drone}" type="{node}" output="screen"/>
  <node pkg="exam" name="exam" type="exam_node.py" output="screen">
    <param name="threshold" value="{limit}" />
  </node>
</launch>
""",
    """<launch>
  <param name="threshold" value="{limit}" />
  <node pkg="{drone}" name="{drone}" type="{node}" output="screen"/>
  <node pkg="exam" name="exam" type="exam_node.py" output="screen"/>
</launch>
""",
    """<launch>
  <arg name="threshold" default="{limit}" />
  <include file="$(find {drone})/launch/{drone}.launch" />
  <node pkg="exam" type="exam_node.py" name="exam_node" output="screen">
    <param name="threshold" value="$(arg threshold)" />
  </node>
</launch>
""",
]
#: Packages whose code every student had (the sheets' drones).
SHEET_PACKAGES = ('mydrone', 'submarinedrone', 'drone_sim', 'node_kit')


class SimilarityError(Exception):
    """The detector could not be installed."""


def venv_dir():
    """Where the detector's virtual environment is kept (the workspace's, root's)."""
    return os.path.join(workspace(), 'similarity-venv')


def ensure_venv(path=None):
    """The Python of the detector's virtual environment, made (with copydetect VERSION) when missing."""
    path = path or venv_dir()
    python = os.path.join(path, 'bin', 'python')
    probe = [python, '-c', 'import importlib.metadata as m; print(m.version("copydetect"))']
    try:
        if os.path.exists(python) and subprocess.run(probe, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                                     timeout=60).stdout.decode().strip() == VERSION:
            return python
    except (OSError, subprocess.SubprocessError):
        pass
    log = path + '.log'
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(log, 'w') as out:
        for argv in ([sys.executable, '-m', 'venv', '--system-site-packages', '--clear', path],
                     [python, '-m', 'pip', 'install', '-q', 'copydetect==%s' % VERSION]):
            try:
                done = subprocess.run(argv, stdout=out, stderr=subprocess.STDOUT, timeout=600)
            except (OSError, subprocess.SubprocessError) as err:
                raise SimilarityError('%s failed: %s (log: %s)' % (' '.join(argv[:4]), err, log))
            if done.returncode != 0:
                raise SimilarityError('%s failed (exit %d); log: %s' % (' '.join(argv[:4]), done.returncode, log))
    return python


def boilerplate(target):
    """Write what every student got into ``target``; return it."""
    os.makedirs(target, exist_ok=True)
    for drone in ('mydrone', 'submarinedrone'):
        where = os.path.join(target, 'catkin_create_pkg-%s' % drone)
        os.makedirs(where)
        try:
            subprocess.run(['catkin_create_pkg', 'exam', 'rospy', 'std_msgs', drone], cwd=where, timeout=60,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        except (OSError, subprocess.SubprocessError):
            pass  # without catkin_create_pkg, its files count like any other
    for index, template in enumerate(LAUNCH_TEMPLATES):
        for drone, node, limit in (('mydrone', 'mydrone_node.py', 1300), ('submarinedrone', 'submarine_drone_node.py', 150)):
            with open(os.path.join(target, 'template-%d-%s.launch' % (index, drone)), 'w') as f:
                f.write(template.format(drone=drone, node=node, limit=limit))
    import rospkg
    packs = rospkg.RosPack()
    for name in SHEET_PACKAGES:
        try:
            source = packs.get_path(name)
        except rospkg.ResourceNotFound:
            continue
        for relative in _code_files(source):
            if '/test/' in '/' + relative:
                continue
            os.makedirs(os.path.dirname(os.path.join(target, name, relative)), exist_ok=True)
            shutil.copyfile(os.path.join(source, relative), os.path.join(target, name, relative))
    return target


def _code_files(package):
    """The code files of one of the teacher's packages (no link followed), relative to it."""
    found = []
    for dirpath, dirnames, filenames in os.walk(package):
        dirnames[:] = sorted(d for d in dirnames if not d.startswith('.') and d not in ('build', 'devel'))
        found += [os.path.relpath(os.path.join(dirpath, name), package) for name in sorted(filenames)
                  if (name.endswith(CODE_SUFFIXES) or name in CODE_NAMES) and not os.path.islink(os.path.join(dirpath, name))]
    return sorted(found)

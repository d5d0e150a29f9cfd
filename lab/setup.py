from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

GRADER = ['exam_lab.grader'] + ['exam_lab.grader.%s' % sub for sub in ('boxed', 'judge', 'host', 'score', 'publish', 'engine')]
setup(**generate_distutils_setup(packages=['exam_lab', 'exam_lab.harness', 'exam_lab.fairness'] + GRADER, package_dir={'': 'src'}))

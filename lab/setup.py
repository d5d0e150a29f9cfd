from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=['exam_lab', 'exam_lab.harness', 'exam_lab.grader'], package_dir={'': 'src'}))

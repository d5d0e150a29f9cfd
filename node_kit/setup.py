# Installs src/node_kit as a Python package; called by catkin_python_setup(), never run by hand.
from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(packages=['node_kit'], package_dir={'': 'src'}))

#!/usr/bin/env python3
"""EXPERIMENT ONLY: run a rospy node script with numpy made unimportable. Never launched by the product.

Usage: without_numpy.py <script.py> [ROS arguments...]

Every rospy node imports numpy through genpy.message, which uses it only to accept numpy scalars in
float fields and falls back to plain Python types when the import fails. numpy is ~23 MB of the
~47 MB a rospy node occupies (docs/benchmarks.md), so this shows what the RSS goal would take.
"""

import runpy
import sys

# A None entry in sys.modules makes `import numpy` raise ImportError: genpy's fallback path.
sys.modules['numpy'] = None
script = sys.argv[1]
sys.argv = sys.argv[1:]
runpy.run_path(script, run_name='__main__')

#!/usr/bin/env python3
"""Launch N namespaced mydrone + exam pairs: fleet_launch.py N [--threshold M] [--delay S] ..."""
import sys

from exam_lab.fleet import main

if __name__ == '__main__':
    main(sys.argv[1:])

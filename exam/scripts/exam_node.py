#!/usr/bin/env python3
"""Entry point of the exam node; the node itself is exam.node (see its docstring)."""
import sys

try:
    from exam.node import main
except KeyboardInterrupt:  # Ctrl-C while Python still loads rospy: nothing started, nothing to report
    sys.exit(130)

if __name__ == '__main__':
    main()

#!/usr/bin/env python3
"""Entry point of the mydrone node; the code lives in mydrone.simulator."""

import sys

try:
    from mydrone.simulator import main
except KeyboardInterrupt:  # Ctrl-C while Python still loads rospy: nothing started, nothing to report
    sys.exit(130)

if __name__ == '__main__':
    main()

#!/usr/bin/env python3
"""Entry point of the submarine_drone node; the code lives in submarinedrone.simulator."""

import sys

try:
    from submarinedrone.simulator import main
except KeyboardInterrupt:  # Ctrl-C while Python still loads rospy: nothing started, nothing to report
    sys.exit(130)

if __name__ == '__main__':
    main()

#!/usr/bin/env python3
"""Entry point of the submarine_drone node; the code lives in submarinedrone.simulator."""

from submarinedrone.simulator import main

if __name__ == '__main__':
    main()

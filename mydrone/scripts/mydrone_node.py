#!/usr/bin/env python3
"""Entry point of the mydrone node; the code lives in mydrone.simulator."""

from mydrone.simulator import main

if __name__ == '__main__':
    main()

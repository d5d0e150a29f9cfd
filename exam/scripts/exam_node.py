#!/usr/bin/env python3
"""Entry point of the exam node; the node itself is exam.node (see its docstring)."""
from exam.node import main

if __name__ == '__main__':
    main()

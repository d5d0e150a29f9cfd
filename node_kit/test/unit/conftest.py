"""What the unit tests that need rospy share: running a function in a process of its own."""
import multiprocessing

import pytest

#: A bound for a child's run: far beyond its few milliseconds, short of a hung test.
CHILD_TIMEOUT = 60.0


def _in_child(function, *args):
    """``function(*args)`` run in a forked child; its result, or its exception raised here."""
    with multiprocessing.get_context('fork').Pool(1) as pool:
        return pool.apply_async(function, args).get(CHILD_TIMEOUT)


@pytest.fixture
def in_child():
    """rospy's state is global to a process and a shutdown cannot be undone: each test that starts
    one runs it in a forked child."""
    return _in_child

"""node_kit.lifecycle: the node's stop is never held up by its Updater being made (in a forked child)."""
import threading
import time

import rospy

from node_kit import lifecycle

#: A bound for each wait on a thread: far beyond the milliseconds each takes, short of a hung test.
JOIN_TIMEOUT = 10.0


class _UpdaterOfAMasterThatIsDown(object):
    """What making a diagnostic_updater.Updater does while the master is down: rospy retries the
    registration of its /diagnostics publisher until ``rospy.is_shutdown()``."""
    making = threading.Event()

    def __init__(self):
        self.making.set()
        while not rospy.is_shutdown():
            time.sleep(0.01)

    def setHardwareID(self, hwid):
        pass


def _stop_while_the_updater_is_made():
    lifecycle.diagnostic_updater.Updater = _UpdaterOfAMasterThatIsDown
    maker = threading.Thread(target=lifecycle.updater, daemon=True)
    maker.start()
    _UpdaterOfAMasterThatIsDown.making.wait(JOIN_TIMEOUT)
    stopper = threading.Thread(target=lifecycle._stop, daemon=True)
    stopper.start()
    stopper.join(JOIN_TIMEOUT)
    maker.join(JOIN_TIMEOUT)
    return not stopper.is_alive(), not maker.is_alive()


def test_the_stop_ends_while_the_updater_waits_for_a_master_that_is_down(in_child):
    # The stop must raise is_shutdown() itself: until then the Updater waits, and with it whatever
    # lock the Updater is made under (a node built as its master died hung until SIGKILL).
    stopped, made = in_child(_stop_while_the_updater_is_made)
    assert stopped, 'the stop waited for the Updater'
    assert made, 'the Updater still waits for the master after the stop'

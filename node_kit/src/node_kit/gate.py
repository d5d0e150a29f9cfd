"""A gate that a node's callbacks pass through, closed once before rospy tears the node down. No rospy.

Why (issue 19): rospy's shutdown closes every publisher *before* ``rospy.is_shutdown()`` turns true
(:mod:`node_kit.lifecycle` says exactly where), so a timer or a callback that publishes in that
window gets ``ROSException: publish() to a closed topic``, and its thread dies with a traceback. A
guard per call site cannot close the window; ordering can: the gate is closed by the node's first
shutdown hook, which rospy runs before it closes anything, and :meth:`Gate.close` returns only once
the callbacks in progress have left. A callback that comes later is not run at all.
"""
import threading


class Gate(object):
    """Counts the callbacks in progress; once closed, admits no new one.

    Usage: ``if gate.enter(): try: ... finally: gate.leave()``.
    """

    def __init__(self):
        self._cond = threading.Condition()
        self._inside = 0
        self._closed = False

    @property
    def closed(self):
        return self._closed

    def enter(self):
        """Admit one callback: True (call :meth:`leave` when it ends), or False once closed."""
        with self._cond:
            if self._closed:
                return False
            self._inside += 1
            return True

    def leave(self):
        with self._cond:
            self._inside -= 1
            if self._inside == 0:
                self._cond.notify_all()

    def close(self, timeout):
        """Admit nothing more and wait up to ``timeout`` s for the callbacks inside to leave.

        A callback that called close() from inside (a shutdown requested by the node itself) would
        wait for itself: pass ``timeout`` 0 there, or call it from another thread.
        :returns: the number still inside at the end (0: the node is quiet).
        """
        with self._cond:
            self._closed = True
            self._cond.wait_for(lambda: self._inside == 0, timeout)
            return self._inside

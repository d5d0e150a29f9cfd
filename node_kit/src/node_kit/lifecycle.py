"""One shutdown order for every timer, callback and thread of a node: all quiet before rospy closes.

Where rospy leaves a window (``rospy/core.py`` ``signal_shutdown``, python3-rospy 1.15.15 of Debian 12,
the same in Noetic's 1.16), in this order:

1. ``_in_shutdown`` turns true (``rospy.core.is_shutdown_requested()``), then the *client* hooks run:
   those given to ``rospy.on_shutdown``.
2. The *pre-shutdown* hooks run: ``RegManager.cleanup`` (``rospy/impl/registration.py``) unregisters
   the node from the master (one XML-RPC multicall: milliseconds, or a socket error after seconds
   when the master is down), then calls the topic manager's ``close_all()``: every publisher is
   closed.
3. Only then ``_shutdown_flag`` turns true: ``rospy.is_shutdown()``.

Throughout step 2, ``Publisher.publish`` raises ``ROSException("publish() to a closed topic")``
(``rospy/topics.py``: it stays silent on a closed topic only once ``is_shutdown()`` is true), and a
``rospy.Timer`` keeps firing, since its loop tests ``is_shutdown()``. A timer whose callback publishes
then dies with "Exception in thread"; a service handler that publishes (a drone's LED) logs a
traceback. A test of ``is_shutdown()`` at the call site cannot close the window: it is false there.

So everything a node runs by itself goes through this module, and one client hook (step 1) stops it
all before step 2 begins:

- :func:`timer` instead of ``rospy.Timer``; :func:`guarded` for subscriber callbacks and service
  handlers: they pass a :class:`node_kit.gate.Gate`;
- :func:`on_stop` for a node's threads (the warning link, the master link): told to end, in order.

The hook closes the gate (no callback starts any more), waits up to ``DRAIN_TIMEOUT_S`` for those in
progress, shuts the timers down, stops the threads, and only then raises ``is_shutdown()`` itself
(rospy's own loops, such as its registration retries, end on it; see :func:`_stop`). :func:`run` is a
node's whole life (init, build, spin), quiet when it is stopped while it starts.

A node has one ``diagnostic_updater.Updater`` (:func:`updater`): the node adds its statuses, the
master link adds "<node>: master", and one timer publishes them all with ``force_update`` every
``~diagnostic_period`` seconds, read once at start. ``Updater.update`` is not used: it asks the master
for ``~diagnostic_period`` at every update (rospy's ``get_param_cached`` never caches an unset one),
which raises while the master is down; ``force_update`` publishes without asking anybody.

ROS Parameters:
    ~diagnostic_period (float, s, default 1.0, > 0): seconds between two publications of the node's
        statuses on /diagnostics (diagnostic_updater's own parameter).

Published Topics:
    /diagnostics (diagnostic_msgs/DiagnosticArray): the node's statuses, "<node>: master" among them.
"""
import functools
import signal
import sys
import threading

import diagnostic_updater
import rospy

from node_kit import master_link, params, rospy_private
from node_kit.gate import Gate

#: Seconds the shutdown waits for callbacks in progress (a publish, a diagnostics update).
DRAIN_TIMEOUT_S = 2.0

#: Default seconds between two publications of the node's statuses on /diagnostics.
STATUS_PERIOD_S = 1.0

_gate = Gate()
# Re-entrant: rospy runs the shutdown hook from its SIGINT handler, on the main thread, which may be
# inside timer() at that moment (a node stopped while it is built).
_lock = threading.RLock()
_timers = []
_stops = []
_installed = []
# Not _lock: making the Updater registers its publisher with the master, which rospy retries until
# is_shutdown() while the master is down, and _stop takes _lock before it raises that flag (a node
# built as its master died hung until roslaunch's SIGKILL: 3 of 9 runs of test_stops.py).
_updater_lock = threading.Lock()
_updaters = []


def _install():
    """Register the one shutdown hook of this module (once). Call under _lock."""
    if not _installed:
        _installed.append(True)
        rospy.on_shutdown(_stop)


def guarded(callback, refusal=None):
    """``callback`` run only while the node is not stopping, and waited for by the shutdown.

    :param refusal: an exception raised instead of running ``callback`` once the node stops (a
        service handler's ``rospy.ServiceException``: the client gets an error, not a half-done
        request); without it, a late call returns None.
    """
    with _lock:
        _install()

    @functools.wraps(callback)
    def run(*args):
        if not _gate.enter():
            if refusal is not None:
                raise refusal
            return None
        try:
            return callback(*args)
        finally:
            _gate.leave()
    return run


def timer(period, callback, oneshot=False):
    """A ``rospy.Timer`` of ``period`` s whose callback is :func:`guarded`; None once stopping.

    reset=True: the timer survives time jumping backwards (rosbag play --loop under sim time).
    """
    callback = guarded(callback)
    with _lock:
        if _gate.closed:
            return None
        _timers[:] = [t for t in _timers if t.is_alive()]  # one-shot timers that fired are gone
        armed = rospy.Timer(rospy.Duration(period), callback, oneshot=oneshot, reset=True)
        _timers.append(armed)
    return armed


def on_stop(stop):
    """Call ``stop()`` at shutdown, after every callback has ended (in the order given)."""
    with _lock:
        _install()
        _stops.append(stop)


def stopping():
    """True once the shutdown began (the gate is closed)."""
    return _gate.closed


def updater():
    """The node's one ``diagnostic_updater.Updater`` (made at the first call, after ``init_node``):
    add the node's statuses to it; :func:`run` publishes them."""
    with _updater_lock:
        if not _updaters:
            made = diagnostic_updater.Updater()
            made.setHardwareID(rospy.get_name())
            _updaters.append(made)
        return _updaters[0]


def _publish_statuses(statuses):
    """Publish every status of the node on /diagnostics (a timer's callback: never raises)."""
    try:
        statuses.force_update()
    except Exception as err:
        rospy.logerr_throttle(60.0, '/diagnostics: statuses not published: %s: %s'
                              % (type(err).__name__, err))


def _stop():
    """The node's first shutdown hook (step 1): everything of the node ends before rospy closes it."""
    left = _gate.close(DRAIN_TIMEOUT_S)
    with _lock:
        timers, stops = list(_timers), list(_stops)
    for armed in timers:
        armed.shutdown()
    for stop in stops:
        try:
            stop()
        except Exception as err:  # one thread that fails to stop must not keep the others running
            rospy.logwarn('stopping %s: %s: %s' % (getattr(stop, '__qualname__', stop),
                                                   type(err).__name__, err))
    if left:
        rospy.logwarn('%d callbacks still running %.0f s after the shutdown began' % (left,
                                                                                   DRAIN_TIMEOUT_S))
    # The node is quiet: raise rospy's is_shutdown() now, not after step 2. A topic created while
    # the master is away (a node built as its master dies) retries its registration inside the
    # topic manager's lock until is_shutdown(); step 2's close_all() waits for that lock, so with
    # the flag raised only after step 2 the node hung until roslaunch's SIGKILL.
    rospy_private.raise_shutdown_flag()


def _on_signal(signum, frame):
    """Ctrl-C or SIGTERM: rospy's shutdown, on a thread of its own (see :func:`run`)."""
    threading.Thread(target=rospy.signal_shutdown, args=('signal-%d' % signum,), name='shutdown').start()


def run(name, build):
    """A node's life: ``init_node(name)``, ``build()``, the master link, spin; quiet at any stop.

    A node can be stopped at any moment, also while it starts: a Ctrl-C inside ``init_node`` makes
    it raise ROSInitException, one while the node is built can make a call to a master that is gone
    raise. Once the shutdown began, such an error is the stop itself, not a failure: the node just
    ends.

    SIGINT and SIGTERM start rospy's shutdown on a thread of its own, not inside the signal handler
    as rospy's own handler does: the handler runs on the main thread, which may be inside rospy's
    topic manager at that instant (a publisher or subscriber being created registers with the
    master under the manager's lock), and the shutdown's ``close_all`` takes that lock again: the
    node hung until roslaunch's SIGKILL (2 of 16 stops during start-up). On its own thread, the
    shutdown waits for the main thread to leave the lock instead.

    A parameter that is unusable (:class:`node_kit.params.ParamError`), ``~diagnostic_period``
    included, is a fatal log naming the node, and exit status 1.
    """
    with _lock:
        _install()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _on_signal)
    try:
        rospy.init_node(name, disable_signals=True)  # the signals are _on_signal's
        master_link.quiet_master_outages()
        status_period = params.positive_float(rospy.resolve_name('~diagnostic_period'),
                                              rospy.get_param('~diagnostic_period', STATUS_PERIOD_S), 's')
        build()
        statuses = updater()
        link = master_link.start(statuses)
        on_stop(link.stop)
        timer(status_period, lambda event: _publish_statuses(statuses))
    except params.ParamError as err:
        rospy.logfatal('%s: %s', rospy.get_name(), err)
        sys.exit(1)
    except Exception:
        if rospy_private.shutdown_begun():
            return
        raise
    rospy.spin()

"""node_kit.lifecycle: a node's callbacks, timers and threads across its stop, its one Updater, and run()
(each test that touches rospy's state in a forked child; init_node, the master and the clock stood in for)."""
import os
import signal
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


# --- The node's callbacks, timers and threads across its stop (each test in a forked child). ---------
# rospy's shutdown (rospy.signal_shutdown, what rospy and lifecycle.run do at a stop) runs lifecycle's
# hook. A rospy.Timer needs a running clock and init_node a master: each test that arms a timer or runs
# a node gives lifecycle these stand-ins, which record how they were used.


class _Timer(object):
    """A rospy.Timer that never fires by itself: the test calls its callback."""

    def __init__(self, period, callback, oneshot=False, reset=False):
        self.period, self.callback, self.oneshot, self.reset = period.to_sec(), callback, oneshot, reset
        self.shut_down = False

    def shutdown(self):
        self.shut_down = True

    def is_alive(self):
        return not self.shut_down


class _Updater(object):
    """A diagnostic_updater.Updater that counts what it published."""
    made = []

    def __init__(self):
        self.hardware_id, self.published = None, 0
        _Updater.made.append(self)

    def setHardwareID(self, hwid):
        self.hardware_id = hwid

    def force_update(self):
        self.published += 1


def _guarded_before_and_after_the_stop():
    calls = []

    def handler(request):
        """Serve ``request``."""
        calls.append(request)
        return 'served %s' % request
    plain = lifecycle.guarded(handler)
    refusing = lifecycle.guarded(handler, refusal=rospy.ServiceException('the node stops'))
    before = [plain('a'), refusing('b'), lifecycle.stopping()]
    rospy.signal_shutdown('test')
    after = [plain('c'), lifecycle.stopping()]
    try:
        refusing('d')
        after.append('not refused')
    except rospy.ServiceException as err:
        after.append(str(err))
    return before, after, calls, (plain.__name__, plain.__doc__, refusing.__name__)


def test_a_guarded_callback_runs_until_the_stop_then_returns_none_or_raises_its_refusal(in_child):
    before, after, calls, names = in_child(_guarded_before_and_after_the_stop)
    assert before == ['served a', 'served b', False]
    assert after == [None, True, 'the node stops']
    assert calls == ['a', 'b']  # nothing ran after the stop
    # It keeps its callback's name and docstring (what rospy's log of a failing callback shows).
    assert names == ('handler', 'Serve ``request``.', 'handler')


def _stops_at_the_shutdown():
    warnings, ran = [], []
    rospy.logwarn = warnings.append

    def fails_to_stop():
        ran.append('fails')
        raise RuntimeError('cannot stop')
    lifecycle.on_stop(fails_to_stop)
    lifecycle.on_stop(lambda: ran.append('second'))
    lifecycle.guarded(lambda: None)  # installing the hook again must not run the stops twice
    rospy.signal_shutdown('test')
    return ran, warnings


def test_every_thread_is_stopped_once_in_order_even_after_one_that_fails_to_stop(in_child):
    ran, warnings = in_child(_stops_at_the_shutdown)
    assert ran == ['fails', 'second']
    # Nothing was inside the gate: the only warning is the stop that failed.
    assert len(warnings) == 1
    assert warnings[0].startswith('stopping ') and warnings[0].endswith(
        'fails_to_stop: RuntimeError: cannot stop'), warnings


def _stop_with_a_callback_that_does_not_end():
    warnings, ran = [], []
    rospy.logwarn = warnings.append
    inside, release = threading.Event(), threading.Event()

    def stuck():
        inside.set()
        release.wait(JOIN_TIMEOUT)
    worker = threading.Thread(target=lifecycle.guarded(stuck), daemon=True)
    worker.start()
    inside.wait(JOIN_TIMEOUT)
    lifecycle.on_stop(lambda: ran.append('stopped'))
    started = time.monotonic()
    rospy.signal_shutdown('test')
    waited = time.monotonic() - started
    release.set()
    worker.join(JOIN_TIMEOUT)
    return warnings, ran, waited


def test_the_stop_waits_2_s_for_a_callback_that_does_not_end_then_stops_the_rest(in_child):
    # docs/architecture.md: the hook "waits up to 2 s for the callbacks inside".
    warnings, ran, waited = in_child(_stop_with_a_callback_that_does_not_end)
    assert warnings == ['1 callbacks still running 2 s after the shutdown began']
    assert waited >= 2.0
    assert ran == ['stopped']


def _timers_until_the_stop():
    rospy.Timer = _Timer
    ticks = []
    periodic = lifecycle.timer(0.5, ticks.append)
    once = lifecycle.timer(2.0, ticks.append, oneshot=True)
    armed = [(t.period, t.oneshot, t.reset) for t in (periodic, once)]
    periodic.callback('tick')
    rospy.signal_shutdown('test')
    late = periodic.callback('late tick')
    return armed, [t.shut_down for t in (periodic, once)], lifecycle.timer(0.5, ticks.append), late, ticks


def test_timers_are_periodic_by_default_survive_time_going_back_and_end_at_the_stop(in_child):
    armed, shut_down, after, late, ticks = in_child(_timers_until_the_stop)
    # reset=True: the timer survives time jumping backwards (lifecycle.timer's docstring).
    assert armed == [(0.5, False, True), (2.0, True, True)]
    assert shut_down == [True, True]
    assert after is None  # none is armed once the node stops
    assert late is None and ticks == ['tick']


def _the_one_updater():
    lifecycle.diagnostic_updater.Updater = _Updater
    first, second = lifecycle.updater(), lifecycle.updater()
    return first is second, len(_Updater.made), first.hardware_id, rospy.get_name()


def test_the_node_has_one_updater_named_after_the_node(in_child):
    same, made, hardware_id, name = in_child(_the_one_updater)
    assert same and made == 1
    assert hardware_id == name


def test_statuses_that_fail_to_publish_are_logged_not_raised(monkeypatch):
    logged = []
    monkeypatch.setattr(rospy, 'logerr_throttle', lambda period, message: logged.append(message))

    class Closed(object):
        def force_update(self):
            raise rospy.ROSException('publish() to a closed topic')
    lifecycle._publish_statuses(Closed())
    assert logged == ['/diagnostics: statuses not published: ROSException: publish() to a closed topic']


# --- lifecycle.run, with init_node, the master link and spin stood in for. ----------------------------

class _Link(object):
    def __init__(self, statuses):
        self.statuses, self.stopped = statuses, False

    def stop(self):
        self.stopped = True


def _run_node(parameters, build, spin):
    """lifecycle.run('exam', build) with ``parameters`` on the stand-in master and ``spin`` as
    rospy.spin; returns what happened: ``{'result' or 'raised', 'init', 'timers', 'links', 'fatal'}``."""
    seen = {'init': [], 'timers': [], 'links': [], 'fatal': []}

    def init_node(name, **kwargs):
        seen['init'].append((name, kwargs))

    def get_param(name, default=None):
        return parameters.get(rospy.resolve_name(name), default)

    def timer(*args, **kwargs):
        armed = _Timer(*args, **kwargs)
        seen['timers'].append(armed)
        return armed

    def start(statuses):
        link = _Link(statuses)
        seen['links'].append(link)
        return link
    rospy.init_node, rospy.get_param, rospy.spin, rospy.Timer = init_node, get_param, spin, timer
    rospy.logfatal = lambda fmt, *args: seen['fatal'].append(fmt % args)
    lifecycle.master_link.quiet_master_outages = lambda: None
    lifecycle.master_link.start = start
    lifecycle.diagnostic_updater.Updater = _Updater
    try:
        seen['result'] = lifecycle.run('exam', build)
    except BaseException as err:  # SystemExit, and KeyboardInterrupt if SIGINT were rospy's
        seen['raised'] = (type(err).__name__, getattr(err, 'code', str(err)))
    finally:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    return seen


def _a_node_that_runs():
    built, spun = [], []
    seen = _run_node({}, lambda: built.append(True), lambda: spun.append(True))
    timer, = seen['timers']
    timer.callback(None)
    link, = seen['links']
    seen.pop('timers'), seen.pop('links')
    return seen, built, spun, (timer.period, timer.oneshot), link.statuses.published, rospy.get_name()


def test_run_starts_the_node_with_its_own_signals_and_publishes_its_statuses_every_second(in_child):
    seen, built, spun, period, published, name = in_child(_a_node_that_runs)
    assert 'raised' not in seen and seen['result'] is None
    # docs/architecture.md: init_node(disable_signals=True), the signals are lifecycle's.
    assert seen['init'] == [('exam', {'disable_signals': True})]
    assert built == [True] and spun == [True]
    # ~diagnostic_period unset: its documented default, 1 s, periodic.
    assert period == (1.0, False)
    assert published == 1  # the timer publishes the Updater the master link was given


def _a_node_stopped_by_sigint():
    stopped, stopper = threading.Event(), []

    def build():
        lifecycle.on_stop(lambda: (stopper.append(threading.current_thread().name), stopped.set()))

    def spin():
        os.kill(os.getpid(), signal.SIGINT)
        stopped.wait(JOIN_TIMEOUT)
    handlers = []
    real_signal = signal.signal

    def record(signum, handler):
        handlers.append((signum, handler))
        return real_signal(signum, handler)
    signal.signal = record
    try:
        seen = _run_node({}, build, spin)
    finally:
        signal.signal = real_signal
    installed = {signum: handler for signum, handler in handlers if signum in (signal.SIGINT, signal.SIGTERM)
                 and handler not in (signal.default_int_handler, signal.SIG_DFL)}
    link, = seen['links']
    return (seen.get('raised'), stopper, threading.current_thread().name, link.stopped,
            rospy.is_shutdown(), len(set(installed.values())), sorted(installed))


def test_sigint_and_sigterm_stop_the_node_on_a_thread_of_their_own(in_child):
    raised, stopper, main, link_stopped, shut_down, handlers, signums = in_child(_a_node_stopped_by_sigint)
    assert raised is None
    assert stopper and stopper[0] != main  # not inside the signal handler, on the main thread
    assert link_stopped and shut_down
    assert handlers == 1 and signums == sorted([signal.SIGINT, signal.SIGTERM])  # SIGTERM as SIGINT


def _a_node_with_a_bad_parameter(period):
    seen = _run_node({'/unnamed/diagnostic_period': period}, lambda: None, lambda: None)
    return seen.get('raised'), seen['fatal'], rospy.get_name()


def _a_node_whose_build_finds_a_bad_parameter():
    def build():
        raise lifecycle.params.ParamError('/unnamed/rate', -1.0, 'must be > 0')
    seen = _run_node({}, build, lambda: None)
    return seen.get('raised'), seen['fatal'], rospy.get_name()


def test_an_unusable_parameter_is_a_fatal_log_naming_the_node_and_exit_status_1(in_child):
    for raised, fatal, name in (in_child(_a_node_with_a_bad_parameter, -1.0),
                                in_child(_a_node_with_a_bad_parameter, 0.0),
                                in_child(_a_node_whose_build_finds_a_bad_parameter)):
        assert raised == ('SystemExit', 1)
        assert len(fatal) == 1 and fatal[0].startswith(name + ': ')
    assert 'diagnostic_period' in in_child(_a_node_with_a_bad_parameter, -1.0)[1][0]


def _a_node_stopped_while_it_is_built():
    def build():
        rospy.signal_shutdown('stopped while built')  # then a call to the master that is gone fails
        raise rospy.ROSException('master unreachable')
    spun = []
    seen = _run_node({}, build, lambda: spun.append(True))
    return seen.get('raised'), seen.get('result'), spun


def _a_node_whose_build_fails():
    def build():
        raise RuntimeError('a bug in the build')
    return _run_node({}, build, lambda: None).get('raised')


def test_a_stop_while_the_node_is_built_ends_it_quietly_and_a_failure_is_raised(in_child):
    assert in_child(_a_node_stopped_while_it_is_built) == (None, None, [])
    assert in_child(_a_node_whose_build_fails) == ('RuntimeError', 'a bug in the build')

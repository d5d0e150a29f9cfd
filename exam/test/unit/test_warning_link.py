"""Delivery rules of the warning link, against a fake service driven by events (no sleeps)."""
import collections
import subprocess
import sys
import threading

import pytest

from exam.debounce import NORMAL, WARNING
from exam.warning_link import ServiceConnection, WarningLink, service_link

WAIT_S = 5.0  # generous deadline for the worker thread to act


class FakeService(object):
    """Records calls; can be made absent (raises) or blocking (waits for release)."""

    def __init__(self):
        self.calls = []
        self.available = True
        self.hold = None  # a threading.Event to wait on inside the call, when set
        self.entered = threading.Event()
        self.changed = threading.Condition()

    def __call__(self, state):
        self.entered.set()
        if self.hold is not None:
            self.hold.wait(WAIT_S)
        if not self.available:
            raise IOError('service /altitude_warning unavailable')
        with self.changed:
            self.calls.append(state)
            self.changed.notify_all()
        return True, 'LED set'

    def wait_calls(self, count):
        with self.changed:
            assert self.changed.wait_for(lambda: len(self.calls) >= count, WAIT_S), self.calls
            return list(self.calls)


@pytest.fixture
def service():
    return FakeService()


@pytest.fixture
def make_link(service):
    links = []
    failures = []

    def make(retry_period=0.01):
        link = WarningLink(service, lambda state, reason: failures.append((state, reason)),
                           lambda state: None, retry_period=retry_period)
        link.failures_seen = failures
        link.start()
        links.append(link)
        return link

    yield make
    for link in links:
        link.stop(timeout=WAIT_S)


def settle(link):
    """Wait until the worker has nothing left to send (what it shows is what is wanted)."""
    for _ in range(int(WAIT_S / 0.01)):
        snap = link.snapshot()
        if snap['wanted'] in (None, snap['shown']):
            return snap
        threading.Event().wait(0.01)
    raise AssertionError('link did not settle: %r' % (link.snapshot(),))


def test_no_call_for_normal_at_start_since_the_led_starts_green(service, make_link):
    link = make_link()
    link.want(NORMAL)
    settle(link)
    link.want(WARNING)
    assert service.wait_calls(1) == [WARNING]


def test_one_call_per_change(service, make_link):
    link = make_link()
    link.want(WARNING)
    service.wait_calls(1)
    link.want(WARNING)
    link.want(NORMAL)
    assert service.wait_calls(2) == [WARNING, NORMAL]
    settle(link)
    assert service.calls == [WARNING, NORMAL]


def test_absent_service_gets_the_latest_state_once_back(service, make_link):
    service.available = False
    link = make_link()
    link.want(WARNING)
    assert service.entered.wait(WAIT_S)
    service.available = True
    assert service.wait_calls(1) == [WARNING]
    settle(link)
    assert link.failures_seen and link.failures_seen[0][0] == WARNING
    assert not link.snapshot()['failing']


def test_flip_and_flip_back_while_absent_sends_nothing(service, make_link):
    service.available = False
    link = make_link()
    link.want(WARNING)
    service.entered.wait(WAIT_S)
    link.want(NORMAL)  # back to what the LED shows
    service.available = True
    settle(link)
    assert service.calls == []


def test_a_blocked_call_does_not_block_want(service, make_link):
    service.hold = threading.Event()
    link = make_link()
    link.want(WARNING)
    assert service.entered.wait(WAIT_S)
    # The worker is stuck in the call; want() must return at once.
    done = threading.Event()
    threading.Thread(target=lambda: (link.want(NORMAL), link.want(WARNING), done.set())).start()
    assert done.wait(1.0)
    service.hold.set()
    assert service.wait_calls(1) == [WARNING]
    settle(link)
    assert service.calls == [WARNING]


def test_a_drone_restart_reported_green_makes_it_resend_warning(service, make_link):
    link = make_link()
    link.want(WARNING)
    service.wait_calls(1)
    link.led_reported(WARNING)  # the drone confirms red: nothing to do
    link.led_reported(NORMAL)   # the drone restarted: green again
    assert service.wait_calls(2) == [WARNING, WARNING]


def test_refused_call_counts_as_failure():
    refusals = []
    link = WarningLink(lambda state: (False, 'unknown status'),
                       lambda state, reason: refusals.append(reason), lambda state: None,
                       retry_period=10.0)
    link.start()
    try:
        link.want(WARNING)
        for _ in range(int(WAIT_S / 0.01)):
            if link.snapshot()['failures']:
                break
            threading.Event().wait(0.01)
        snap = link.snapshot()
        assert snap['failing'] and snap['failures'] == 1  # once per attempt; the next is 10 s away
        assert 'unknown status' in snap['last_error']
        assert snap['shown'] == NORMAL
    finally:
        link.stop(timeout=WAIT_S)


class FakeConnection(object):
    """The node's connect(): fails while ``available`` is False, counts its attempts."""

    def __init__(self):
        self.available = False
        self.attempts = 0
        self.opened = threading.Event()

    def __call__(self):
        self.attempts += 1
        if not self.available:
            raise IOError('no provider for /altitude_warning')
        self.opened.set()
        return True


def test_the_connection_is_opened_before_any_state_is_due(service):
    connection = FakeConnection()
    link = WarningLink(service, lambda state, reason: None, lambda state: None, retry_period=0.01,
                       connect=connection)
    link.start()
    try:
        # Nothing wanted yet: the worker keeps trying to open the connection, and makes no call.
        for _ in range(int(WAIT_S / 0.01)):
            if connection.attempts >= 3:
                break
            threading.Event().wait(0.01)
        assert connection.attempts >= 3 and service.calls == []
        connection.available = True
        assert connection.opened.wait(WAIT_S)
        # Open: no more attempts while idle.
        attempts = connection.attempts
        threading.Event().wait(0.1)
        assert connection.attempts == attempts and service.calls == []
        link.want(WARNING)
        assert service.wait_calls(1) == [WARNING]
    finally:
        link.stop(timeout=WAIT_S)


@pytest.fixture
def open_link(service):
    """A started link whose connection is open, and that connection; stopped after the test."""
    connection = FakeConnection()
    connection.available = True
    link = WarningLink(service, lambda state, reason: None, lambda state: None, retry_period=0.01,
                       connect=connection)
    link.start()
    assert connection.opened.wait(WAIT_S)
    yield link, connection
    link.stop(timeout=WAIT_S)


def test_a_failed_call_has_the_connection_opened_again_while_idle(service, open_link):
    link, connection = open_link
    service.available = False
    link.want(WARNING)
    assert service.entered.wait(WAIT_S)
    connection.opened.clear()
    link.want(NORMAL)  # nothing left to deliver: the worker reopens the connection instead
    assert connection.opened.wait(WAIT_S)
    settle(link)
    assert service.calls == []


def test_a_new_link_reports_nothing_wanted_and_no_failure(make_link):
    assert make_link().snapshot() == {'wanted': None, 'shown': NORMAL, 'failing': False, 'failures': 0,
                                      'last_error': ''}


def test_a_failing_service_is_retried_once_per_period_not_hammered(service, make_link):
    service.available = False
    link = make_link(retry_period=0.2)
    link.want(WARNING)
    assert service.entered.wait(WAIT_S)
    threading.Event().wait(0.5)
    # 0.5 s at one attempt per 0.2 s: three attempts at most, where a loop without the pause makes
    # thousands.
    assert 1 <= link.snapshot()['failures'] <= 4


def test_a_link_never_stopped_does_not_keep_the_process_alive():
    # The worker is a daemon thread: a node that dies before its shutdown hook still exits.
    code = ('from exam.warning_link import WarningLink\n'
            'link = WarningLink(lambda s: (True, ""), lambda s, r: None, lambda s: None)\n'
            'link.start()\n')
    done = subprocess.run([sys.executable, '-c', code], timeout=WAIT_S * 2)
    assert done.returncode == 0


def test_a_delivered_call_keeps_the_connection_it_used(service, open_link):
    link, connection = open_link
    attempts = connection.attempts
    link.want(WARNING)
    assert service.wait_calls(1) == [WARNING]
    threading.Event().wait(0.2)  # twenty retry periods: the link opens nothing more
    assert connection.attempts == attempts


def test_a_connection_that_cannot_be_opened_is_tried_once_per_period_not_hammered(service):
    connection = FakeConnection()  # never available
    link = WarningLink(service, lambda state, reason: None, lambda state: None, retry_period=0.2,
                       connect=connection)
    link.start()
    try:
        threading.Event().wait(0.5)
        # 0.5 s at one attempt per 0.2 s: three attempts at most, where a loop without the pause makes
        # thousands.
        assert 1 <= connection.attempts <= 4
    finally:
        link.stop(timeout=WAIT_S)


class FakeProxy(object):
    """A persistent proxy: answers calls until ``broken``; records its calls and whether it was closed."""

    def __init__(self, name, broken=False):
        self.name = name
        self.broken = broken
        self.calls = []
        self.closed = False

    def __call__(self, state):
        if self.broken:
            raise IOError('connection to %s reset' % self.name)
        self.calls.append(state)
        return collections.namedtuple('Response', 'success message')(True, 'LED set by %s' % self.name)

    def close(self):
        self.closed = True


class Opener(object):
    """open_persistent(): hands out the prepared proxies in turn; raises when none is left."""

    def __init__(self, *proxies):
        self.proxies = list(proxies)
        self.opened = []

    def __call__(self):
        if not self.proxies:
            raise IOError('service /altitude_warning not found')
        proxy = self.proxies.pop(0)
        self.opened.append(proxy)
        return proxy, 'rosrpc://drone:%d' % (40000 + len(self.opened))


def connection_with(*proxies):
    log = []
    opener = Opener(*proxies)
    return ServiceConnection('/altitude_warning', opener, log.append), opener, log


def test_the_connection_is_opened_once_and_kept_for_every_call():
    first = FakeProxy('first')
    connection, opener, log = connection_with(first)
    assert connection.open() and connection.open()
    assert connection.call(WARNING) == (True, 'LED set by first')
    assert connection.call(NORMAL) == (True, 'LED set by first')
    assert opener.opened == [first] and first.calls == [WARNING, NORMAL] and not first.closed
    assert log == ['/altitude_warning: connected to rosrpc://drone:40001; the connection is kept for '
                   'every call']


def test_a_call_that_fails_on_the_open_connection_is_made_again_on_a_new_one():
    first, second = FakeProxy('first'), FakeProxy('second')
    connection, opener, log = connection_with(first, second)
    connection.open()
    first.broken = True  # the drone restarted
    assert connection.call(WARNING) == (True, 'LED set by second')
    assert first.closed and not second.closed and second.calls == [WARNING]
    assert log[1] == ('/altitude_warning: the call on the open connection failed (OSError: connection '
                      'to first reset); calling again on a new connection')


def test_a_call_without_a_connection_opens_one_and_a_failure_there_is_the_links_to_retry():
    broken = FakeProxy('broken', broken=True)
    connection, opener, _ = connection_with(broken)
    with pytest.raises(IOError):
        connection.call(WARNING)
    assert broken.closed
    with pytest.raises(IOError, match='not found'):  # nothing left to open: the service is gone
        connection.call(WARNING)
    assert opener.opened == [broken]


class Lines(object):
    """A log function whose lines a test can wait for."""

    def __init__(self):
        self.lines = []
        self.changed = threading.Condition()

    def __call__(self, line):
        with self.changed:
            self.lines.append(line)
            self.changed.notify_all()

    def wait_for(self, count):
        with self.changed:
            assert self.changed.wait_for(lambda: len(self.lines) >= count, WAIT_S), self.lines
            return list(self.lines)


def test_the_service_link_connects_ahead_delivers_and_warns_of_a_failed_attempt_naming_the_service():
    first = FakeProxy('first')
    opener = Opener(first)
    log, warn = Lines(), Lines()
    link = service_link('/altitude_warning', opener, 0.01, log, warn)
    link.start()
    try:
        # Connected while nothing is due: the call needs no lookup later.
        assert log.wait_for(1) == ['/altitude_warning: connected to rosrpc://drone:40001; the '
                                   'connection is kept for every call']
        link.want(WARNING)
        assert log.wait_for(2)[1] == '/altitude_warning: LED set to WARNING'
        first.broken = True  # the drone went away, and nothing is left to open
        link.want(NORMAL)
        assert warn.wait_for(1)[0] == ('could not set /altitude_warning to NORMAL (retrying every 0 s): '
                                       'OSError: service /altitude_warning not found')
        assert first.calls == [WARNING] and first.closed
    finally:
        link.stop(timeout=WAIT_S)

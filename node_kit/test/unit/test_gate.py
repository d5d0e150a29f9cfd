"""The gate a node's callbacks pass: closed at shutdown, it waits for those inside (threads, events)."""
import threading

from node_kit.gate import Gate

WAIT_S = 5.0


def test_an_open_gate_admits_and_a_closed_one_refuses():
    gate = Gate()
    assert not gate.closed
    assert gate.enter()
    gate.leave()
    assert gate.close(timeout=0.0) == 0
    assert gate.closed
    assert not gate.enter()


def test_close_waits_for_the_callback_inside_and_admits_no_new_one():
    gate = Gate()
    inside, release, closed = threading.Event(), threading.Event(), threading.Event()
    result = []

    def callback():
        assert gate.enter()
        inside.set()
        release.wait(WAIT_S)
        gate.leave()

    def closer():
        result.append(gate.close(timeout=WAIT_S))
        closed.set()

    worker = threading.Thread(target=callback)
    worker.start()
    assert inside.wait(WAIT_S)
    stopper = threading.Thread(target=closer)
    stopper.start()
    # close() has begun: nothing new gets in, and it is still waiting for the callback inside.
    assert not closed.wait(0.2)
    assert not gate.enter()
    release.set()
    assert closed.wait(WAIT_S)
    worker.join(WAIT_S)
    stopper.join(WAIT_S)
    assert result == [0]


def test_close_gives_up_after_its_timeout_and_says_how_many_are_still_inside():
    gate = Gate()
    assert gate.enter() and gate.enter()
    gate.leave()
    assert gate.close(timeout=0.05) == 1
    gate.leave()
    assert gate.close(timeout=0.0) == 0


#: A close() timeout that no test waits out: a close that returns must have seen the gate empty.
LONG_CLOSE_S = 120.0


def _close_in_thread(gate, timeout):
    """close(timeout) on a thread of its own: (event set when it returns, list of its result)."""
    done, result = threading.Event(), []

    def closer():
        result.append(gate.close(timeout))
        done.set()
    threading.Thread(target=closer, daemon=True).start()
    return done, result


def test_close_returns_as_soon_as_the_last_callback_leaves_not_at_its_timeout():
    # close() waits "up to" its timeout: the last leave() ends the wait at once. Two callbacks inside:
    # the first to leave does not end it, the last does.
    gate = Gate()
    assert gate.enter() and gate.enter()
    done, result = _close_in_thread(gate, LONG_CLOSE_S)
    assert not done.wait(0.2)
    gate.leave()
    assert not done.wait(0.2)  # one is still inside
    gate.leave()
    assert done.wait(LONG_CLOSE_S / 4), 'close() waited for its timeout, not for the last callback'
    assert result == [0]


def test_closing_an_empty_gate_does_not_wait():
    gate = Gate()
    assert gate.enter()
    gate.leave()
    done, result = _close_in_thread(gate, LONG_CLOSE_S)
    assert done.wait(LONG_CLOSE_S / 4), 'close() of an empty gate waited for its timeout'
    assert result == [0]

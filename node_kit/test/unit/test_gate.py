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

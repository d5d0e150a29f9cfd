"""The warning rule, driven by synthetic timestamps: examples first, then properties (hypothesis)."""
from hypothesis import given, settings
from hypothesis import strategies as st

from exam.debounce import NORMAL, WARNING, Debouncer, excess_news

THRESHOLD = 1300.0
DELAY = 5.0


def feed(debouncer, readings):
    """Feed (time, value) readings; return the (time, state) changes they produced."""
    changes = []
    for now, value in readings:
        state = debouncer.update(value, now)
        if state is not None:
            changes.append((now, state))
    return changes


def test_state_is_unknown_until_the_first_reading():
    debouncer = Debouncer(THRESHOLD, DELAY)
    assert debouncer.state is None
    assert debouncer.deadline is None


def test_first_reading_below_asserts_normal_once():
    debouncer = Debouncer(THRESHOLD, DELAY)
    assert feed(debouncer, [(0.0, 100.0), (0.1, 200.0), (0.2, 1300.0)]) == [(0.0, NORMAL)]


def test_short_excursion_gives_no_warning():
    debouncer = Debouncer(THRESHOLD, DELAY)
    readings = [(0.0, 1000.0)] + [(t / 10.0, 1400.0) for t in range(10, 40)] + [(4.0, 1000.0)]
    assert feed(debouncer, readings) == [(0.0, NORMAL)]
    assert debouncer.deadline is None


def test_sustained_excess_warns_exactly_at_the_delay_after_the_first_reading_above():
    debouncer = Debouncer(THRESHOLD, DELAY)
    feed(debouncer, [(0.0, 1000.0), (1.0, 1400.0), (3.0, 1500.0)])
    assert debouncer.deadline == 6.0
    assert debouncer.poll(5.999) is None
    assert debouncer.poll(6.0) == WARNING
    assert debouncer.poll(7.0) is None
    assert debouncer.deadline is None


def test_a_reading_after_the_deadline_also_warns():
    debouncer = Debouncer(THRESHOLD, DELAY)
    assert feed(debouncer, [(0.0, 1400.0), (6.0, 1400.0)]) == [(6.0, WARNING)]


def test_back_to_normal_on_the_first_reading_at_or_below_the_threshold():
    debouncer = Debouncer(THRESHOLD, DELAY)
    feed(debouncer, [(0.0, 1400.0)])
    assert debouncer.poll(5.0) == WARNING
    assert feed(debouncer, [(5.5, 1350.0), (6.0, 1300.0), (6.1, 1200.0)]) == [(6.0, NORMAL)]


def test_a_dip_restarts_the_delay_from_the_next_reading_above():
    debouncer = Debouncer(THRESHOLD, DELAY)
    feed(debouncer, [(0.0, 1400.0), (4.0, 1299.0), (4.5, 1400.0)])
    assert debouncer.poll(5.0) is None
    assert debouncer.deadline == 9.5
    assert debouncer.poll(9.5) == WARNING


def test_interrupt_cancels_the_pending_excess_but_keeps_the_state():
    debouncer = Debouncer(THRESHOLD, DELAY)
    feed(debouncer, [(0.0, 1400.0)])
    debouncer.interrupt()
    assert debouncer.poll(10.0) is None
    assert debouncer.state is None
    assert feed(debouncer, [(10.0, 1400.0)]) == []
    assert debouncer.poll(15.0) == WARNING
    debouncer.interrupt()
    assert debouncer.state == WARNING


def test_zero_delay_warns_on_the_first_reading_above():
    debouncer = Debouncer(THRESHOLD, 0.0)
    assert feed(debouncer, [(0.0, 1000.0), (1.0, 1300.1)]) == [(0.0, NORMAL), (1.0, WARNING)]


# --- properties ---------------------------------------------------------------------------------------

# A reading: a time step (0 to 2 s) and a value around the threshold; optionally a poll in between.
steps = st.lists(
    st.tuples(st.floats(min_value=0.0, max_value=2.0),
              st.floats(min_value=THRESHOLD - 50, max_value=THRESHOLD + 50),
              st.booleans()),
    max_size=80)


def run(events):
    """Replay events; return the ordered log of ('reading', time, value) and ('change', time, state)."""
    debouncer = Debouncer(THRESHOLD, DELAY)
    now = 0.0
    log = []
    for step, value, poll_first in events:
        now += step
        if poll_first:
            state = debouncer.poll(now)
            if state is not None:
                log.append(('change', now, state))
        log.append(('reading', now, value))
        state = debouncer.update(value, now)
        if state is not None:
            log.append(('change', now, state))
    return log


def changes(log):
    return [state for kind, _, state in log if kind == 'change']


@settings(max_examples=300, deadline=None)
@given(steps)
def test_never_two_equal_states_in_a_row(events):
    states = changes(run(events))
    assert all(a != b for a, b in zip(states, states[1:]))


@settings(max_examples=300, deadline=None)
@given(steps)
def test_never_warning_before_delay_of_uninterrupted_excess(events):
    log = run(events)
    for i, (kind, when, state) in enumerate(log):
        if kind != 'change' or state != WARNING:
            continue
        # Walk back over the readings before the WARNING: all must be above the threshold back to a
        # reading at least DELAY older than the WARNING.
        excess_start = None
        for kind_before, t, value in reversed(log[:i]):
            if kind_before != 'reading':
                continue
            if value <= THRESHOLD:
                break
            excess_start = t
        assert excess_start is not None and when - excess_start >= DELAY


@settings(max_examples=300, deadline=None)
@given(steps)
def test_normal_at_the_first_reading_back_after_a_warning(events):
    log = run(events)
    for i, (kind, _, state) in enumerate(log):
        if kind != 'change' or state != WARNING:
            continue
        later = log[i + 1:]
        back = [j for j, (k, _, v) in enumerate(later) if k == 'reading' and v <= THRESHOLD]
        if back:
            # The very next log entry after that reading is its NORMAL change.
            assert later[back[0] + 1:back[0] + 2] == [('change', later[back[0]][1], NORMAL)]


def test_the_properties_see_warnings():
    # Guard against vacuous properties: the strategy's shape does produce WARNINGs and returns.
    log = run([(0.5, THRESHOLD + 10, False)] * 12 + [(0.5, THRESHOLD - 10, True)])
    assert changes(log) == [WARNING, NORMAL]


def test_excess_news_once_per_excess_and_its_cancellation():
    assert excess_news(None, 15.0, None) == 'pending'          # an excess began, WARNING due at 15 s
    assert excess_news(15.0, 15.0, None) is None               # the same excess goes on
    assert excess_news(15.0, None, NORMAL) == 'cancelled'      # back within the limit
    assert excess_news(15.0, None, None) == 'cancelled'        # interrupted (stale inputs)
    assert excess_news(15.0, None, WARNING) is None            # it fired: logged as the WARNING
    assert excess_news(None, None, NORMAL) is None             # nothing was pending
    assert excess_news(15.0, 21.0, None) == 'pending'          # a new excess right after another

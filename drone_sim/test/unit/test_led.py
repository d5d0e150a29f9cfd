"""The warning LED rule: NORMAL -> GREEN, WARNING -> RED, anything else refused."""

from hypothesis import given, strategies as st

from drone_sim.led import GREEN, RED, WarningLed


def test_starts_green_and_follows_requests():
    led = WarningLed('ALT WARN')
    assert led.colour == GREEN
    assert led.apply('WARNING') == (True, 'ALT WARN LED set to RED (was GREEN)', True)
    assert led.colour == RED
    assert led.apply('WARNING') == (True, 'ALT WARN LED already RED', False)
    assert led.apply('NORMAL') == (True, 'ALT WARN LED set to GREEN (was RED)', True)
    assert led.colour == GREEN


def test_refusal_names_accepted_values_and_keeps_the_colour():
    led = WarningLed('DEPTH WARN')
    led.apply('WARNING')
    success, message, changed = led.apply('normal')
    assert (success, changed, led.colour) == (False, False, RED)
    assert message == ("refused status 'normal': accepted values are 'NORMAL' or 'WARNING'; "
                       "DEPTH WARN LED stays RED")


@given(st.text().filter(lambda s: s not in ('NORMAL', 'WARNING')), st.sampled_from(['NORMAL', 'WARNING']))
def test_any_other_string_is_refused(status, before):
    led = WarningLed('ALT WARN')
    led.apply(before)
    colour = led.colour
    success, _, changed = led.apply(status)
    assert not success and not changed
    assert led.colour == colour

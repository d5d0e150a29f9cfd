"""What the report says about a recorded flight or dive, computed from its bag; and the model error.

Reading the bag needs the rosbag module; everything after that is plain Python on (time, value) lists.

The exam node decides on *readings*: each sensor message updates its cache, and the value computed from
the latest temperature and pressure (or both pressures) goes to the debouncer at once. So the
crossings are measured here the same way: the value is recomputed, with the exam package's own
formula, at every sensor message of the bag, and compared with the instants the drone's LED topic
changed colour (each change is one successful service call).
"""
import math

from exam import formulas
from mydrone import atmosphere


def read_bag(path):
    """{topic: [(receive time [s], message), ...]} of every message in the bag at ``path``."""
    import rosbag  # only here: the pure functions below are testable without it
    series = {}
    with rosbag.Bag(path) as bag:
        for topic, msg, stamp in bag.read_messages():
            series.setdefault(topic, []).append((stamp.to_sec(), msg))
    return series


def values(series, topic):
    """[(time, msg.data), ...] of one topic (empty when the topic has no message)."""
    return [(t, msg.data) for t, msg in series.get(topic, [])]


def recompute(series, inputs, compute):
    """The value the exam node computed at each reading: [(time, value)], once every input has arrived.

    :param inputs: the input topics, in the order ``compute`` takes their latest values.
    """
    latest = {}
    merged = sorted((t, topic, data) for topic in inputs for t, data in values(series, topic))
    result = []
    for t, topic, data in merged:
        latest[topic] = data
        if len(latest) == len(inputs):
            result.append((t, compute(*(latest[name] for name in inputs))))
    return result


def excess_episodes(samples, threshold):
    """Runs of samples strictly above ``threshold``: [(first time above, first time back at or below)].

    The end is None when the samples stop while still above.
    """
    episodes = []
    start = None
    for t, value in samples:
        if value > threshold and start is None:
            start = t
        elif value <= threshold and start is not None:
            episodes.append((start, t))
            start = None
    if start is not None:
        episodes.append((start, None))
    return episodes


def led_changes(series, led_topic):
    """[(time, colour)] of each change of the latched LED topic, without its initial colour."""
    changes = []
    colour = None
    for t, data in values(series, led_topic):
        if colour is not None and data != colour:
            changes.append((t, data))
        colour = data
    return changes


def summarise(series, inputs, compute, output, truth, led_topic, threshold, delay, origin):
    """Facts of one recorded run, times in seconds since ``origin`` (the roslaunch start).

    Returns a dict: ``episodes`` [(start, end, duration)] of the recomputed value above the threshold;
    ``changes`` [(time, colour)] of the LED; ``warning_lag`` [s] from the end of the delay (first reading
    above + delay) to each RED; ``normal_lag`` [s] from the reading back at or below to each GREEN;
    ``published``/``truth``/``readings`` series for the figures; ``rate`` of the output topic [Hz].
    """
    readings = [(t - origin, v) for t, v in recompute(series, inputs, compute)]
    published = [(t - origin, v) for t, v in values(series, output)]
    truth_samples = [(t - origin, v) for t, v in values(series, truth)]
    changes = [(t - origin, colour) for t, colour in led_changes(series, led_topic)]
    episodes = []
    for start, end in excess_episodes(readings, threshold):
        episodes.append((start, end, None if end is None else end - start))
    warning_lag, normal_lag = [], []
    for t, colour in changes:
        if colour == 'RED':
            # The episode running at that instant, and the instant its delay ran out.
            for start, end, _ in episodes:
                if start <= t and (end is None or t <= end + 1.0):
                    warning_lag.append(t - (start + delay))
                    break
        else:
            ends = [end for _, end, _ in episodes if end is not None and end <= t + 1.0]
            if ends:
                normal_lag.append(t - max(ends))
    rate = None
    if len(published) > 1:
        rate = (len(published) - 1) / (published[-1][0] - published[0][0])
    return {'episodes': episodes, 'changes': changes, 'warning_lag': warning_lag,
            'normal_lag': normal_lag, 'readings': readings, 'published': published,
            'truth': truth_samples, 'rate': rate}


def hold_errors(series, inputs, compute, truth, hold_tolerance=0.01):
    """[(true value, estimate - truth)] at the readings where the truth holds still.

    The truth is published with each reading of the truth-bearing sensor; a sample counts when the
    truth before and after it is the same (within ``hold_tolerance``), so the estimate's lag behind a
    fast climb (the inputs are sampled at 0.78 and 2 Hz) does not pollute the model error.
    """
    truth_samples = values(series, truth)
    readings = recompute(series, inputs, compute)
    errors = []
    j = 0
    for i in range(1, len(truth_samples) - 1):
        t, value = truth_samples[i]
        if (abs(truth_samples[i - 1][1] - value) > hold_tolerance
                or abs(truth_samples[i + 1][1] - value) > hold_tolerance):
            continue
        # The recomputed value at the same message (published in the same timer callback).
        while j + 1 < len(readings) and readings[j + 1][0] <= t + 0.005:
            j += 1
        if readings and abs(readings[j][0] - t) < 0.05:
            errors.append((value, readings[j][1] - value))
    return errors


def isothermal_error(altitude_m):
    """Error [m] of the exam's equation (1) fed with the ISA temperature and pressure at ``altitude_m``."""
    return formulas.altitude(atmosphere.temperature_c(altitude_m), atmosphere.pressure_pa(altitude_m)) - altitude_m


def lapse_rate_altitude(temperature_c, pressure_pa):
    """Altitude [m] with the ISA lapse rate instead of an isothermal column, from the local temperature.

    With T(h) = T0 - L*h and P = P0*(T/T0)^(g*mu/(R*L)), the sea-level temperature is
    T0 = T*(P0/P)^(R*L/(g*mu)), so h = (T0 - T)/L = T/L*((P0/P)^(R*L/(g*mu)) - 1).
    """
    t_k = temperature_c + formulas.ZERO_CELSIUS
    exponent = formulas.R * atmosphere.LAPSE_RATE / (formulas.G * formulas.MU_AIR)
    return t_k / atmosphere.LAPSE_RATE * ((formulas.P0 / pressure_pa) ** exponent - 1.0)


def standard_altitude(pressure_pa):
    """Altitude [m] from the ISA formula h = T0/L*(1 - (P/P0)^(R*L/(g*mu))), sea-level T0 = 288.15 K."""
    exponent = formulas.R * atmosphere.LAPSE_RATE / (formulas.G * formulas.MU_AIR)
    return atmosphere.T0 / atmosphere.LAPSE_RATE * (1.0 - (pressure_pa / formulas.P0) ** exponent)


def lapse_rate_error(altitude_m):
    """Error [m] of :func:`lapse_rate_altitude` against the ISA truth (rounding only)."""
    return lapse_rate_altitude(atmosphere.temperature_c(altitude_m), atmosphere.pressure_pa(altitude_m)) - altitude_m


def mean_temperature_altitude(temperature_c, pressure_pa, iterations=50):
    """Equation (1) with the column's mean temperature T + L*h/2 instead of the local T [m].

    h appears on both sides; a fixed-point iteration from the isothermal value converges in a few steps
    (the correction is a few per cent of h).
    """
    t_k = temperature_c + formulas.ZERO_CELSIUS
    log_ratio = math.log(formulas.P0 / pressure_pa)
    h = formulas.altitude(temperature_c, pressure_pa)
    for _ in range(iterations):
        h = formulas.R * (t_k + atmosphere.LAPSE_RATE * h / 2.0) / (formulas.MU_AIR * formulas.G) * log_ratio
    return h


def mean_temperature_error(altitude_m):
    """Error [m] of :func:`mean_temperature_altitude` against the ISA truth."""
    return (mean_temperature_altitude(atmosphere.temperature_c(altitude_m), atmosphere.pressure_pa(altitude_m))
            - altitude_m)


def true_altitude_read_as(estimate_m, low=-500.0, high=11000.0):
    """The ISA altitude [m] at which equation (1) reads ``estimate_m`` (bisection; the error is monotonic)."""
    for _ in range(100):
        middle = (low + high) / 2.0
        if isothermal_error(middle) + middle < estimate_m:
            low = middle
        else:
            high = middle
    return (low + high) / 2.0


def mean(numbers):
    numbers = list(numbers)
    return sum(numbers) / len(numbers) if numbers else math.nan

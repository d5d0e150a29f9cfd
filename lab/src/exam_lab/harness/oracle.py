"""The independent oracle: both exam sheets' equations and the debounce rule, written from the sheets.

Every test, tool and grader that needs an expected value takes it from here. It is deliberately NOT
imported from the ``exam`` package: an oracle that reuses the code it checks cannot catch a wrong
constant or a wrong sign. No rospy here.

Sheet 000 (aerial drone), equation (1): ``P = P0 * exp(-mu*g*h / (R*T))``, T in kelvin.
Sheet 001 (underwater drone), equation (1): ``depth = (P_robot - P_remote) / (rho*g)``.
The warning rule (question 14b): WARNING once the value has stayed strictly above the threshold for
``delay`` seconds, counted from the first reading above; NORMAL at the first reading at or below.
"""
import math

#: Standard pressure at sea level [Pa] (sheet 000).
P0 = 101325.0
#: Mean molar mass of air [kg/mol] (sheet 000).
MU_AIR = 0.0289644
#: Gravity [m/s^2] (both sheets).
G = 9.80665
#: Perfect gas constant [J/(K*mol)] (sheet 000).
R = 8.31432
#: T[K] = T[degC] + 273.15 (sheet 000's footnote).
ZERO_CELSIUS = 273.15
#: Density of salt water [kg/m^3] (sheet 001).
RHO_SEA_WATER = 1030.0

NORMAL = 'NORMAL'
WARNING = 'WARNING'


def altitude_of(temperature_c, pressure_pa):
    """Altitude [m] that equation (1) of sheet 000 gives for a temperature [degC] and pressure [Pa]."""
    return R * (temperature_c + ZERO_CELSIUS) / (MU_AIR * G) * math.log(P0 / pressure_pa)


def pressure_at(altitude_m, temperature_c):
    """Pressure [Pa] that equation (1) of sheet 000 gives at ``altitude_m`` and ``temperature_c``."""
    return P0 * math.exp(-MU_AIR * G * altitude_m / (R * (temperature_c + ZERO_CELSIUS)))


def depth_of(pressure_robot_pa, pressure_remote_pa):
    """Depth [m, positive down] that equation (1) of sheet 001 gives for the two pressures [Pa]."""
    return (pressure_robot_pa - pressure_remote_pa) / (RHO_SEA_WATER * G)


def pressure_robot_at(depth_m, pressure_remote_pa):
    """Pressure [Pa] at the robot that equation (1) of sheet 001 turns back into ``depth_m``."""
    return pressure_remote_pa + depth_m * RHO_SEA_WATER * G


def debounce_transitions(readings, threshold, delay):
    """Transitions ``[(time, state)]`` the rule demands for ``readings`` ``[(time s, value)]`` in order.

    The state starts NORMAL; it turns WARNING once the value has been above the threshold continuously
    for ``delay`` seconds, counted from the first reading above it (any reading at or below cancels the
    count); it turns NORMAL at the first reading at or below the threshold. A WARNING is due at the
    instant the delay expires, even between two readings.
    """
    transitions = []
    state = NORMAL
    excess_since = None
    for t, value in readings:
        if state == NORMAL and excess_since is not None and t >= excess_since + delay:
            state = WARNING
            transitions.append((excess_since + delay, WARNING))
        if value > threshold:
            if excess_since is None:
                excess_since = t
        else:
            excess_since = None
            if state == WARNING:
                state = NORMAL
                transitions.append((t, NORMAL))
    return transitions


def spans_above(times, values, threshold):
    """Intervals ``[(first_time_above, last_time_above)]`` where ``values`` stay above ``threshold``.

    Locates a profile's excursions from sampled values (accurate to one sampling step).
    """
    spans = []
    start = last = None
    for t, v in zip(times, values):
        if v > threshold:
            if start is None:
                start = t
            last = t
        elif start is not None:
            spans.append((start, last))
            start = None
    if start is not None:
        spans.append((start, last))
    return spans

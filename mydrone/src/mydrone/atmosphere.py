"""The ISA troposphere (International Standard Atmosphere, 0 to 11 km). No rospy here.

Temperature falls linearly with altitude, T = T0 - L*h, and pressure follows the hydrostatic law for
that linear temperature, P = P0 * (T/T0)^(g*mu/(R*L)). The exam node inverts the isothermal law of the
exam sheet instead, so its estimate is a little low (about 19 m at 1300 m): the flight profiles keep
their excursions well clear of the threshold for that reason.
"""

P0 = 101325.0  # Pa, standard sea-level pressure
T0 = 288.15  # K, standard sea-level temperature (15 degC)
LAPSE_RATE = 0.0065  # K/m, L
G = 9.80665  # m/s^2
MU = 0.0289644  # kg/mol, molar mass of dry air
R = 8.31432  # J/(K*mol), the gas constant as the exam sheet gives it
KELVIN_OFFSET = 273.15  # T[K] = T[degC] + 273.15
TOP = 11000.0  # m, the tropopause: above it the lapse rate is no longer L
# The ISA formula would still give numbers below sea level; the Dead Sea shore is the lowest land.
BOTTOM = -500.0  # m

_EXPONENT = G * MU / (R * LAPSE_RATE)


def temperature_k(altitude_m):
    """Air temperature (K) at ``altitude_m`` (m above sea level)."""
    return T0 - LAPSE_RATE * altitude_m


def temperature_c(altitude_m):
    """Air temperature (degC) at ``altitude_m``, as the drone's thermometer reports it."""
    return temperature_k(altitude_m) - KELVIN_OFFSET


def pressure_pa(altitude_m):
    """Static air pressure (Pa) at ``altitude_m``."""
    return P0 * (temperature_k(altitude_m) / T0) ** _EXPONENT

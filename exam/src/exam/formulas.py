"""The two physical models of the exam, and what counts as a usable sensor reading.

Pure functions, no rospy: they are unit-tested against hand-computed values without a ROS master.

Altitude (aerial drone, sheet 000, equation 1): the barometric law ``P = P0 * exp(-mu*g*h / (R*T))``
solved for the altitude::

    h = R*T / (mu*g) * ln(P0 / P)

It treats the air column below the drone as isothermal at the temperature measured on board. The real
troposphere cools with height (ISA: -6.5 K/km), so against the ISA atmosphere this formula reads low:
about 19 m at 1300 m. That is the model the exam asks for, kept as it is; docs/report.md quantifies it.

Depth (underwater drone, sheet 001, equation 1): hydrostatics of an incompressible sea::

    depth = (P_robot - P_remote) / (rho * g)

where the remote floats at the surface, so its pressure is the atmospheric pressure on the water.
"""
import math

#: Standard pressure at sea level [Pa].
P0 = 101325.0
#: Mean molar mass of air [kg/mol].
MU_AIR = 0.0289644
#: Standard gravity [m/s^2].
G = 9.80665
#: Perfect gas constant [J/(K*mol)] (the value the exam sheet gives).
R = 8.31432
#: 0 degC in kelvin.
ZERO_CELSIUS = 273.15
#: Density of salt water [kg/m^3].
RHO_SEA_WATER = 1030.0
#: Kelvin temperatures up to this are taken as absolute zero [K]. std_msgs/Float32 cannot hold
#: -273.15 exactly: it arrives as -273.1499939 degC, 6e-6 K above absolute zero, and would pass a bare
#: comparison. 1 mK is far above that rounding and far below any real air temperature.
ABSOLUTE_ZERO_MARGIN_K = 1e-3


def altitude(temperature_c, pressure_pa):
    """Altitude [m] from the on-board temperature [degC] and air pressure [Pa] (isothermal model)."""
    temperature_k = temperature_c + ZERO_CELSIUS
    return R * temperature_k / (MU_AIR * G) * math.log(P0 / pressure_pa)


def depth(pressure_robot_pa, pressure_remote_pa):
    """Depth [m, positive downwards] from the robot's and the surface remote's pressures [Pa]."""
    return (pressure_robot_pa - pressure_remote_pa) / (RHO_SEA_WATER * G)


def why_unusable_temperature(temperature_c):
    """Why a temperature reading [degC] is unusable (a reason for the log), or None when it is usable.

    NaN and infinities come from a broken sensor driver; at or below absolute zero the kelvin
    temperature would be <= 0 and the altitude formula meaningless.
    """
    if not math.isfinite(temperature_c):
        return 'not a finite number'
    if temperature_c + ZERO_CELSIUS <= ABSOLUTE_ZERO_MARGIN_K:
        return 'at or below absolute zero (-273.15 degC)'
    return None


def why_unusable_pressure(pressure_pa):
    """Why a pressure reading [Pa] is unusable (a reason for the log), or None when it is usable.

    A pressure is absolute, so it is strictly positive; ln(P0/P) needs that too.
    """
    if not math.isfinite(pressure_pa):
        return 'not a finite number'
    if pressure_pa <= 0.0:
        return 'not strictly positive'
    return None

"""Pressures of the underwater drone and of its remote at the surface. No rospy here.

The water is incompressible (as the exam sheet assumes), so the pressure at a depth is the surface
pressure plus rho*g*depth. The surface (atmospheric) pressure drifts slowly with the weather; both the
remote's and the robot's readings use the same instant's surface pressure, so the drift cancels in the
exam's depth formula and only sensor noise (and the two topics' sampling instants) remain.
"""

import math

RHO = 1030.0  # kg/m^3, salt water
G = 9.80665  # m/s^2
P_ATM = 101325.0  # Pa, mean sea-level pressure
# Weather drift: two slow sinusoids (periods of minutes, tens of Pa) whose sum does not repeat within
# a session; real fronts move hundreds of Pa over hours, far slower than anything here.
_DRIFT = ((40.0, 600.0, 0.0), (15.0, 173.0, 1.3))  # (amplitude Pa, period s, phase rad)
DEEPEST = 11000.0  # m, deeper than the Mariana Trench: the bound of a dive profile


def surface_pressure_pa(t):
    """Atmospheric pressure (Pa) at sea level, ``t`` seconds after the start."""
    return P_ATM + sum(a * math.sin(2.0 * math.pi * t / period + phase) for a, period, phase in _DRIFT)


def pressure_at_depth_pa(surface_pa, depth_m):
    """Absolute water pressure (Pa) at ``depth_m`` below a surface at ``surface_pa``."""
    return surface_pa + RHO * G * depth_m


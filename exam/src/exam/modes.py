"""What differs between the aerial and the underwater drone, in one table.

The exam node's logic is the same for both sheets (cache two inputs, compute, publish, debounce a
threshold, drive a warning LED through a service); only the names, the formula and the default
threshold change. Each :class:`Mode` gathers those, so the wiring in :mod:`exam.node` never tests which
drone it serves.
"""
import collections

from mydrone.srv import AltitudeWarning
from submarinedrone.srv import DepthWarning

from exam import formulas

#: One input topic, its unit, and why_unusable: function reading -> why it is unusable, or None.
Input = collections.namedtuple('Input', 'topic unit why_unusable')

Mode = collections.namedtuple('Mode', [
    'name',               # value of the ~mode parameter
    'inputs',             # Input tuple, in the order compute() takes them
    'compute',            # function(*input values) -> published value
    'output',             # published topic (std_msgs/Float32)
    'unit',               # unit of the output and of ~threshold
    'default_threshold',  # ~threshold when the launch file gives none
    'service',            # warning service to call with "NORMAL"/"WARNING"
    'service_type',       # its srv class
    'led_topic',          # latched std_msgs/String "GREEN"/"RED" the drone publishes
    'above',              # the log's words for a value beyond the threshold ("above", "deeper than")
    'within',             # and for one within it ("at or below", "not deeper than")
])

ALTITUDE = Mode(
    name='altitude',
    inputs=(Input('temperature', 'degC', formulas.why_unusable_temperature),
            Input('pressure', 'Pa', formulas.why_unusable_pressure)),
    compute=formulas.altitude,
    output='altitude',
    unit='m',
    default_threshold=1300.0,  # range of today's remote controller (sheet 000)
    service='altitude_warning',
    service_type=AltitudeWarning,
    led_topic='alt_warn_led',
    above='above',
    within='at or below',
)

DEPTH = Mode(
    name='depth',
    inputs=(Input('pressure_robot', 'Pa', formulas.why_unusable_pressure),
            Input('pressure_remote', 'Pa', formulas.why_unusable_pressure)),
    compute=formulas.depth,
    output='depth',
    unit='m',
    default_threshold=150.0,  # depth rating of today's drone (sheet 001)
    service='depth_warning',
    service_type=DepthWarning,
    led_topic='depth_warn_led',
    above='deeper than',
    within='not deeper than',
)

MODES = {mode.name: mode for mode in (ALTITUDE, DEPTH)}

"""Built-in dive profiles of the submarine drone: ``[time_s, depth_m]`` waypoints, looping. No rospy here.

Chosen with the exam node in mind (threshold 150 m, 5 s debounce). The depth formula of the exam
sheet is exact for this simulator (incompressible water, same rho and g), so only sensor noise (a few
millimetres of depth) separates the estimate from the truth; the profiles still cross 150 m by 25 m
or more and stay 25 m shallower otherwise.

``default`` (loop 100 s)::

    time  s   0    15    20    23    26    40    46    66    72    85   100
    depth m   0   125   125   175   125   125   200   200   125   125     0

- 0-20 s: dive to 125 m and hold (LED green).
- 20-26 s: excursion to 175 m, deeper than 150 m from 21.5 s to 24.5 s (3.0 s): shorter than the
  5 s delay, so no warning.
- 40-72 s: stay at 200 m, deeper than 150 m from 42.0 s to 70.0 s (28 s): a debounced exam node warns
  at about 47 s and returns to NORMAL at about 70 s.
- 72-100 s: back to 125 m, then up to the surface, where the next loop starts.

``calm`` (loop 120 s): 0 m -> 60 m -> 100 m -> 60 m -> 0 m at 0, 30, 60, 90, 120 s; never below 150 m.

``deep`` (loop 60 s): 200 m all the time: a warning after the delay, and it holds.
"""

DIVES = {
    'default': [[0.0, 0.0], [15.0, 125.0], [20.0, 125.0], [23.0, 175.0], [26.0, 125.0],
                [40.0, 125.0], [46.0, 200.0], [66.0, 200.0], [72.0, 125.0], [85.0, 125.0],
                [100.0, 0.0]],
    'calm': [[0.0, 0.0], [30.0, 60.0], [60.0, 100.0], [90.0, 60.0], [120.0, 0.0]],
    'deep': [[0.0, 200.0], [60.0, 200.0]],
}

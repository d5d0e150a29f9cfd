"""Built-in flight profiles of mydrone: ``[time_s, altitude_m]`` waypoints, looping. No rospy here.

Chosen with the exam node in mind (threshold 1300 m, 5 s debounce). Its isothermal formula reads
about 19 m low near 1300 m (1300 m true gives 1280.7 m, 1450 m gives 1426.0 m, 1500 m gives 1474.3 m,
1200 m gives 1183.6 m), so every crossing below goes clearly past 1300 m in the estimate too, and the
drone stays 100 m below the threshold otherwise.

``default`` (loop 100 s)::

    time s     0    15    20   22.5    25    40    46    66    72    85   100
    alt  m  1000  1200  1200   1450  1200  1200  1500  1500  1200  1200  1000

- 0-20 s: climb to 1200 m and hold (LED green).
- 20-25 s: excursion to 1450 m. True altitude above 1300 m from 21.0 s to 24.0 s (3.0 s); estimate
  above 1300 m from 21.2 s to 23.8 s (2.6 s): shorter than the 5 s delay, so no warning.
- 40-72 s: stay at 1500 m. True altitude above 1300 m from 42.0 s to 70.0 s (28 s); estimate above
  1300 m from 42.4 s to 69.6 s (27.2 s): a debounced exam node warns at about 47.4 s and returns to
  NORMAL at about 69.6 s.
- 72-100 s: back to 1200 m, then down to 1000 m, where the next loop starts.

``calm`` (loop 120 s): 0 m -> 800 m -> 1100 m -> 800 m -> 0 m at 0, 30, 60, 90, 120 s; never above
1300 m (estimate at most 1086 m): the LED stays green.

``high`` (loop 60 s): 1500 m all the time (estimate 1474 m): a warning after the delay, and it holds;
for tests that need a lasting WARNING, e.g. a drone restarted while the warning is on.
"""

FLIGHTS = {
    'default': [[0.0, 1000.0], [15.0, 1200.0], [20.0, 1200.0], [22.5, 1450.0], [25.0, 1200.0],
                [40.0, 1200.0], [46.0, 1500.0], [66.0, 1500.0], [72.0, 1200.0], [85.0, 1200.0],
                [100.0, 1000.0]],
    'calm': [[0.0, 0.0], [30.0, 800.0], [60.0, 1100.0], [90.0, 800.0], [120.0, 0.0]],
    'high': [[0.0, 1500.0], [60.0, 1500.0]],
}

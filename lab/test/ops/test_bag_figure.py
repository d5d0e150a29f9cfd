"""lab/report/bag_figure.py, run as README says, on a small bag: the figure is written, and what the
script reports (the span above the threshold, the LED's changes) is the bag's. No master needed.

The bag is flight_bag.py's flight (its sensors), plus what a recording of the running system would
hold: /altitude at 10 Hz and the drone's latched LED topic, RED 5 s after the first reading above 1300 m
and GREEN at the first reading back.
"""
import os
import subprocess
import sys

import flight_bag

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))))
SCRIPT = os.path.join(REPO, 'lab', 'report', 'bag_figure.py')
THRESHOLD = 1300.0


def write_recording(path):
    """The flight's sensors, /altitude and /alt_warn_led; returns (up, down, red, green) [s from start]."""
    import rosbag
    import rospy
    from std_msgs.msg import Float32, String
    readings = flight_bag.readings()
    states = flight_bag.states(readings)
    up, down = flight_bag.crossings(states, THRESHOLD)
    red, green = up + 5.0 + 0.01, down + 0.01
    with rosbag.Bag(path, 'w') as bag:
        for t, topic, value in readings:
            bag.write('/' + topic, Float32(data=value), rospy.Time.from_sec(flight_bag.START + t))
        for tick in range(1, int(flight_bag.WAYPOINTS[-1][0] * 10)):
            t = tick / 10.0
            latest = [h for s, h in states if s <= t]
            if latest:
                bag.write('/altitude', Float32(data=latest[-1]), rospy.Time.from_sec(flight_bag.START + t))
        for t, colour in ((0.05, 'GREEN'), (red, 'RED'), (green, 'GREEN')):
            bag.write('/alt_warn_led', String(data=colour), rospy.Time.from_sec(flight_bag.START + t))
    return up, down, red, green


def test_the_bag_becomes_the_flight_figure(tmp_path):
    bag, png = str(tmp_path / 'flight.bag'), str(tmp_path / 'flight.png')
    up, down, red, green = write_recording(bag)
    done = subprocess.run([sys.executable, SCRIPT, bag, png], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, timeout=120)
    output = done.stdout.decode()
    assert done.returncode == 0, output
    assert 'above 1300 m from %.1f s to %.1f s' % (up, down) in output, output
    assert 'LED: RED at %.1f s, GREEN at %.1f s' % (red, green) in output, output
    with open(png, 'rb') as f:
        assert f.read(8) == b'\x89PNG\r\n\x1a\n'


def test_a_bag_without_the_output_topic_is_refused_with_what_to_record(tmp_path):
    bag = str(tmp_path / 'sensors.bag')
    flight_bag.write(bag)  # sensors only: no /altitude
    done = subprocess.run([sys.executable, SCRIPT, bag, str(tmp_path / 'x.png')], stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, timeout=120)
    assert done.returncode != 0
    assert '/altitude' in done.stdout.decode()
    assert not os.path.exists(str(tmp_path / 'x.png'))

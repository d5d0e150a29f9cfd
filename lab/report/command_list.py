"""Every command line that docs/report.md shows, in the order `make report` runs them. No rospy here.

One list for both the runner (collect.py) and the report (report_template.md names each command by its
key), so the report can never show a command that was not run. The docs test
(lab/test/docs/test_docs.py) checks that each line still parses, that the programs, packages, launch
files, nodes, topics, services and parameters it names exist in the code, and that the template uses
every key.

A line is split with shlex and run without a shell, from the report's work folder (bags land there).
``limit`` [s] is a safety net only: commands that would run forever (``rostopic hz``) are bounded by a
visible ``timeout -s INT``, which stops them as Ctrl-C would.

A long output may be shown in part: ``show_from`` shows it from the first line that matches this regular
expression on, ``show_until`` up to the first line that matches; the report says how many lines it
leaves out.
"""
import collections

#: key: the template's name for the command; line: the exact command line; limit: safety timeout [s];
#: show_from, show_until: regular expressions that cut a long output (None: the whole output).
Command = collections.namedtuple('Command', 'key line limit show_from show_until', defaults=(None, None))

#: Topics of a full flight recorded to a bag: sensors, estimate, LED and ground truth.
FLIGHT_TOPICS = '/temperature /pressure /altitude /alt_warn_led /mydrone/true_altitude'
DIVE_TOPICS = '/pressure_robot /pressure_remote /depth /depth_warn_led /submarine_drone/true_depth'

# --- both sheets, question 1: catkin_make in a fresh workspace of this repository's packages ---------
#: Only its end is shown: from the first "[100%]" line of make on.
CATKIN_MAKE = Command('build.catkin_make', 'catkin_make', 300, show_from=r'^\[100%\]')

# --- sheet 000, questions 3 to 8: the aerial drone's node alone --------------------------------------
MYDRONE_NODE = Command('mydrone.run', 'rosrun mydrone mydrone_node.py', None)
MYDRONE_ALONE = [
    Command('mydrone.rosnode_list', 'rosnode list', 15),
    Command('mydrone.rosnode_info', 'rosnode info /mydrone', 15),
    Command('mydrone.rostopic_list', 'rostopic list', 15),
    Command('mydrone.rostopic_info_rosout', 'rostopic info /rosout', 15),
    Command('mydrone.rostopic_type', 'rostopic type /temperature', 15),
    Command('mydrone.rosmsg_info', 'rosmsg info std_msgs/Float32', 15),
    Command('mydrone.echo_temperature', 'rostopic echo -n 3 /temperature', 20),
    Command('mydrone.hz_temperature', 'timeout -s INT 6 rostopic hz /temperature', 20),
    Command('mydrone.hz_pressure', 'timeout -s INT 3 rostopic hz /pressure', 15),
    Command('mydrone.rosservice_list', 'rosservice list', 15),
    Command('mydrone.rossrv_show', 'rossrv show mydrone/AltitudeWarning', 15),
    Command('mydrone.call_warning', 'rosservice call /altitude_warning "status: \'WARNING\'"', 15),
    Command('mydrone.echo_led', 'rostopic echo -n 1 /alt_warn_led', 15),
    Command('mydrone.call_normal', 'rosservice call /altitude_warning "status: \'NORMAL\'"', 15),
    Command('mydrone.call_bad', 'rosservice call /altitude_warning "status: \'RED\'"', 15),
    # Question 10's first step: the student's node that only logs what it receives (lab/report/).
    Command('mydrone.first_step', 'timeout -s INT 3 rosrun exam_lab exam_node_step10.py', 20),
]

# --- both sheets, question 9: the package, each sheet's command in a scratch folder of its own ------
CREATE_PKG = Command('exam.create_pkg', 'catkin_create_pkg exam rospy std_msgs mydrone', 30)
CREATE_PKG_SUBMARINE = Command('exam.create_pkg_submarine', 'catkin_create_pkg exam rospy std_msgs submarinedrone',
                               30)

# --- both sheets, question 12: a launch whose exam node refuses its parameter ends at once -----------
BAD_LAUNCH = Command('flight.bad_launch', 'roslaunch exam exam.launch threshold:=1300m', 40,
                     show_from=r'\]: /exam: parameter /exam/threshold')

# --- sheet 000, questions 10 to 14: the exam node with the drone, one full default flight -----------
FLIGHT_RECORD = Command('flight.record', 'rosbag record -O flight.bag ' + FLIGHT_TOPICS, None)
#: Shown from roslaunch's server to the exam node's first decision: the summary, the processes, the
#: nodes' start (the log folder and disk check before it are left out).
FLIGHT_LAUNCH = Command('flight.launch', 'roslaunch exam exam.launch', None,
                        show_from=r'^started roslaunch server', show_until=r'\]: altitude -?[0-9.]+ m at or below')
FLIGHT_LIVE = [
    Command('flight.rosnode_list', 'rosnode list', 15),
    Command('flight.rosnode_info_exam', 'rosnode info /exam', 15),
    Command('flight.echo_altitude', 'rostopic echo -n 3 /altitude', 15),
    Command('flight.hz_altitude', 'timeout -s INT 3 rostopic hz /altitude', 15),
    Command('flight.param_threshold', 'rosparam get /exam/threshold', 15),
    Command('flight.param_delay', 'rosparam get /exam/delay', 15),
]
#: The same flight at the same time on a second master, for another remote model and a shorter delay
#: (question 14): with 1200 m even the short climb at 22 s warns. (A threshold of 1500 m would never
#: warn with this flight: its estimate peaks at about 1474 m.)
CUSTOM_RECORD = Command('custom.record',
                        'rosbag record -O flight_1200.bag /temperature /pressure /altitude /alt_warn_led', None)
CUSTOM_LAUNCH = Command('custom.launch', 'roslaunch exam exam.launch threshold:=1200 delay:=3', None)
CUSTOM_LIVE = [
    Command('custom.param_threshold', 'rosparam get /exam/threshold', 15),
    Command('custom.param_delay', 'rosparam get /exam/delay', 15),
]

# --- sheet 001, questions 3 to 8: the underwater drone's node alone ---------------------------------
SUBMARINE_NODE = Command('submarine.run', 'rosrun submarinedrone submarine_drone_node.py', None)
SUBMARINE_ALONE = [
    Command('submarine.rosnode_list', 'rosnode list', 15),
    Command('submarine.rosnode_info', 'rosnode info /submarine_drone', 15),
    Command('submarine.rostopic_list', 'rostopic list', 15),
    Command('submarine.rostopic_type', 'rostopic type /pressure_robot', 15),
    # (rosmsg info std_msgs/Float32 is the same for both drones: run once, with mydrone.)
    Command('submarine.echo_pressure_robot', 'rostopic echo -n 3 /pressure_robot', 15),
    Command('submarine.hz_pressure_robot', 'timeout -s INT 3 rostopic hz /pressure_robot', 15),
    Command('submarine.hz_pressure_remote', 'timeout -s INT 4 rostopic hz /pressure_remote', 15),
    Command('submarine.call_warning', 'rosservice call /depth_warning "status: \'WARNING\'"', 15),
    Command('submarine.call_normal', 'rosservice call /depth_warning "status: \'NORMAL\'"', 15),
    Command('submarine.first_step', 'timeout -s INT 3 rosrun exam_lab exam_submarine_node_step10.py', 20),
]

# --- sheet 001, questions 10 to 14: the exam node in depth mode, one full default dive --------------
DIVE_RECORD = Command('dive.record', 'rosbag record -O dive.bag ' + DIVE_TOPICS, None)
DIVE_LAUNCH = Command('dive.launch', 'roslaunch exam exam_submarine.launch', None)
DIVE_LIVE = [
    Command('dive.echo_depth', 'rostopic echo -n 3 /depth', 15),
    Command('dive.hz_depth', 'timeout -s INT 3 rostopic hz /depth', 15),
    Command('dive.param_threshold', 'rosparam get /exam/threshold', 15),
]

# --- both sheets, questions 10 to 14: the simple answer (docs/simple_answer/exam), built in question
# 1's workspace and run beside ours, each sheet on a master of its own, recorded for its LED changes ---
SIMPLE_RECORD = Command('simple.record', 'rosbag record -O simple.bag /temperature /pressure /altitude /alt_warn_led',
                        None)
SIMPLE_LAUNCH = Command('simple.launch', 'roslaunch exam exam.launch', None)
SIMPLE_LIVE = [
    Command('simple.hz_altitude', 'timeout -s INT 3 rostopic hz /altitude', 15),
    Command('simple.param_threshold', 'rosparam get /exam/threshold', 15),
]
SIMPLE_DIVE_RECORD = Command('simple_dive.record', 'rosbag record -O simple_dive.bag /pressure_robot '
                             '/pressure_remote /depth /depth_warn_led', None)
SIMPLE_DIVE_LAUNCH = Command('simple_dive.launch', 'roslaunch exam exam_submarine.launch', None)

#: Processes started in the background (their console is kept; they are stopped with SIGINT).
BACKGROUND = [MYDRONE_NODE, FLIGHT_RECORD, FLIGHT_LAUNCH, CUSTOM_RECORD, CUSTOM_LAUNCH,
              SUBMARINE_NODE, DIVE_RECORD, DIVE_LAUNCH, SIMPLE_RECORD, SIMPLE_LAUNCH, SIMPLE_DIVE_RECORD,
              SIMPLE_DIVE_LAUNCH]
#: Commands run to completion, output captured.
FOREGROUND = ([CATKIN_MAKE] + MYDRONE_ALONE + [CREATE_PKG, CREATE_PKG_SUBMARINE, BAD_LAUNCH] + FLIGHT_LIVE
              + CUSTOM_LIVE + SIMPLE_LIVE + SUBMARINE_ALONE + DIVE_LIVE)
ALL = BACKGROUND + FOREGROUND
BY_KEY = {command.key: command for command in ALL}

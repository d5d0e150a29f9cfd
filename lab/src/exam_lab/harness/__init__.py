"""The lab's harness: the one set of tools that drives the product (or a student's node) from outside.

Modules, from the bottom up (each imports only those above it, and the answer's packages only for
their service types):

- :mod:`exam_lab.harness.oracle` -- both sheets' equations and the debounce rule, written from the
  sheets, independently of the ``exam`` package. No rospy.
- :mod:`exam_lab.harness.wait` -- ``wait_until`` (a deadline, never a fixed sleep) and ``stays``
  (the one deliberate observation window). No rospy.
- :mod:`exam_lab.harness.supervisor` -- ``Supervisor``: masters on free ports, processes in their own
  groups with their logs kept, every process of a run ended on close; ``free_port``, ``ros_env``.
  Needs ROS only for ``start_master``.
- :mod:`exam_lab.harness.fake_drone` -- ``Drone``: scripted sensors of either sheet, a recording
  warning service with an LED topic, a recorder of the node's output; ``DroneScenario`` for rostests.
  Runs inside a rospy node (``rosrun exam_lab fake_drone_node.py`` is one on its own).

Users: the exam node's and the simulators' rostests (``lab/test``), the operations checks, the
benchmark (``lab/bench``), the report generator (``lab/report``), the soak run and the grader.
"""

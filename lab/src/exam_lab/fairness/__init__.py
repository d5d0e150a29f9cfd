"""Generated student answers that test the grader's fairness (issue 35 point 7): correct answers to
either sheet in the styles students use, and one-mistake variants of them, each with the points it must
get. Pure Python, no rospy: :mod:`exam_lab.fairness.generator` writes the packages, `make fairness`
(lab/scripts/fairness.py) grades them.
"""

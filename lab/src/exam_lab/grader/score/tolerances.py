"""The rubric's tolerances and weights, one constant each: what a correction of the rubric changes (then
``make rescore``). Pure, no rospy; docs/grading.md says why each is what it is.
"""

#: Question 11: the rate the sheet asks for, and the accepted relative deviation.
RATE_HZ = 10.0
RATE_TOLERANCE = 0.10
#: Question 11: a published value agrees when within this many metres, or this share of the value.
VALUE_TOLERANCE_M = 0.5
VALUE_TOLERANCE_REL = 0.001
#: Question 14b: WARNING accepted from delay - EARLY to delay + LATE s after the node's own value went
#: beyond the threshold and stayed: 5 s less one reading of the 2 Hz input (4.5 s) falls outside. LATE
#: is at least one period of the slowest input and a tick of the node's 10 Hz (:func:`~.flight.warning_window`):
#: a node that checks its delay at each reading, or at each synchronised pair, warns at the first one
#: at or after 5 s, up to one reading later.
WARNING_EARLY_S = 0.3
WARNING_LATE_S = 0.5
#: Question 14b: NORMAL accepted up to this many s after the node's own value came back (at once); one
#: that comes later (the flight waits for it) is "not at once", Q14b's 0.5 alone.
NORMAL_LATE_S = 0.5
#: Question 13: this many calls repeating the previous status make "called in a loop".
LOOP_REPEATS = 3
#: Question 11: the publisher's types accepted on the output topic (the sheets name none).
NUMERIC_TYPES = tuple('std_msgs/%s' % t for t in ('Float32', 'Float64', 'Int8', 'Int16', 'Int32', 'Int64',
                                                  'UInt8', 'UInt16', 'UInt32', 'UInt64'))
#: Question 12: what a launch file without a single comment loses ("la moitie si pas de commentaires").
NO_COMMENT_LOSS = 0.5
#: Question 11's lag: the node's value follows its inputs within one period of its slowest input (a
#: node that waits for a fresh reading of each) plus this: a tick of its 10 Hz and the transport.
LAG_SLACK_S = 0.5
#: The slowest input's rate of a probe that did not record its rates (the lab's drone before issue 35).
OLD_SLOWEST_HZ = 2.0

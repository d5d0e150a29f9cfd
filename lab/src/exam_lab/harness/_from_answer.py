"""Test-only helpers that left the answer's product modules (issue 9), to fold into the lab's harness.

- :func:`spans_above` was ``drone_sim.profile.spans_above``.
- :func:`depth_m` was ``submarinedrone.hydrostatics.depth_m``: the exam sheet's equation (1), the
  formula ``exam.formulas.depth`` implements for the node.

No rospy here.
"""

from submarinedrone.hydrostatics import G, RHO


def spans_above(times, values, threshold):
    """Intervals where ``values`` stay strictly above ``threshold``.

    Used by the tests and the docs to locate a profile's excursions from sampled values.

    :param times: increasing sample times (s).
    :param values: the value at each time.
    :returns: list of ``(first_time_above, last_time_above)``; the duration of a span is
        ``last - first`` (accurate to one sampling step).
    """
    spans = []
    start = None
    last = None
    for t, v in zip(times, values):
        if v > threshold:
            if start is None:
                start = t
            last = t
        elif start is not None:
            spans.append((start, last))
            start = None
    if start is not None:
        spans.append((start, last))
    return spans


def depth_m(robot_pa, remote_pa):
    """The exam sheet's equation (1): depth from the robot's and the remote's pressures (Pa)."""
    return (robot_pa - remote_pa) / (RHO * G)

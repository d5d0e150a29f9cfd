"""The warning LED of the remote controller and the rule of its warning service. No rospy here.

The service accepts exactly the two statuses of the exam sheets: ``"NORMAL"`` lights the LED green,
``"WARNING"`` lights it red. Anything else (another word, other case, surrounding spaces) is refused and
leaves the LED as it was, so a client bug shows up as ``success: false`` rather than as a wrong colour.
"""

GREEN = 'GREEN'
RED = 'RED'
# Accepted statuses and the colour each one sets, in the order the refusal message lists them.
COLOUR_OF_STATUS = {'NORMAL': GREEN, 'WARNING': RED}


class WarningLed:
    """One LED, GREEN at start. Not thread-safe: the caller serialises calls of apply().

    :param label: the LED's name on the remote, for messages (e.g. ``"ALT WARN"``).
    """

    def __init__(self, label):
        self.label = label
        self.colour = GREEN

    def apply(self, status):
        """Apply one service request.

        :param status: the request's ``status`` string.
        :returns: ``(success, message, changed)``: the service response fields, and whether the colour
            changed (the caller logs and publishes only then).
        """
        colour = COLOUR_OF_STATUS.get(status)
        if colour is None:
            accepted = ' or '.join(repr(s) for s in COLOUR_OF_STATUS)
            return (False, 'refused status %r: accepted values are %s; %s LED stays %s'
                    % (status, accepted, self.label, self.colour), False)
        previous = self.colour
        self.colour = colour
        if colour == previous:
            return True, '%s LED already %s' % (self.label, colour), False
        return True, '%s LED set to %s (was %s)' % (self.label, colour, previous), True

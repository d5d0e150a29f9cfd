"""Reproducible sensor noise: each sensor channel draws from its own seeded generator.

One generator per channel (rather than one shared by the node) keeps a run reproducible even though
each sensor is sampled by its own timer thread: the interleaving of the threads then changes nothing.
No rospy here.
"""

import random


def channel_rng(seed, channel):
    """A ``random.Random`` determined by the node seed and the channel name only.

    String seeds are hashed with SHA-512 by ``random.Random`` (version 2 seeding), so the sequence is
    the same on every run and every Python 3 interpreter, unlike ``hash()``-based seeding.
    """
    return random.Random('%d/%s' % (seed, channel))


class GaussianNoise:
    """Additive zero-mean Gaussian noise of standard deviation ``sigma`` (in the reading's unit).

    :param seed: the node's ``~seed``.
    :param channel: the sensor's name (its topic), so two sensors never share a sequence.
    :param sigma: standard deviation, >= 0; 0 gives noiseless readings.
    """

    def __init__(self, seed, channel, sigma):
        self.sigma = sigma
        self._rng = channel_rng(seed, channel)

    def __call__(self, value):
        """``value`` plus one noise sample."""
        return value + self._rng.gauss(0.0, self.sigma)

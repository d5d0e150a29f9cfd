"""The LED topic keeps every change (issue 19): README's service call, 20 times, shows RED then GREEN.

With the exam node running, ``rosservice call /altitude_warning "status: 'WARNING'"`` turns the
drone's LED RED and the exam node, which reads the LED, sets it back GREEN within milliseconds
(README, "The call the exam node makes"). A subscriber connected before must see both messages, in
that order, at every try: the drone's latched LED publisher queues every change for each connection
(a queue of one message dropped the RED when the GREEN followed before the writer thread sent it;
2 of 12 tries showed only GREEN).

On a master of its own; the flight (``calm``) never crosses the threshold, so the exam node wants
GREEN throughout. Each try waits for the GREEN that follows the call (an event, with a deadline).
"""
import json
import time

from exam_lab.harness.supervisor import Supervisor
from exam_lab.harness.wait import wait_until

TRIES = 20
#: Generous bound for the exam node's re-sync after the call (it takes about 10 ms).
RESYNC_TIMEOUT = 20.0


def leds(output):
    """The probe's --echo lines of the LED topic: [(arrival time s, colour)], in arrival order."""
    return [(s['t'], s['data']) for s in (json.loads(line) for line in output.splitlines()
                                           if line.startswith('{"echo"'))
            if s['echo'] == '/alt_warn_led']


def test_every_call_shows_red_then_green(tmp_path):
    with Supervisor(tmp_path) as procs:
        env = procs.start_master().env
        launch = procs.start('launch', ['roslaunch', 'exam', 'exam.launch', 'profile:=calm'], env)
        # Connected once, before the calls; it never meets its conditions (it runs until stopped).
        procs.start('watch', ['rosrun', 'exam_lab', 'probe.py', '--echo', '--timeout', '600',
                              '--count', '1000000', '--value', '/altitude', '--led', '/alt_warn_led=RED'],
                    env)
        # The exam node has a state (NORMAL) once /altitude flows, and the LED's latched GREEN is in.
        assert wait_until(lambda: '"/altitude"' in procs.output('watch') and leds(procs.output('watch')),
                          60.0), procs.output('watch') + procs.output('launch')
        seen = []
        for attempt in range(TRIES):
            before = len(leds(procs.output('watch')))
            called = time.time()
            status, out, _ = procs.run('call%d' % attempt, ['rosservice', 'call', '/altitude_warning',
                                                            "status: 'WARNING'"], 60.0, env)
            assert status == 0 and 'success: True' in out, out
            assert wait_until(lambda: 'GREEN' in [c for _, c in leds(procs.output('watch'))[before:]],
                              RESYNC_TIMEOUT), 'no GREEN after call %d:\n%s' % (
                                  attempt, procs.output('launch')[-3000:])
            after = leds(procs.output('watch'))[before:]
            colours = [c for _, c in after]
            seen.append(colours)
            assert colours == ['RED', 'GREEN'], 'try %d: the LED topic showed %s' % (attempt, colours)
            print('try %2d: RED then GREEN %.1f ms apart (%.0f ms after the call began)'
                  % (attempt, 1000 * (after[1][0] - after[0][0]), 1000 * (after[0][0] - called)))
        assert launch.poll() is None
        assert len(seen) == TRIES

"""BENCH_PROFILE=1: sample the exam node with py-spy where it misses a goal, and rank its functions.

py-spy reads the node's memory from outside (``--nonblocking``: it never pauses the process), so the
profile shows the node as it runs, every thread included: rospy's receive threads, the timer, the
service worker. lab/bench/run.sh installs py-spy into a throwaway directory only when asked.
"""

import os
import subprocess

import stages
import stats


JITTER_GOAL_MS = 0.5


class Profiler:
    def __init__(self, py_spy, out_dir, window, jitter_rounds, jitter_window, always_jitter=False):
        self.always_jitter = always_jitter  # a smoke run exercises the experiment whatever the sd
        self.py_spy = py_spy
        self.out_dir = out_dir
        self.window = window
        self.jitter_rounds = jitter_rounds
        self.jitter_window = jitter_window

    def profile_missed(self, lab, results):
        """Profiles of ours at 10 Hz (CPU goal) and at the first rate it could not sustain, and the
        jitter experiment when the 10 Hz interval sd misses its goal (py-spy cannot see scheduling
        delays: a thread waiting to run takes no samples)."""
        profiles = {}
        ours = results['ours']
        targets = [10]
        runs = (ours.get('max_rate') or {}).get('runs') or []
        failed = [x['target_hz'] for x in runs if not x['sustained']]
        if failed:
            targets.append(min(failed))
        for target in targets:
            label = 'ours at ~rate %g Hz' % target
            stages.progress('profile: py-spy on %s for %d s' % (label, self.window))
            out = os.path.join(self.out_dir, 'py-spy-%g.txt' % target)
            try:
                stages.rate_and_cost(lab, 'ours', self.window, rate=target,
                                     during=lambda pid, window: self._record(pid, window, out))
                profiles[label] = stats.summarize_collapsed(out)
            except (RuntimeError, OSError, subprocess.SubprocessError) as e:
                profiles[label] = 'profile failed: %s' % e
        sd = (ours.get('rate') or {}).get('sd_ms')
        if self.always_jitter or (sd is not None and sd > JITTER_GOAL_MS):
            stages.progress('profile: jitter experiment, %d rounds of %d s per variant'
                            % (self.jitter_rounds, self.jitter_window))
            try:
                profiles['jitter'] = stages.jitter(lab, self.jitter_rounds, self.jitter_window)
            except RuntimeError as e:
                profiles['jitter'] = 'jitter experiment failed: %s' % e
        return profiles

    def _record(self, pid, seconds, out):
        subprocess.run([self.py_spy, 'record', '--pid', str(pid), '--duration', str(seconds),
                        '--rate', '250', '--nonblocking', '--format', 'raw', '--output', out],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       timeout=seconds + 30)

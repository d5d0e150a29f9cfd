"""What produced a grade, for appeals and audits: written into every grade.json. No rospy here.

``{"grader": commit (with "+changes" when the working tree differs from it), "rubric": a digest of the
scoring code (score/), "machine": host, kernel, cores, "date": UTC, "how": "run" or "rescore"}``.
The rubric's digest changes with any change to what turns measurements into points, so two grades
with the same digest were scored by the same rules, whatever else changed in the grader.
"""
import datetime
import glob
import hashlib
import os
import platform
import subprocess

_HERE = os.path.dirname(os.path.realpath(__file__))
_SCORE = os.path.join(os.path.dirname(_HERE), 'score')
_cache = {}


def rubric_version():
    """The first 12 hex digits of the SHA-256 of the scoring modules' source (score/*.py)."""
    if 'rubric' not in _cache:
        digest = hashlib.sha256()
        for path in sorted(glob.glob(os.path.join(_SCORE, '*.py'))):
            digest.update(os.path.basename(path).encode() + b'\0')
            with open(path, 'rb') as f:
                digest.update(f.read())
        _cache['rubric'] = digest.hexdigest()[:12]
    return _cache['rubric']


def grader_version():
    """The repository's commit, "+changes" when its tracked files differ from it; "unknown" outside
    a git checkout (an installed copy)."""
    if 'grader' not in _cache:
        try:
            def git(*args):
                return subprocess.run(('git', '-C', _HERE) + args, stdout=subprocess.PIPE,
                                      stderr=subprocess.DEVNULL, timeout=20, check=True).stdout.decode().strip()
            commit = git('rev-parse', 'HEAD')
            changed = git('status', '--porcelain', '--untracked-files=no')
            _cache['grader'] = commit[:12] + ('+changes' if changed else '')
        except (OSError, subprocess.SubprocessError):
            _cache['grader'] = 'unknown'
    return _cache['grader']


def stamp(how='run'):
    """The provenance of a grade made now (``how``: "run" or "rescore")."""
    return {'grader': grader_version(), 'rubric': rubric_version(), 'how': how,
            'machine': '%s (%s %s, %d cores)' % (platform.node(), platform.system(), platform.release(),
                                                os.cpu_count() or 0),
            'date': datetime.datetime.utcnow().replace(microsecond=0).isoformat() + 'Z'}

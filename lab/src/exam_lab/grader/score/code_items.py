"""The comments (4 points) and the code quality (2 points) proposed from what the inspection's box
measured of the student's code (:mod:`exam_lab.grader.boxed.code_quality`, the measurements'
``comments``): always "to check", with the measure and each signal's file and line. Pure, no rospy.
"""
import re

from exam_lab.grader.score import answers

#: Share of functions and blocks commented: "commenté partout" from this share on, "assez peu" from
#: the next one on, "clairement pas assez" below it (sheet 000's notes: 4, 2, 0).
EVERYWHERE, FEW = 0.8, 0.4


def comments_proposal(comments):
    """The comments item (4 points) from the inspection's ``comments`` (the measurements'): always
    to check, whether the comments are clear is the teacher's call."""
    if not comments:
        return answers.proposal('comments', answers.TO_CHECK, None, 'no Python code was read: nothing to measure')
    units = comments.get('units')
    lines = '%d comment line(s) for %d code line(s)' % (comments['comments'], comments['code'])
    if not units:
        share = comments['comments'] / float(max(1, comments['code']))
        return answers.proposal('comments', answers.TO_CHECK, None, '%s (%.0f %%); no function or block measured (kept before '
                        'they were): the teacher judges' % (lines, 100 * share))
    done = [u for u in units if u['commented']]
    share = len(done) / float(len(units))
    points, words = (4.0, 'commenté partout') if share >= EVERYWHERE else \
        (2.0, 'assez peu') if share >= FEW else (0.0, 'clairement pas assez')
    functions = [u for u in units if u['kind'] == 'function']
    bare = ['%s:%d %s' % (u['file'], u['line'], u['name'] + '()' if u['kind'] == 'function' else u['kind'])
            for u in units if not u['commented']]
    checks = [answers.named_check('functions commented', None, '%d of %d' % (len([u for u in functions if u['commented']]),
                                                             len(functions))),
              answers.named_check('blocks commented', None, '%d of %d' % (len(done) - len([u for u in functions if u['commented']]),
                                                          len(units) - len(functions))),
              answers.named_check('comment lines', None, lines)]
    evidence = ('%d of %d functions and blocks commented (%.0f %%) -> "%s": %s; %s%s; to check: whether the '
                'comments are clear' % (len(done), len(units), 100 * share, words, answers.shown_number(points), lines,
                                        '; without a comment: %s' % ', '.join(bare[:12]) +
                                        (' and %d more' % (len(bare) - 12) if len(bare) > 12 else '') if bare else ''))
    return answers.proposal('comments', answers.TO_CHECK, points, evidence, checks)


#: Signals that weigh half a point each kind (the others a point each kind).
MINOR = ('global without need',)
#: pyflakes' messages that are style, not a fault (half a point, as MINOR).
_MINOR_FLAKES = re.compile(r'imported but unused|assigned to but never used|redefinition of unused|'
                           r'unable to detect undefined names|f-string is missing placeholders')


def quality_proposal(comments):
    """The code-quality item (2 points) from the signals the inspection found, each with its file and
    line; always to check."""
    signals = [s for s in (comments or {}).get('quality') or [] if s['kind'] != 'note']
    notes = [s['detail'] for s in (comments or {}).get('quality') or [] if s['kind'] == 'note']
    if comments is None or 'quality' not in (comments or {}):
        return answers.proposal('quality', answers.TO_CHECK, None, 'no code quality measured (no Python code read, or kept '
                        'before it was): the teacher judges')
    kinds = {}
    for s in signals:
        minor = s['kind'] in MINOR or s['kind'] == 'pyflakes' and _MINOR_FLAKES.search(s['detail'])
        kinds.setdefault(('minor ' if minor else '') + s['kind'], []).append(s)
    cost = sum(0.5 if kind.startswith('minor ') else 1.0 for kind in kinds)
    points = max(0.0, 2.0 - cost)
    checks = [answers.named_check(kind, False, '; '.join('%s:%d %s' % (s['file'], s['line'], s['detail']) for s in found[:5]))
              for kind, found in sorted(kinds.items())]
    listed = '; '.join('%s:%d %s: %s' % (s['file'], s['line'], s['kind'], s['detail']) for s in signals[:10])
    evidence = ('%s -> %s (each kind of signal 1 point, a minor one 0.5)%s; to check: the algorithm itself' % (
        listed or 'no signal found (pyflakes, service in a loop, busy wait, blocking call in a callback, global '
        'without need)', answers.shown_number(points), '; ' + '; '.join(notes) if notes else ''))
    return answers.proposal('quality', answers.TO_CHECK, points, evidence, checks)


def student_proposals(report, ref, comments):
    """All 8 proposals of one student, in the contract's order (Q4-Q9, comments, quality)."""
    return answers.report_proposals(report, ref) + [comments_proposal(comments), quality_proposal(comments)]

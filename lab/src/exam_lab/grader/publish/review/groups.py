"""The class's answers to one hand item, in groups of identical answers. Pure: no I/O, no rospy.

Gradescope's answer groups, for a report: the teacher reads an answer once and gives its points to
every student who wrote it. Two answers are one when they are the same text once what does not change
their meaning is set aside (:func:`normalise`): case, accents' composed or decomposed forms, spacing
and line breaks, and what differs from one run of the drone to the next (a node's URI with its host
and port, a pid, a port), so that two students who pasted the same ``rosnode info`` are one group.

The answer of an item is the passage its proposal rests on (the student's text for a question); the
evidence where there is no passage (the code's measure for the comments and the quality); nothing
where no answer was found or the report was not read: those students are one group by that state, so
that the teacher sees them together, and must type their points (there is no proposal to confirm).
Students on the two sheets are never one group: the same text can be right for one drone and wrong
for the other.
"""
import collections
import hashlib
import re
import unicodedata

#: States whose students have no answer to read: one group per state (and sheet).
NO_ANSWER = ('no answer found', 'not read')
#: A proposal that is missing altogether (proposals not made for this run).
NO_PROPOSAL = 'no proposal'

_URI = re.compile(r'\b(?:https?|rosrpc)://[^\s/]+/?', re.I)
_PID = re.compile(r'\bpid\s*[:=]?\s*\d+', re.I)
_LONG_NUMBER = re.compile(r'(?<![\d.])\d{4,}(?![\d.])')
_SPACE = re.compile(r'\s+')
_EDGE_PUNCTUATION = ' .;:,!?-'

Group = collections.namedtuple('Group', 'id item sheet state answer members proposals')
Group.__doc__ = """One answer of a class to an item.

``id`` stable across runs (the item, the sheet and the normalised answer hashed), ``answer`` the text
shown (the first member's), ``members`` the students (their indexes, in order), ``proposals`` the
distinct ``(points, state)`` proposed to them (one when the rules decided alike)."""


def normalise(text):
    """``text`` as it is compared: NFKC, case-folded, each URI ``http://host:port/`` as ``uri``, pids and
    other numbers of 4 digits or more as ``#`` (pids and ports; a rate, a reading, a year of 3 digits or
    with a point keep theirs), whitespace runs one space, punctuation at the ends gone."""
    text = unicodedata.normalize('NFKC', text or '').casefold()
    text = _URI.sub('uri ', text)
    text = _PID.sub('pid #', text)
    text = _LONG_NUMBER.sub('#', text)
    return _SPACE.sub(' ', text).strip(_EDGE_PUNCTUATION)


def answer_of(proposal):
    """``(state, the text an item's answer is compared by)`` of a proposal (a dict of proposals.json's
    shape, or None when there is none)."""
    if proposal is None:
        return NO_PROPOSAL, ''
    state = proposal.get('state') or ''
    if state in NO_ANSWER:
        return state, ''
    return state, proposal.get('passage') or proposal.get('evidence') or ''


def group_id(item, sheet, normalised, state=''):
    digest = hashlib.sha1('\0'.join((item, sheet or '', state, normalised)).encode('utf-8', 'surrogatepass'))
    return digest.hexdigest()[:12]


def groups(item, students):
    """The groups of ``item`` in a class.

    :param students: ``[(sheet, proposal or None)]``, one per student in the page's order.
    :returns: the groups, the largest first (then by the first member's place).
    """
    found = collections.OrderedDict()
    for index, (sheet, proposal) in enumerate(students):
        state, text = answer_of(proposal)
        normalised = normalise(text)
        # an empty answer is one only with another of its state: "no answer found" is not "not read"
        kind = state if not normalised else ''
        gid = group_id(item, sheet, normalised, kind)
        if gid not in found:
            found[gid] = Group(gid, item, sheet or '', kind, text, [], [])
        group = found[gid]
        group.members.append(index)
        offered = (proposal.get('points') if proposal else None, state)
        if offered not in group.proposals:
            group.proposals.append(offered)
    ordered = list(found.values())
    ordered.sort(key=lambda g: (-len(g.members), g.members[0]))
    return ordered


def proposed_points(group):
    """The points the rules gave every member of ``group`` alike, or None (they differ, or none)."""
    points = {p for p, _ in group.proposals}
    return points.pop() if len(points) == 1 else None
